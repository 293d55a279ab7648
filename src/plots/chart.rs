//! The helper layer every figure of `kerf` draws with: a white SVG figure, Cartesian charts
//! with a caption and label areas, axes, padded ranges, line runs with legend entries, a
//! horizontal reference line and the legend box.

use std::{fmt::Display, ops::Range, path::Path};

use plotters::coord::{types::RangedCoordf64, Shift};
use plotters::prelude::*;

/// The drawing area of a figure (or of one of its panels).
pub type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;

/// A chart with `f64` axes on a figure.
pub type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A drawing failure of plotters' SVG backend.
pub type PlotError = DrawingAreaErrorKind<std::io::Error>;

/// Maps a drawing failure to the message `plot PATH: error`.
///
/// # Arguments
/// * `path` – the file being drawn.
///
/// # Returns
/// The mapping, for `map_err`.
pub fn draw_err<E: Display>(path: &Path) -> impl Fn(E) -> String + '_ {
    move |e| format!("plot {}: {e}", path.display())
}

/// A figure of `size` pixels written to `path`, filled white.
///
/// # Arguments
/// * `path` – the SVG file; `size` – width and height in pixels.
///
/// # Returns
/// The figure's drawing area.
///
/// # Errors
/// A drawing failure.
pub fn figure(path: &Path, size: (u32, u32)) -> Result<Area<'_>, PlotError> {
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    Ok(root)
}

/// How a chart is framed: its caption and the space around it.
pub struct Frame<'c> {
    /// Caption above the chart.
    pub caption: &'c str,
    /// Caption font size (sans-serif).
    pub caption_size: u32,
    /// Margin around the chart in pixels.
    pub margin: u32,
    /// Height of the x label area in pixels.
    pub x_label_area: u32,
    /// Width of the y label area in pixels.
    pub y_label_area: u32,
}

impl Frame<'_> {
    /// Builds the chart of ranges `x` × `y` on `area`.
    ///
    /// # Arguments
    /// * `area` – the figure or panel; `x`, `y` – the axis ranges.
    ///
    /// # Returns
    /// The chart.
    ///
    /// # Errors
    /// A drawing failure.
    pub fn build<'a, 'b>(
        &self,
        area: &'a Area<'b>,
        x: Range<f64>,
        y: Range<f64>,
    ) -> Result<Chart<'a, 'b>, PlotError> {
        ChartBuilder::on(area)
            .caption(self.caption, ("sans-serif", self.caption_size))
            .margin(self.margin)
            .x_label_area_size(self.x_label_area)
            .y_label_area_size(self.y_label_area)
            .build_cartesian_2d(x, y)
    }
}

/// How the axes of a chart are labelled.
pub struct Axes<'d> {
    /// The x axis's description.
    pub x_desc: &'d str,
    /// The y axis's description.
    pub y_desc: &'d str,
    /// x tick labels as whole numbers (segments, episodes).
    pub whole_x: bool,
    /// Draw the background grid.
    pub grid: bool,
}

impl Axes<'_> {
    /// Draws the axes (and the grid) of `chart`.
    ///
    /// # Errors
    /// A drawing failure.
    pub fn draw(&self, chart: &mut Chart<'_, '_>) -> Result<(), PlotError> {
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(self.x_desc).y_desc(self.y_desc);
        if self.whole_x {
            mesh.x_label_formatter(&|x| format!("{x:.0}"));
        }
        if !self.grid {
            mesh.disable_mesh();
        }
        mesh.draw()
    }
}

/// The smallest and largest finite value, or `None` when there is none.
pub fn finite_bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    lo.is_finite().then_some((lo, hi))
}

/// `[lo, hi]` padded by `frac` of its width on both sides; a flat range (lo = hi) gets ±1 %
/// of its value, at least `tiny` (±1 when the value is 0).
pub fn widen(lo: f64, hi: f64, frac: f64, tiny: f64) -> (f64, f64) {
    let pad = if hi > lo {
        frac * (hi - lo)
    } else {
        (0.01 * lo.abs()).max(if lo == 0.0 { 1.0 } else { tiny })
    };
    (lo - pad, hi + pad)
}

/// `[lo, hi]` of the finite values, padded by 5 % (a single value: ±1 %, at least 1e-9, or
/// ±1; no value: `(0, 1)`).
pub fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    finite_bounds(values).map_or((0.0, 1.0), |(lo, hi)| widen(lo, hi, 0.05, 1e-9))
}

/// `(lo, hi)` with `frac` × its width added on top (room for a legend in the upper corner).
pub fn with_headroom((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    (lo, hi + frac * (hi - lo))
}

/// Splits points into runs of consecutive finite values (a non-finite value breaks a curve).
pub fn runs(points: impl Iterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
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

/// A legend sample: a 20-pixel line in `colour`.
fn sample(colour: RGBColor) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour)
}

/// Draws `points` as lines, one per run of finite points ([`runs`]), in `colour` and `width`
/// pixels; the first run carries `label` in the legend.
///
/// # Returns
/// Whether any run was drawn.
///
/// # Errors
/// A drawing failure.
pub fn draw_runs(
    chart: &mut Chart<'_, '_>,
    points: impl Iterator<Item = (f64, f64)>,
    colour: RGBColor,
    width: u32,
    label: &str,
) -> Result<bool, PlotError> {
    let runs = runs(points);
    for (i, run) in runs.iter().enumerate() {
        let s = chart.draw_series(LineSeries::new(
            run.iter().copied(),
            colour.stroke_width(width),
        ))?;
        if i == 0 {
            s.label(label).legend(sample(colour));
        }
    }
    Ok(!runs.is_empty())
}

/// Draws the horizontal line y = `y` from `x0` to `x1` (black, 1 pixel) with `label` in the
/// legend.
///
/// # Errors
/// A drawing failure.
pub fn draw_level(
    chart: &mut Chart<'_, '_>,
    (x0, x1): (f64, f64),
    y: f64,
    label: &str,
) -> Result<(), PlotError> {
    chart
        .draw_series(LineSeries::new([(x0, y), (x1, y)], BLACK.stroke_width(1)))?
        .label(label)
        .legend(sample(BLACK));
    Ok(())
}

/// Draws the legend box: `background` opacity over white, black border, at `position`, in
/// the label font size `font` (plotters' default when `None`).
///
/// # Errors
/// A drawing failure.
pub fn draw_legend<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    position: SeriesLabelPosition,
    background: f64,
    font: Option<u32>,
) -> Result<(), PlotError> {
    let mut labels = chart.configure_series_labels();
    labels
        .background_style(WHITE.mix(background))
        .border_style(BLACK)
        .position(position);
    if let Some(size) = font {
        labels.label_font(("sans-serif", size));
    }
    labels.draw()
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn widen_without_padding_keeps_a_range_and_opens_a_flat_one() {
        assert_eq!(widen(2.0, 5.0, 0.0, 1e-9), (2.0, 5.0));
        assert_eq!(widen(0.0, 0.0, 0.05, 1e-9), (-1.0, 1.0));
        let (lo, hi) = widen(2.0, 2.0, 0.05, 1e-9);
        assert!((lo - 1.98).abs() < 1e-12 && (hi - 2.02).abs() < 1e-12);
        assert_eq!(finite_bounds([f64::NAN].into_iter()), None);
    }
}
