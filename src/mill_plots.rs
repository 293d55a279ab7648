//! SVG plots of the milling planner (issue 5 section 2):
//!
//! * [`training_curve`] — seed 004 Fig. 5: the reward of every training episode, its moving
//!   average, and the mean actor loss per episode, against the episode number
//!   (`kerf train mill --plots DIR`);
//! * [`plan_panels`] — seed 004 Fig. 6 (and Fig. 8 for the g = 0 ablation): six panels over
//!   the segment index — (a) step reward (eq. 12), (b) |μ|max with the |μ| = 1 line, (c) the
//!   condition indicator 1/K, (d) spindle speed Ω \[rpm\], (e) feed f \[m/s\], (f) redundancy
//!   angle g \[rad\] — one curve per planner, so several planners overlay
//!   (`kerf plan mill --plots DIR`).
//!
//! Text in the SVG is ASCII (`|mu|max`, `Omega`), as in `kerf lobes`. A non-finite value
//! breaks a curve instead of being drawn.

use std::path::Path;

use kerf_millplan::{plan::Plan, EpisodeReport};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Colours of the planners' curves, in order.
const PALETTE: [RGBColor; 6] = [
    RGBColor(0x1f, 0x4e, 0xc8),
    RGBColor(0xd0, 0x30, 0x20),
    RGBColor(0x20, 0x90, 0x40),
    RGBColor(0x90, 0x40, 0xb0),
    RGBColor(0xe0, 0x90, 0x10),
    RGBColor(0x40, 0x40, 0x40),
];

/// Colour of the per-episode reward (light) under its moving average.
const EPISODE_COLOR: RGBColor = RGBColor(0x9c, 0xb8, 0xe8);

fn draw_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> String + '_ {
    move |e| format!("plot {}: {e}", path.display())
}

/// `[lo, hi]` of the finite values, padded by 5 % (a single value or none: ±1 % or ±1).
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        let pad = (0.01 * lo.abs()).max(if lo == 0.0 { 1.0 } else { 1e-9 });
        (lo - pad, hi + pad)
    }
}

