//! The per-segment plot of `kerf plan mill --plots` (seed 004 Fig. 6, and Fig. 8 for the
//! g = 0 ablation): six panels over the segment index — (a) step reward (eq. 12), (b) |μ|max
//! with the |μ| = 1 line, (c) the condition indicator 1/K, (d) spindle speed Ω \[rpm\], (e)
//! feed f \[m/s\], (f) redundancy angle g \[rad\] — one curve per planner, so several
//! planners overlay.

use std::path::Path;

use kerf_millplan::plan::{Plan, SegmentPlan};
use plotters::prelude::*;

use super::chart::{
    draw_err, draw_legend, draw_level, draw_runs, figure, padded_range, with_headroom, Axes, Frame,
};
use super::PALETTE;

/// One panel of [`plan_panels`]: caption, y label and the value of a segment.
struct Panel {
    caption: &'static str,
    y_desc: &'static str,
    value: fn(&SegmentPlan) -> f64,
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
    let root = figure(path, (1300, 1100)).map_err(&err)?;
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
        let mut chart = Frame {
            caption: panel.caption,
            caption_size: 18,
            margin: 10,
            x_label_area: 36,
            y_label_area: 70,
        }
        .build(area, x0..x1, y0..y1)
        .map_err(&err)?;
        Axes {
            x_desc: "segment",
            y_desc: panel.y_desc,
            whole_x: true,
            grid: true,
        }
        .draw(&mut chart)
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
            draw_level(&mut chart, (x0, x1), 1.0, "stability limit |mu|max = 1").map_err(&err)?;
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 0.8, Some(12)).map_err(&err)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}
