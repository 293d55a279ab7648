//! [`Chart::render`]: a chart as a standalone SVG document.

use std::fmt::Write as _;

use super::chart::{
    plot_size, Chart, Style, HEIGHT, LEFT, LIMIT_COLOUR, MIN_PIXEL_STEP, TOP, WIDTH,
};
use super::legend::legend;
use super::svg::{escape, line, px, text};
use super::ticks::tick_label;
use crate::error::ToolpathError;

impl Chart {
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
        legend(self, &mut out, w);
        let _ = writeln!(
            out,
            r#"<rect class="frame" x="{LEFT}" y="{TOP}" width="{}" height="{}" fill="none" stroke="black"/>"#,
            px(w),
            px(h)
        );
        out.push_str("</svg>\n");
        Ok(out)
    }
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