/// `(lo, hi)` with `frac` × its width added on top (room for a legend in the upper corner).
fn with_headroom((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    (lo, hi + frac * (hi - lo))
}

/// Splits points into runs of consecutive finite values (a non-finite value breaks a curve).
fn runs(points: impl Iterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (x, y) in points {
        match out.last_mut() {
            Some(run) if y.is_finite() && x.is_finite() => run.push((x, y)),
            _ => out.push(Vec::new()),
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

/// The trailing moving average: entry k is the mean of `values[k + 1 − w ..= k]` with
/// w = min(k + 1, `window`) (the first entries average what exists so far). A `window` of 0
/// is treated as 1.
/// Draws `points` as lines, one per run of finite points ([`runs`]), in `colour` and `width`
/// pixels; the first run carries `label` in the legend. Returns whether any run was drawn.
fn draw_runs<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    points: impl Iterator<Item = (f64, f64)>,
    colour: RGBColor,
    width: u32,
    label: &str,
) -> Result<bool, DrawingAreaErrorKind<DB::ErrorType>> {
    let runs = runs(points);
    for (i, run) in runs.iter().enumerate() {
        let s = chart.draw_series(LineSeries::new(
            run.iter().copied(),
            colour.stroke_width(width),
        ))?;
        if i == 0 {
            s.label(label)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour));
        }
    }
    Ok(!runs.is_empty())
}

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
    let root = SVGBackend::new(path, (1000, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let root = root.titled(title, ("sans-serif", 24)).map_err(&err)?;
    let (top, bottom) = root.split_vertically(480);

    let (y0, y1) = padded_range(rewards.iter().chain(&average).copied());
    let mut chart = ChartBuilder::on(&top)
        .caption("training reward", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(&err)?;
    chart
        .configure_mesh()
        .x_label_formatter(&|x| format!("{x:.0}"))
        .x_desc("episode")
        .y_desc("episode reward")
        .draw()
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
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(&err)?;

    let losses: Vec<(f64, f64)> = history
        .iter()
        .filter_map(|r| r.mean_actor_loss.map(|l| (r.episode as f64, l)))
        .collect();
    let (l0, l1) = with_headroom(padded_range(losses.iter().map(|p| p.1)), 0.25);
    let mut chart = ChartBuilder::on(&bottom)
        .caption("actor loss", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, l0..l1)
        .map_err(&err)?;
    chart
        .configure_mesh()
        .x_label_formatter(&|x| format!("{x:.0}"))
        .x_desc("episode")
        .y_desc("mean actor loss -Q")
        .draw()
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
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(&err)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}

/// One panel of [`plan_panels`]: caption, y label and the value of a segment.
struct Panel {
    caption: &'static str,
    y_desc: &'static str,
    value: fn(&kerf_millplan::plan::SegmentPlan) -> f64,
}

/// The six panels of seed 004 Fig. 6 / Fig. 8, in the paper's order.
const PANELS: [Panel; 6] = [
    Panel {
        caption: "(a) step reward",
        y_desc: "reward r (eq. 12)",
        value: |s| s.reward.total,
    },
    Panel {
        caption: "(b) chatter indicator",
        y_desc: "|mu|max",
        value: |s| s.spectral_radius,
    },
    Panel {
        caption: "(c) condition indicator",
        y_desc: "1/K",
        value: |s| s.condition_indicator,
    },
    Panel {
        caption: "(d) spindle speed",
        y_desc: "Omega [rpm]",
        value: |s| s.rpm,
    },
    Panel {
        caption: "(e) feed",
        y_desc: "f [m/s]",
        value: |s| s.feed,
    },
    Panel {
        caption: "(f) redundancy angle",
        y_desc: "g [rad]",
        value: |s| s.g,
    },
];

/// Writes the per-segment plot of one or several plans (seed 004 Fig. 6 / Fig. 8): six
/// panels in a 3 × 2 grid over the segment index, one curve per plan labelled with its
/// name; panel (b) also draws the stability limit |μ|max = 1 (black) and always includes it
/// in its range.
///
/// # Errors
/// A message naming the file: no plan, or a drawing failure.
pub fn plan_panels(path: &Path, plans: &[(&str, &Plan)], title: &str) -> Result<(), String> {
    let err = draw_err(path);
    if plans.is_empty() || plans.iter().all(|(_, p)| p.segments.is_empty()) {
        return Err(format!("plot {}: no plan to draw", path.display()));
    }
    let last = plans
        .iter()
        .flat_map(|(_, p)| p.segments.iter().map(|s| s.segment))
        .max()
        .unwrap_or(0) as f64;
    let (x0, x1) = if last > 0.0 { (0.0, last) } else { (-0.5, 0.5) };
    let root = SVGBackend::new(path, (1300, 1100)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let root = root.titled(title, ("sans-serif", 24)).map_err(&err)?;
    let areas = root.split_evenly((3, 2));
    for (panel, area) in PANELS.iter().zip(areas.iter()) {
        let values = plans
            .iter()
            .flat_map(|(_, p)| p.segments.iter().map(panel.value));
        // Room on top for the legend (one line per plan, plus the limit in panel (b)).
        let headroom = 0.12 * (plans.len() + 1) as f64 + 0.1;
        let (y0, y1) = with_headroom(
            if panel.y_desc == "|mu|max" {
                padded_range(values.chain(std::iter::once(1.0)))
            } else {
                padded_range(values)
            },
            headroom,
        );
        let mut chart = ChartBuilder::on(area)
            .caption(panel.caption, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(&err)?;
        chart
            .configure_mesh()
            .x_label_formatter(&|x| format!("{x:.0}"))
            .x_desc("segment")
            .y_desc(panel.y_desc)
            .draw()
            .map_err(&err)?;
        for (k, (name, plan)) in plans.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let points = plan
                .segments
                .iter()
                .map(|s| (s.segment as f64, (panel.value)(s)));
            draw_runs(&mut chart, points, colour, 2, name).map_err(&err)?;
        }
        if panel.y_desc == "|mu|max" {
            chart
                .draw_series(LineSeries::new(
                    [(x0, 1.0), (x1, 1.0)],
                    BLACK.stroke_width(1),
                ))
                .map_err(&err)?
                .label("stability limit |mu|max = 1")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(&err)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_is_trailing_and_starts_with_what_exists() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        let m = moving_average(&v, 3);
        assert_eq!(m, vec![1.0, 1.5, 2.0, 3.0, 4.0]);
        assert_eq!(moving_average(&v, 0), v.to_vec());
        assert!(moving_average(&[], 5).is_empty());
    }

    #[test]
    fn runs_break_at_non_finite_values() {
        let r = runs([(0.0, 1.0), (1.0, f64::NAN), (2.0, 2.0), (3.0, 3.0)].into_iter());
        assert_eq!(r, vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]);
    }

    #[test]
    fn padded_range_ignores_non_finite_values() {
        let (lo, hi) = padded_range([1.0, f64::NAN, 3.0, f64::INFINITY].into_iter());
        assert!(
            (lo - 0.9).abs() < 1e-12 && (hi - 3.1).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert_eq!(padded_range([f64::NAN].into_iter()), (0.0, 1.0));
    }
}
