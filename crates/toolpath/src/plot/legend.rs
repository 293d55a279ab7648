//! The legend of a [`Chart`]: one entry per series (a line or a dot in its
//! colour) and per limit line (dashed), right of the plot area.

use std::fmt::Write as _;

use super::chart::{Chart, Style, LEFT, LIMIT_COLOUR, TOP};
use super::svg::{line, px, text};

/// Appends the legend of `chart`, whose plot area is `w` pixels wide.
pub(super) fn legend(chart: &Chart, out: &mut String, w: f64) {
    let entries: Vec<(String, String, &str)> = chart
        .series
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let kind = match s.style {
                Style::Markers => "marker",
                _ => "line",
            };
            (s.name.clone(), chart.colour(k), kind)
        })
        .chain(
            chart
                .limits
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
