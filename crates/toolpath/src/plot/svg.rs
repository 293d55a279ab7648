//! The few pieces of SVG text the charts write.

use std::fmt::Write as _;

/// `text` with `&`, `<`, `>` and `"` escaped for SVG text and attributes.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

/// A pixel coordinate with two decimals (a hundredth of a pixel).
pub fn px(v: f64) -> String {
    let r = (v * 100.0).round() / 100.0;
    // −0.00 reads as 0.
    format!("{}", if r == 0.0 { 0.0 } else { r })
}

/// Appends `<text>` at (x, y) with an anchor and extra attributes.
pub fn text(out: &mut String, x: f64, y: f64, anchor: &str, extra: &str, body: &str) {
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}" text-anchor="{anchor}"{extra}>{}</text>"#,
        px(x),
        px(y),
        escape(body)
    );
}

/// Appends a `<line>` from (x1, y1) to (x2, y2) with extra attributes.
pub fn line(out: &mut String, (x1, y1): (f64, f64), (x2, y2): (f64, f64), extra: &str) {
    let _ = writeln!(
        out,
        r#"<line x1="{}" y1="{}" x2="{}" y2="{}"{extra}/>"#,
        px(x1),
        px(y1),
        px(x2),
        px(y2)
    );
}
