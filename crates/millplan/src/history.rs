//! The training history of `kerf train mill` as a file: one row per episode as CSV (with
//! the moving average of the reward) or a JSON array of [`EpisodeReport`], read back
//! exactly; and the trailing moving average of the training curve (seed 004 Fig. 5).

use std::fmt::Write as _;

use crate::{EpisodeReport, MillPlanError};

/// The trailing moving average: entry k is the mean of `values[k + 1 − w ..= k]` with
/// w = min(k + 1, `window`) (the first entries average what exists so far). A `window` of 0
/// is treated as 1.
///
/// # Arguments
/// * `values` – the series (episode rewards); `window` – episodes averaged.
///
/// # Returns
/// One average per value.
pub fn moving_average(values: &[f64], window: usize) -> Vec<f64> {
    let window = window.max(1);
    let mut out = Vec::with_capacity(values.len());
    let mut sum = 0.0;
    for (k, v) in values.iter().enumerate() {
        sum += v;
        if k >= window {
            sum -= values[k - window];
        }
        out.push(sum / (k + 1).min(window) as f64);
    }
    out
}

/// The history as CSV: a header and one row per episode (empty loss cells in the warm-up).
///
/// # Arguments
/// * `history` – the episodes; `window` – episodes of the `moving_average_N` column.
///
/// # Returns
/// The CSV text, newline-terminated.
pub fn history_csv(history: &[EpisodeReport], window: usize) -> String {
    let rewards: Vec<f64> = history.iter().map(|r| r.total_reward).collect();
    let average = moving_average(&rewards, window);
    let mut s = format!(
        "episode,episodes,steps,total_reward,moving_average_{},mean_critic_loss,\
         mean_actor_loss,noise_std,elapsed_s,remaining_s\n",
        window.max(1)
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
    for (r, avg) in history.iter().zip(&average) {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{}",
            r.episode,
            r.episodes,
            r.steps,
            r.total_reward,
            avg,
            opt(r.mean_critic_loss),
            opt(r.mean_actor_loss),
            r.noise_std,
            r.elapsed_s,
            r.remaining_s
        );
    }
    s
}

/// Reads a history written by `kerf train mill --history`: CSV when `csv`, else a JSON array
/// of [`EpisodeReport`].
///
/// # Arguments
/// * `source` – the file's name, for the messages; `text` – its contents; `csv` – its format.
///
/// # Returns
/// The episodes, in file order.
///
/// # Errors
/// [`MillPlanError::Io`] naming `source`, the row and the column: a missing column, a value
/// that is not a number, a non-finite reward, noise or time (NaN never passes), or no
/// episode at all.
pub fn parse_history(
    source: &str,
    text: &str,
    csv: bool,
) -> Result<Vec<EpisodeReport>, MillPlanError> {
    parse_text(text, csv).map_err(|message| MillPlanError::Io {
        path: source.to_string(),
        message,
    })
}

