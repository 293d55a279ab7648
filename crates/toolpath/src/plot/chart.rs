//! [`Chart`]: a line chart (one or more named series of (x, y), horizontal
//! limit lines, optional point markers) rendered as a standalone SVG
//! document with axes, nice ticks ([`super::ticks`]) and a legend.

use std::fmt::Write as _;

use super::svg::{escape, line, px, text};
use super::ticks::{tick_label, Axis};
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
const PALETTE: [&str; 6] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#17becf",
];
/// Colour of limit lines.
const LIMIT_COLOUR: &str = "#d62728";

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

    /// The chart as a standalone SVG document.
    ///
    /// # Errors
    /// As [`Chart::validate`].
    pub fn render(&self) -> Result<String, ToolpathError> {
        let (xa, ya) = self.axes()?;
        let (w, h) = plot_size();
        let to_px = |p: [f64; 2]| {
            (
                LEFT + xa.fraction(p[0]) * w,
                TOP + (1.0 - ya.fraction(p[1])) * h,
            )
        };
        let mut out = String::new();
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(out, "<title>{}</title>", escape(&self.title));
        let _ = writeln!(
            out,
            r#"<rect class="background" x="0" y="0" width="{WIDTH}" height="{HEIGHT}" fill="white"/>"#
        );
        let _ = writeln!(
            out,
            r#"<defs><clipPath id="plot-area"><rect x="{LEFT}" y="{TOP}" width="{}" height="{}"/></clipPath></defs>"#,
            px(w),
            px(h)
        );
        // Grid, ticks and their labels.
        out.push_str("<g class=\"axes\" stroke=\"#dddddd\">\n");
        for v in xa.ticks() {
            let (x, _) = to_px([v, ya.lo]);
            line(&mut out, (x, TOP), (x, TOP + h), r#" class="grid""#);
            line(
                &mut out,
                (x, TOP + h),
                (x, TOP + h + 5.0),
                r#" class="tick" stroke="black""#,
            );
            text(
                &mut out,
                x,
                TOP + h + 18.0,
                "middle",
                r#" class="tick-label" stroke="none""#,
                &tick_label(v, xa.step),
            );
        }
        for v in ya.ticks() {
            let (_, y) = to_px([xa.lo, v]);
            line(&mut out, (LEFT, y), (LEFT + w, y), r#" class="grid""#);
            line(
                &mut out,
                (LEFT - 5.0, y),
                (LEFT, y),
                r#" class="tick" stroke="black""#,
            );
            text(
                &mut out,
                LEFT - 8.0,
                y + 4.0,
                "end",
                r#" class="tick-label" stroke="none""#,
                &tick_label(v, ya.step),
            );
        }
        out.push_str("</g>\n");
        text(
            &mut out,
            LEFT + 0.5 * w,
            24.0,
            "middle",
            r#" class="title" font-size="15""#,
            &self.title,
        );
        text(
            &mut out,
            LEFT + 0.5 * w,
            HEIGHT - 14.0,
            "middle",
            r#" class="x-label""#,
            &self.x_label,
        );
        let (lx, ly) = (18.0, TOP + 0.5 * h);
        text(
            &mut out,
            lx,
            ly,
            "middle",
            &format!(
                r#" class="y-label" transform="rotate(-90 {} {})""#,
                px(lx),
                px(ly)
            ),
            &self.y_label,
        );
        // Series.
        out.push_str("<g class=\"data\" clip-path=\"url(#plot-area)\">\n");
        for (k, s) in self.series.iter().enumerate() {
            let colour = self.colour(k);
            let drawn = thin(s.points.iter().map(|p| to_px(*p)));
            if matches!(s.style, Style::Line | Style::LineAndMarkers) {
                let mut pts = String::with_capacity(drawn.len() * 14);
                for (x, y) in &drawn {
                    let _ = write!(pts, "{},{} ", px(*x), px(*y));
                }
                let _ = writeln!(
                    out,
                    r#"<polyline class="series" data-name="{}" fill="none" stroke="{colour}" stroke-width="1.5" points="{}"/>"#,
                    escape(&s.name),
                    pts.trim_end()
                );
            }
            if matches!(s.style, Style::Markers | Style::LineAndMarkers) {
                let _ = writeln!(
                    out,
                    r#"<g class="markers" data-name="{}" fill="{colour}">"#,
                    escape(&s.name)
                );
                for (x, y) in &drawn {
                    let _ = writeln!(out, r#"<circle cx="{}" cy="{}" r="2.5"/>"#, px(*x), px(*y));
                }
                out.push_str("</g>\n");
            }
        }
        for l in &self.limits {
            let (_, y) = to_px([xa.lo, l.y]);
            line(
                &mut out,
                (LEFT, y),
                (LEFT + w, y),
                &format!(
                    r#" class="limit" data-name="{}" stroke="{LIMIT_COLOUR}" stroke-width="1.2" stroke-dasharray="6 4""#,
                    escape(&l.name)
                ),
            );
        }
        out.push_str("</g>\n");
        self.legend(&mut out, w);
        let _ = writeln!(
            out,
            r#"<rect class="frame" x="{LEFT}" y="{TOP}" width="{}" height="{}" fill="none" stroke="black"/>"#,
            px(w),
            px(h)
        );
        out.push_str("</svg>\n");
        Ok(out)
    }

    /// The colour of series `k`: its own, or the palette's next one (series
    /// with their own colour take none from the palette).
    fn colour(&self, k: usize) -> String {
        self.series[k].colour.clone().unwrap_or_else(|| {
            let n = self.series[..k]
                .iter()
                .filter(|s| s.colour.is_none())
                .count();
            PALETTE[n % PALETTE.len()].to_string()
        })
    }

    /// The legend, right of the plot area.
    fn legend(&self, out: &mut String, w: f64) {
        let entries: Vec<(String, String, &str)> = self
            .series
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let kind = match s.style {
                    Style::Markers => "marker",
                    _ => "line",
                };
                (s.name.clone(), self.colour(k), kind)
            })
            .chain(
                self.limits
                    .iter()
                    .map(|l| (l.name.clone(), LIMIT_COLOUR.to_string(), "limit")),
            )
            .collect();
        let longest = entries
            .iter()
            .map(|e| e.0.chars().count())
            .max()
            .unwrap_or(0);
        let (bw, bh) = (
            40.0 + 7.0 * longest as f64,
            8.0 + 18.0 * entries.len() as f64,
        );
        let (x0, y0) = (LEFT + w + 10.0, TOP);
        let _ = writeln!(
            out,
            r##"<g class="legend"><rect x="{}" y="{}" width="{}" height="{}" fill="white" fill-opacity="0.85" stroke="#999999"/>"##,
            px(x0),
            px(y0),
            px(bw),
            px(bh)
        );
        for (k, (name, colour, kind)) in entries.iter().enumerate() {
            let y = y0 + 16.0 + 18.0 * k as f64;
            match *kind {
                "marker" => {
                    let _ = writeln!(
                        out,
                        r#"<circle cx="{}" cy="{}" r="3" fill="{colour}"/>"#,
                        px(x0 + 18.0),
                        px(y - 4.0)
                    );
                }
                "limit" => line(
                    out,
                    (x0 + 6.0, y - 4.0),
                    (x0 + 30.0, y - 4.0),
                    &format!(r#" stroke="{colour}" stroke-dasharray="6 4""#),
                ),
                _ => line(
                    out,
                    (x0 + 6.0, y - 4.0),
                    (x0 + 30.0, y - 4.0),
                    &format!(r#" stroke="{colour}" stroke-width="1.5""#),
                ),
            }
            text(out, x0 + 36.0, y, "start", "", name);
        }
        out.push_str("</g>\n");
    }
}

/// Width and height of the plot area \[px\].
pub fn plot_size() -> (f64, f64) {
    (WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM)
}

/// The pixel points to draw: a point within [`MIN_PIXEL_STEP`] of the last
/// drawn one in both directions is dropped, the last point always kept.
fn thin(points: impl Iterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut last_dropped = None;
    for p in points {
        match out.last() {
            Some(q) if (p.0 - q.0).abs() < MIN_PIXEL_STEP && (p.1 - q.1).abs() < MIN_PIXEL_STEP => {
                last_dropped = Some(p);
            }
            _ => {
                out.push(p);
                last_dropped = None;
            }
        }
    }
    out.extend(last_dropped);
    out
}
