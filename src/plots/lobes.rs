//! The stability-lobe diagram of `kerf lobes` (seed 004 Fig. 4 style): critical axial depth
//! against spindle speed.

use std::path::Path;

use kerf_chatter::LobeMap;
use plotters::prelude::*;

use super::chart::{
    draw_err, draw_legend, draw_level, draw_runs, figure, widen, Axes, Chart, Frame, PlotError,
};

/// Colour of the constant-delay lobe.
const CONSTANT_COLOR: RGBColor = RGBColor(0x1f, 0x4e, 0xc8);
/// Colour of the state-dependent lobe.
const SD_COLOR: RGBColor = RGBColor(0xd0, 0x30, 0x20);

/// `(speed, depth in mm)` per speed, NaN where the cut is stable up to the max depth (a
/// break in the curve).
fn depths_mm<'a>(
    rpms: impl Iterator<Item = f64> + 'a,
    depths: impl Iterator<Item = Option<f64>> + 'a,
) -> impl Iterator<Item = (f64, f64)> + 'a {
    rpms.zip(depths)
        .map(|(rpm, d)| (rpm, d.map_or(f64::NAN, |d| d * 1e3)))
}

/// Marks every speed stable up to the max depth (`None`) by a hollow circle of `radius`
/// pixels in `colour` at depth `top` \[mm\].
///
/// # Errors
/// A drawing failure.
fn stable_marks(
    chart: &mut Chart<'_, '_>,
    depths: impl Iterator<Item = (f64, Option<f64>)>,
    top: f64,
    (radius, colour): (u32, RGBColor),
) -> Result<(), PlotError> {
    let marks: Vec<(f64, f64)> = depths
        .filter(|(_, d)| d.is_none())
        .map(|(rpm, _)| (rpm, top))
        .collect();
    chart.draw_series(
        marks
            .into_iter()
            .map(|c| Circle::new(c, radius, colour.stroke_width(1))),
    )?;
    Ok(())
}

/// Writes the lobe diagram: a_lim \[mm\] against spindle speed \[rpm\], constant-delay lobe
/// (blue), state-dependent lobe at the nominal feed (red, state-dependent model only), the
/// process's axial depth (black). Speeds stable up to the max depth are marked by hollow
/// circles on the top edge.
///
/// # Arguments
/// * `path` – the SVG file; `r` – the chart.
/// * `segment`, `g`, `condition_number` – the state, for the caption.
///
/// # Errors
/// A message naming the file that could not be drawn.
pub fn lobe_diagram(
    path: &Path,
    r: &LobeMap,
    segment: usize,
    g: f64,
    condition_number: f64,
) -> Result<(), String> {
    let err = draw_err(path);
    let (x0, x1) = widen(
        r.rpms.first().copied().unwrap_or(0.0),
        r.rpms.last().copied().unwrap_or(1.0),
        0.0,
        1e-9,
    );
    let top = r.options.max_depth * 1e3;
    // y range: up to 1.3 × the largest finite depth drawn (critical depths, cell depth),
    // never above the searched range (stable-to-max speeds are drawn at `top`).
    let any_stable = r.constant.iter().any(|p| p.critical_depth.is_none())
        || r.state_dependent
            .as_ref()
            .is_some_and(|v| v.iter().any(|d| d.is_none()));
    let drawn = r
        .constant
        .iter()
        .filter_map(|p| p.critical_depth)
        .chain(r.state_dependent.iter().flatten().flatten().copied())
        .chain(std::iter::once(r.process.axial_depth))
        .map(|d| d * 1e3)
        .filter(|d| d.is_finite())
        .fold(0.0_f64, f64::max);
    let y_top = if any_stable {
        top * 1.05
    } else {
        (1.3 * drawn).clamp(1e-3, top * 1.05)
    };
    let root = figure(path, (1000, 650)).map_err(&err)?;
    let caption =
        format!("Stability lobes, segment {segment}, g = {g} rad (K = {condition_number:.3})");
    let mut chart = Frame {
        caption: &caption,
        caption_size: 24,
        margin: 15,
        x_label_area: 50,
        y_label_area: 70,
    }
    .build(&root, x0..x1, 0.0..y_top)
    .map_err(&err)?;
    Axes {
        x_desc: "spindle speed [rpm]",
        y_desc: "critical axial depth a_lim [mm]",
        whole_x: false,
        grid: true,
    }
    .draw(&mut chart)
    .map_err(&err)?;
    draw_runs(
        &mut chart,
        depths_mm(
            r.constant.iter().map(|p| p.rpm),
            r.constant.iter().map(|p| p.critical_depth),
        ),
        CONSTANT_COLOR,
        2,
        "constant delay (Insperger & Stepan 2004)",
    )
    .map_err(&err)?;
    stable_marks(
        &mut chart,
        r.constant.iter().map(|p| (p.rpm, p.critical_depth)),
        top,
        (4, CONSTANT_COLOR),
    )
    .map_err(&err)?;
    if let Some(sd) = &r.state_dependent {
        draw_runs(
            &mut chart,
            depths_mm(r.rpms.iter().copied(), sd.iter().copied()),
            SD_COLOR,
            2,
            &format!("state-dependent, feed {} m/s (seed 004)", r.nominal_feed),
        )
        .map_err(&err)?;
        stable_marks(
            &mut chart,
            r.rpms.iter().copied().zip(sd.iter().copied()),
            top,
            (3, SD_COLOR),
        )
        .map_err(&err)?;
    }
    let depth = r.process.axial_depth * 1e3;
    draw_level(
        &mut chart,
        (x0, x1),
        depth,
        &format!("cell axial depth {depth} mm"),
    )
    .map_err(&err)?;
    draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, 0.85, None).map_err(&err)?;
    root.present().map_err(&err)?;
    Ok(())
}
