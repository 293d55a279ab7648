//! The progress display of `kerf train mill` on stderr: a bar redrawn in place on a
//! terminal, else a line every N episodes, and at least one every [`MAX_SILENCE_S`] seconds
//! (slow episodes, e.g. wide `--hidden` layers, never leave a long run silent).

use kerf_millplan::EpisodeReport;

/// `12s`, `4m50s`, `1h02m03s` (rounded to the second; `?` for a non-finite or negative
/// time).
pub fn format_duration(seconds: f64) -> String {
    if !(seconds.is_finite() && seconds >= 0.0) {
        return "?".to_string();
    }
    let s = seconds.round() as u64;
    let (h, m, s) = (s / 3600, (s / 60) % 60, s % 60);
    if h > 0 {
        format!("{h}h{m:02}m{s:02}s")
    } else if m > 0 {
        format!("{m}m{s:02}s")
    } else {
        format!("{s}s")
    }
}

/// The progress display of a run (module documentation).
pub struct Progress {
    rewards: Vec<f64>,
    /// Running sum over the last `window` rewards.
    window_sum: f64,
    window: usize,
    terminal: bool,
    log_every: usize,
    /// Elapsed time of the last line printed (s).
    last_line_s: f64,
}

/// Longest time between two progress lines when stderr is no terminal (s), checked after each
/// episode.
pub const MAX_SILENCE_S: f64 = 10.0;

/// Width of the progress bar in characters.
pub const BAR_WIDTH: usize = 20;

impl Progress {
    pub fn new(window: usize, terminal: bool, log_every: usize) -> Self {
        Self {
            rewards: Vec::new(),
            window_sum: 0.0,
            window: window.max(1),
            terminal,
            log_every: log_every.max(1),
            last_line_s: 0.0,
        }
    }

    /// Records an episode and returns the text to print (empty when nothing is due).
    pub fn update(&mut self, r: &EpisodeReport) -> String {
        self.rewards.push(r.total_reward);
        self.window_sum += r.total_reward;
        let n = self.rewards.len();
        if n > self.window {
            self.window_sum -= self.rewards[n - 1 - self.window];
        }
        let average = self.window_sum / n.min(self.window) as f64;
        let last = r.episode >= r.episodes;
        let stats = format!(
            "reward {:>9.3}, average({}) {:>9.3}, σ {:.4}, {} elapsed, {} left",
            r.total_reward,
            self.window,
            average,
            r.noise_std,
            format_duration(r.elapsed_s),
            format_duration(r.remaining_s)
        );
        if self.terminal {
            let filled = (BAR_WIDTH * r.episode)
                .checked_div(r.episodes)
                .unwrap_or(BAR_WIDTH)
                .min(BAR_WIDTH);
            let bar: String = std::iter::repeat_n('#', filled)
                .chain(std::iter::repeat_n('.', BAR_WIDTH - filled))
                .collect();
            // \r + clear to the end of the line (ANSI), then the bar.
            let mut s = format!("\r\x1b[K[{bar}] {}/{} {stats}", r.episode, r.episodes);
            if last {
                s.push('\n');
            }
            s
        } else if r.episode.is_multiple_of(self.log_every)
            || last
            || r.episode == 1
            || r.elapsed_s - self.last_line_s >= MAX_SILENCE_S
        {
            self.last_line_s = r.elapsed_s;
            format!("episode {}/{}: {stats}\n", r.episode, r.episodes)
        } else {
            String::new()
        }
    }
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

    #[test]
    fn slow_episodes_still_print_a_line_every_ten_seconds() {
        // One line every 100 episodes, but 6 s per episode: a line every other episode.
        let mut p = Progress::new(2, false, 100);
        let slow = |e: usize| EpisodeReport {
            elapsed_s: 6.0 * e as f64,
            ..report(e, 1000, 1.0)
        };
        let printed: Vec<usize> = (1..=7)
            .filter(|&e| !p.update(&slow(e)).is_empty())
            .collect();
        assert_eq!(printed, [1, 3, 5, 7]);
    }

    #[test]
    fn durations_read_as_hours_minutes_seconds() {
        assert_eq!(format_duration(12.4), "12s");
        assert_eq!(format_duration(290.0), "4m50s");
        assert_eq!(format_duration(3723.0), "1h02m03s");
        assert_eq!(format_duration(f64::NAN), "?");
        assert_eq!(format_duration(-1.0), "?");
    }

    #[test]
    fn progress_lines_every_n_episodes_with_the_moving_average() {
        let mut p = Progress::new(2, false, 2);
        let first = p.update(&report(1, 4, 1.0));
        assert!(
            first.starts_with("episode 1/4: reward     1.000, average(2)     1.000"),
            "{first}"
        );
        assert!(first.contains("2s elapsed, 6s left"), "{first}");
        assert!(p
            .update(&report(2, 4, 3.0))
            .contains("average(2)     2.000"));
        assert!(p.update(&report(3, 4, 5.0)).is_empty());
        let last = p.update(&report(4, 4, 7.0));
        // Average of the last two: (5 + 7) / 2.
        assert!(last.contains("average(2)     6.000"), "{last}");
    }

    #[test]
    fn terminal_progress_is_a_bar_redrawn_in_place() {
        let mut p = Progress::new(10, true, 1);
        let s = p.update(&report(1, 4, -2.0));
        assert!(s.starts_with("\r\x1b[K[#####...............] 1/4"), "{s:?}");
        assert!(s.contains("] 1/4 reward"), "{s:?}");
        assert!(!s.ends_with('\n'));
        for k in 2..4 {
            p.update(&report(k, 4, -2.0));
        }
        let s = p.update(&report(4, 4, -2.0));
        assert!(
            s.contains(&"#".repeat(BAR_WIDTH)) && s.ends_with('\n'),
            "{s:?}"
        );
    }
}
