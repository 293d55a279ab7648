//! [`Chart`]: a line chart (one or more named series of (x, y), horizontal
//! limit lines, optional point markers) with its layout; rendered as a
//! standalone SVG document by [`Chart::render`] ([`super::render`]), with
//! axes, nice ticks ([`super::ticks`]) and a legend ([`super::legend`]).

use super::ticks::Axis;
use crate::error::ToolpathError;

/// Width of the document \[px\].
pub const WIDTH: f64 = 900.0;
/// Height of the document \[px\].
pub const HEIGHT: f64 = 460.0;
/// Left margin (tick labels and the y label) \[px\].
pub const LEFT: f64 = 90.0;
/// Right margin (the legend) \[px\].
pub const RIGHT: f64 = 210.0;
/// The y range is widened by this fraction of its span on each side (not
/// below 0 when no value is negative), so that limit lines at the data's
/// extremes stay inside the frame.
pub const Y_PADDING: f64 = 0.05;
/// Top margin (the title) \[px\].
pub const TOP: f64 = 40.0;
/// Bottom margin (tick labels and the x label) \[px\].
pub const BOTTOM: f64 = 60.0;
/// Consecutive points of a series closer than this in both directions are
/// drawn as one \[px\] (every dropped point is within it of a drawn one).
pub const MIN_PIXEL_STEP: f64 = 0.25;

/// Colours of the series in order (the "tab10" palette), then again.
pub(super) const PALETTE: [&str; 6] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#17becf",
];
/// Colour of limit lines.
pub(super) const LIMIT_COLOUR: &str = "#d62728";

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A polyline through the points.
    Line,
    /// A dot at every point.
    Markers,
    /// Both.
    LineAndMarkers,
}

/// A named series of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// The points in drawing order.
    pub points: Vec<[f64; 2]>,
    /// How they are drawn.
    pub style: Style,
    /// An SVG colour; `None`: the palette's by position.
    pub colour: Option<String>,
}

/// A horizontal line at a limit value.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitLine {
    /// Legend entry.
    pub name: String,
    /// Its y value.
    pub y: f64,
}

/// A line chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Title.
    pub title: String,
    /// Label of the x axis, with its unit.
    pub x_label: String,
    /// Label of the y axis, with its unit.
    pub y_label: String,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Horizontal limit lines.
    pub limits: Vec<LimitLine>,
    /// One unit is as long on both axes (geometry in a plane).
    pub equal_aspect: bool,
}

impl Chart {
    /// An empty chart.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            series: Vec::new(),
            limits: Vec::new(),
            equal_aspect: false,
        }
    }

    /// With a series drawn as a line.
    pub fn line(self, name: &str, points: Vec<[f64; 2]>) -> Self {
        self.with_series(name, points, Style::Line, None)
    }

    /// With a series of any style and an optional colour.
    pub fn with_series(
        mut self,
        name: &str,
        points: Vec<[f64; 2]>,
        style: Style,
        colour: Option<&str>,
    ) -> Self {
        self.series.push(Series {
            name: name.to_string(),
            points,
            style,
            colour: colour.map(str::to_string),
        });
        self
    }

    /// With a horizontal limit line at `y`.
    pub fn limit(mut self, name: &str, y: f64) -> Self {
        self.limits.push(LimitLine {
            name: name.to_string(),
            y,
        });
        self
    }

    /// With equal scales on both axes.
    pub fn with_equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }

    /// Checks the data: at least one point, every value finite.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming the chart, the series or
    /// limit and the point.
    pub fn validate(&self) -> Result<(), ToolpathError> {
        let bad = |name: String, value: f64, reason: &str| ToolpathError::InvalidParameter {
            name,
            value,
            reason: reason.to_string(),
        };
        if self.series.iter().all(|s| s.points.is_empty()) {
            return Err(bad(
                format!("points of chart {:?}", self.title),
                0.0,
                "a chart needs at least one point",
            ));
        }
        for s in &self.series {
            for (k, p) in s.points.iter().enumerate() {
                if let Some(v) = p.iter().find(|v| !v.is_finite()) {
                    return Err(bad(
                        format!("chart {:?}, series {:?}, point {k}", self.title, s.name),
                        *v,
                        "not finite",
                    ));
                }
            }
        }
        if let Some(l) = self.limits.iter().find(|l| !l.y.is_finite()) {
            return Err(bad(
                format!("chart {:?}, limit {:?}", self.title, l.name),
                l.y,
                "not finite",
            ));
        }
        Ok(())
    }

    /// The x and y axes the chart is drawn with: nice ranges covering every
    /// point and limit, widened on one axis for [`Chart::equal_aspect`].
    ///
    /// # Errors
    /// As [`Chart::validate`].
    pub fn axes(&self) -> Result<(Axis, Axis), ToolpathError> {
        self.validate()?;
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in self.series.iter().flat_map(|s| &s.points) {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        for l in &self.limits {
            lo[1] = lo[1].min(l.y);
            hi[1] = hi[1].max(l.y);
        }
        let pad = Y_PADDING * (hi[1] - lo[1]);
        let y_lo = if lo[1] >= 0.0 {
            (lo[1] - pad).max(0.0)
        } else {
            lo[1] - pad
        };
        let mut x = Axis::covering(lo[0], hi[0], 8);
        let mut y = Axis::covering(y_lo, hi[1] + pad, 6);
        if self.equal_aspect {
            let (w, h) = plot_size();
            let scale = (w / (x.hi - x.lo)).min(h / (y.hi - y.lo));
            for (axis, size, count) in [(&mut x, w, 8), (&mut y, h, 6)] {
                let span = size / scale;
                let centre = 0.5 * (axis.lo + axis.hi);
                axis.lo = centre - 0.5 * span;
                axis.hi = centre + 0.5 * span;
                axis.step = super::ticks::nice_step(span, count);
            }
        }
        Ok((x, y))
    }

    /// The colour of series `k`: its own, or the palette's next one (series
    /// with their own colour take none from the palette).
    pub(super) fn colour(&self, k: usize) -> String {
        self.series[k].colour.clone().unwrap_or_else(|| {
            let n = self.series[..k]
                .iter()
                .filter(|s| s.colour.is_none())
                .count();
            PALETTE[n % PALETTE.len()].to_string()
        })
    }
}

/// Width and height of the plot area \[px\].
pub fn plot_size() -> (f64, f64) {
    (WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM)
}
