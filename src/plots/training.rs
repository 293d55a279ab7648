//! The training curve of `kerf train mill --plots` and `kerf train curve` (seed 004 Fig. 5):
//! the reward of every training episode, its moving average, and the mean actor loss per
//! episode, against the episode number.

use std::path::Path;

use kerf_millplan::{history::moving_average, EpisodeReport};
use plotters::prelude::*;

use super::chart::{
    draw_err, draw_legend, draw_runs, figure, padded_range, with_headroom, Axes, Frame,
};
use super::PALETTE;

/// Colour of the per-episode reward (light) under its moving average.
const EPISODE_COLOR: RGBColor = RGBColor(0x9c, 0xb8, 0xe8);

/// The frame of one of the two panels.
fn panel(caption: &str) -> Frame<'_> {
    Frame {
        caption,
        caption_size: 18,
        margin: 12,
        x_label_area: 40,
        y_label_area: 70,
    }
}

/// Episode axes with `y_desc`.
fn episode_axes(y_desc: &str) -> Axes<'_> {
    Axes {
        x_desc: "episode",
        y_desc,
        whole_x: true,
        grid: true,
    }
}

/// Writes the training curve (seed 004 Fig. 5): top panel, the total reward of every episode
/// (light blue) and its moving average over `window` episodes (dark blue) against the
/// episode number; bottom panel, the mean actor loss L_a = −mean Q of every episode
/// (episodes without an update, the warm-up, are left out).
///
/// # Errors
/// A message naming the file: no episode, or a drawing failure.
pub fn training_curve(
    path: &Path,
    history: &[EpisodeReport],
    window: usize,
    title: &str,
) -> Result<(), String> {
    let err = draw_err(path);
    if history.is_empty() {
        return Err(format!("plot {}: no training episode", path.display()));
    }
    let episodes: Vec<f64> = history.iter().map(|r| r.episode as f64).collect();
    let rewards: Vec<f64> = history.iter().map(|r| r.total_reward).collect();
    let average = moving_average(&rewards, window);
    let (x0, x1) = padded_range(episodes.iter().copied());
    let root = figure(path, (1000, 800)).map_err(&err)?;
    let root = root.titled(title, ("sans-serif", 24)).map_err(&err)?;
    let (top, bottom) = root.split_vertically(480);

    let (y0, y1) = padded_range(rewards.iter().chain(&average).copied());
    let mut chart = panel("training reward")
        .build(&top, x0..x1, y0..y1)
        .map_err(&err)?;
    episode_axes("episode reward")
        .draw(&mut chart)
        .map_err(&err)?;
    draw_runs(
        &mut chart,
        episodes.iter().copied().zip(rewards.iter().copied()),
        EPISODE_COLOR,
        1,
        "episode reward",
    )
    .map_err(&err)?;
    draw_runs(
        &mut chart,
        episodes.iter().copied().zip(average.iter().copied()),
        PALETTE[0],
        3,
        &format!("moving average ({} episodes)", window.max(1)),
    )
    .map_err(&err)?;
    draw_legend(&mut chart, SeriesLabelPosition::LowerRight, 0.85, None).map_err(&err)?;

    let losses: Vec<(f64, f64)> = history
        .iter()
        .filter_map(|r| r.mean_actor_loss.map(|l| (r.episode as f64, l)))
        .collect();
    let (l0, l1) = with_headroom(padded_range(losses.iter().map(|p| p.1)), 0.25);
    let mut chart = panel("actor loss")
        .build(&bottom, x0..x1, l0..l1)
        .map_err(&err)?;
    episode_axes("mean actor loss -Q")
        .draw(&mut chart)
        .map_err(&err)?;
    if draw_runs(
        &mut chart,
        losses.into_iter(),
        PALETTE[1],
        2,
        "mean actor loss per episode",
    )
    .map_err(&err)?
    {
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 0.85, None).map_err(&err)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}