/// [`parse_history`] with the message alone.
fn parse_text(text: &str, csv: bool) -> Result<Vec<EpisodeReport>, String> {
    let history: Vec<EpisodeReport> = if csv {
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let header: Vec<&str> = lines
            .next()
            .ok_or("empty history")?
            .split(',')
            .map(str::trim)
            .collect();
        let col = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| format!("the header has no column `{name}`"))
        };
        let idx = [
            col("episode")?,
            col("episodes")?,
            col("steps")?,
            col("total_reward")?,
            col("mean_critic_loss")?,
            col("mean_actor_loss")?,
            col("noise_std")?,
            col("elapsed_s")?,
            col("remaining_s")?,
        ];
        let mut out = Vec::new();
        for (row, line) in lines.enumerate() {
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            let cell = |k: usize| -> Result<&str, String> {
                cells
                    .get(idx[k])
                    .copied()
                    .ok_or_else(|| format!("row {}: column `{}` missing", row + 1, header[idx[k]]))
            };
            let num = |k: usize| -> Result<f64, String> {
                let c = cell(k)?;
                c.parse::<f64>().map_err(|_| {
                    format!(
                        "row {}: `{}` = `{c}` is not a number",
                        row + 1,
                        header[idx[k]]
                    )
                })
            };
            let whole = |k: usize| -> Result<usize, String> {
                let c = cell(k)?;
                c.parse::<usize>().map_err(|_| {
                    format!(
                        "row {}: `{}` = `{c}` is not a whole number",
                        row + 1,
                        header[idx[k]]
                    )
                })
            };
            let opt = |k: usize| -> Result<Option<f64>, String> {
                if cell(k)?.is_empty() {
                    Ok(None)
                } else {
                    num(k).map(Some)
                }
            };
            out.push(EpisodeReport {
                episode: whole(0)?,
                episodes: whole(1)?,
                steps: whole(2)?,
                total_reward: num(3)?,
                mean_critic_loss: opt(4)?,
                mean_actor_loss: opt(5)?,
                noise_std: num(6)?,
                elapsed_s: num(7)?,
                remaining_s: num(8)?,
            });
        }
        out
    } else {
        serde_json::from_str(text)
            .map_err(|e| format!("not a JSON array of episode reports: {e}"))?
    };
    if history.is_empty() {
        return Err("no episode in the history".to_string());
    }
    for r in &history {
        for (name, v) in [
            ("total_reward", Some(r.total_reward)),
            ("noise_std", Some(r.noise_std)),
            ("elapsed_s", Some(r.elapsed_s)),
            ("remaining_s", Some(r.remaining_s)),
            ("mean_critic_loss", r.mean_critic_loss),
            ("mean_actor_loss", r.mean_actor_loss),
        ] {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return Err(format!(
                    "episode {}: {name} is {v}, must be finite",
                    r.episode
                ));
            }
        }
    }
    Ok(history)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(episode: usize, episodes: usize, reward: f64) -> EpisodeReport {
        EpisodeReport {
            episode,
            episodes,
            steps: 10,
            total_reward: reward,
            mean_critic_loss: (episode > 1).then_some(0.5),
            mean_actor_loss: (episode > 1).then_some(-1.5),
            noise_std: 0.1,
            elapsed_s: 2.0 * episode as f64,
            remaining_s: 2.0 * (episodes - episode) as f64,
        }
    }

    /// The message of a parse failure.
    fn message(r: Result<Vec<EpisodeReport>, MillPlanError>) -> String {
        match r {
            Err(MillPlanError::Io { path, message }) => {
                assert_eq!(path, "h.csv");
                message
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn moving_average_is_trailing_and_starts_with_what_exists() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        let m = moving_average(&v, 3);
        assert_eq!(m, vec![1.0, 1.5, 2.0, 3.0, 4.0]);
        assert_eq!(moving_average(&v, 0), v.to_vec());
        assert!(moving_average(&[], 5).is_empty());
    }

    #[test]
    fn csv_and_json_histories_read_back_exactly_and_nan_is_refused() {
        let h = vec![report(1, 2, -1.25), report(2, 2, 0.1 + 0.2)];
        assert_eq!(
            parse_history("h.csv", &history_csv(&h, 50), true).ok(),
            Some(h.clone())
        );
        let json = serde_json::to_string(&h).expect("json");
        assert_eq!(parse_history("h.csv", &json, false).ok(), Some(h.clone()));
        let mut bad = h.clone();
        bad[1].total_reward = f64::NAN;
        let e = message(parse_history("h.csv", &history_csv(&bad, 50), true));
        assert_eq!(e, "episode 2: total_reward is NaN, must be finite");
        assert!(
            message(parse_history("h.csv", "episode,steps\n1,2\n", true))
                .contains("no column `episodes`")
        );
        let header = history_csv(&h, 50)
            .lines()
            .next()
            .expect("header")
            .to_string();
        let e = message(parse_history(
            "h.csv",
            &format!("{header}\n1,2,10,x,1,,,0.1,2,2\n"),
            true,
        ));
        assert_eq!(e, "row 1: `total_reward` = `x` is not a number");
        assert_eq!(
            message(parse_history("h.csv", "[]", false)),
            "no episode in the history"
        );
        assert_eq!(
            parse_history("h.csv", "[]", false).unwrap_err().to_string(),
            "h.csv: no episode in the history"
        );
    }

    #[test]
    fn history_csv_has_a_row_per_episode_and_empty_warm_up_losses() {
        let h = [report(1, 2, 1.0), report(2, 2, 3.0)];
        let csv = history_csv(&h, 50);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("episode,episodes,steps,total_reward,moving_average_50,"));
        assert_eq!(lines[1], "1,2,10,1,1,,,0.1,2,2");
        assert_eq!(lines[2], "2,2,10,3,2,0.5,-1.5,0.1,4,0");
    }
}
