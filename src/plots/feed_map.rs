//! The feed map of `kerf lobes` (seed 004 Fig. 7 style): |μ|max at the process's depth over
//! feed × spindle speed as coloured cells, the |μ| = 1 boundary (marching squares) and a
//! colour bar.

use std::path::Path;

use kerf_chatter::{DelayModel, LobeMap};
use plotters::prelude::*;

use super::chart::{draw_err, figure, finite_bounds, widen, Axes, Frame};

/// Colour of map cells where |μ| is undefined (f = 0 with a sublinear force law).
const UNDEFINED_COLOR: RGBColor = RGBColor(0xb0, 0xb0, 0xb0);

/// A perceptually ordered colour for `t` ∈ [0, 1] (piecewise-linear through five samples of
/// the viridis map: dark blue → green → yellow).
pub fn colormap(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut k = 0;
    while k + 2 < STOPS.len() && t > STOPS[k + 1].0 {
        k += 1;
    }
    let (ta, a) = STOPS[k];
    let (tb, b) = STOPS[k + 1];
    let w = if tb > ta { (t - ta) / (tb - ta) } else { 0.0 };
    let c = |i: usize| (a[i] + w * (b[i] - a[i])).round().clamp(0.0, 255.0) as u8;
    RGBColor(c(0), c(1), c(2))
}

/// Segments of the `level` contour of `z[i][j]` sampled at `(xs[i], ys[j])` by marching
/// squares (linear interpolation on the cell edges; a saddle cell is resolved by its
/// centre value, the mean of its corners).
pub fn contour(xs: &[f64], ys: &[f64], z: &[Vec<f64>], level: f64) -> Vec<[(f64, f64); 2]> {
    let mut segs = Vec::new();
    let at = |i: usize, j: usize| z.get(i).and_then(|r| r.get(j)).copied();
    for i in 0..xs.len().saturating_sub(1) {
        for j in 0..ys.len().saturating_sub(1) {
            let (Some(z00), Some(z10), Some(z11), Some(z01)) =
                (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1))
            else {
                continue;
            };
            if ![z00, z10, z11, z01].iter().all(|v| v.is_finite()) {
                continue;
            }
            // Corners counter-clockwise: (i, j), (i+1, j), (i+1, j+1), (i, j+1).
            let corners = [
                (xs[i], ys[j], z00),
                (xs[i + 1], ys[j], z10),
                (xs[i + 1], ys[j + 1], z11),
                (xs[i], ys[j + 1], z01),
            ];
            let mut pts = Vec::with_capacity(4);
            for e in 0..4 {
                let (xa, ya, za) = corners[e];
                let (xb, yb, zb) = corners[(e + 1) % 4];
                if (za >= level) != (zb >= level) {
                    let w = (level - za) / (zb - za);
                    pts.push((xa + w * (xb - xa), ya + w * (yb - ya)));
                }
            }
            match pts.len() {
                2 => segs.push([pts[0], pts[1]]),
                4 => {
                    // Saddle (corners 0 and 2 on one side, 1 and 3 on the other; edge e
                    // joins corners e and e+1). Centre on corner 0's side: corners 0 and 2
                    // connect through it and corners 1 and 3 are cut off, by (edge 0, edge 1)
                    // and (edge 2, edge 3); otherwise corners 0 and 2 are cut off, by
                    // (edge 3, edge 0) and (edge 1, edge 2).
                    let centre = 0.25 * (z00 + z10 + z11 + z01);
                    if (centre >= level) == (z00 >= level) {
                        segs.push([pts[0], pts[1]]);
                        segs.push([pts[2], pts[3]]);
                    } else {
                        segs.push([pts[3], pts[0]]);
                        segs.push([pts[1], pts[2]]);
                    }
                }
                _ => {}
            }
        }
    }
    segs
}

/// Cell edges around grid values: midpoints between neighbours, half a step beyond the ends
/// (a single value gets ±`pad`).
fn edges(v: &[f64], pad: f64) -> Vec<f64> {
    match v {
        [] => Vec::new(),
        [x] => vec![x - pad, x + pad],
        _ => {
            let mut e = Vec::with_capacity(v.len() + 1);
            e.push(v[0] - 0.5 * (v[1] - v[0]));
            for w in v.windows(2) {
                e.push(0.5 * (w[0] + w[1]));
            }
            let n = v.len();
            e.push(v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]));
            e
        }
    }
}

/// `[lo, hi]` widened to a non-empty range (±1 % of the value, or ±1, when lo = hi).
fn span(lo: f64, hi: f64) -> (f64, f64) {
    widen(lo, hi, 0.0, 1e-9)
}

/// Writes the feed map: |μ|max at the process's depth as coloured cells over spindle speed
/// \[rpm\] (x) × feed \[m/s\] (y), the |μ| = 1 boundary as a black polyline (marching
/// squares; cells with an undefined |μ| are grey and skipped), unstable cells outlined in
/// white when the grid is one row or column wide (no contour exists then), and a colour bar.
///
/// # Arguments
/// * `path` – the SVG file; `r` – the chart; `segment`, `g` – the state, for the caption.
///
/// # Errors
/// A message naming the file that could not be drawn.
pub fn feed_map(path: &Path, r: &LobeMap, segment: usize, g: f64) -> Result<(), String> {
    let err = draw_err(path);
    let (lo, hi) = finite_bounds(r.map.iter().flatten().flatten().copied())
        .map_or((0.0, 1.0), |(lo, hi)| span(lo, hi));
    let xe = edges(&r.rpms, 10.0);
    let ye = edges(&r.feeds, 1e-3);
    let (x0, x1) = span(
        xe.first().copied().unwrap_or(0.0),
        xe.last().copied().unwrap_or(1.0),
    );
    let (y0, y1) = span(
        ye.first().copied().unwrap_or(0.0),
        ye.last().copied().unwrap_or(1.0),
    );
    let root = figure(path, (1100, 700)).map_err(&err)?;
    let (main, bar) = root.split_horizontally(950);
    let caption = format!(
        "|mu|max at a_p = {} mm, segment {segment}, g = {g} rad ({}); black: |mu|max = 1",
        r.process.axial_depth * 1e3,
        match r.settings.model {
            DelayModel::Constant => "constant delay",
            DelayModel::StateDependent => "state-dependent",
        }
    );
    let mut chart = Frame {
        caption: &caption,
        caption_size: 22,
        margin: 15,
        x_label_area: 50,
        y_label_area: 80,
    }
    .build(&main, x0..x1, y0..y1)
    .map_err(&err)?;
    Axes {
        x_desc: "spindle speed [rpm]",
        y_desc: "feed [m/s]",
        whole_x: false,
        grid: false,
    }
    .draw(&mut chart)
    .map_err(&err)?;
    let scale = |v: f64| (v - lo) / (hi - lo);
    let mut cells = Vec::new();
    for (i, row) in r.map.iter().enumerate() {
        for (j, mu) in row.iter().enumerate() {
            if let (Some(xa), Some(xb), Some(ya), Some(yb)) =
                (xe.get(i), xe.get(i + 1), ye.get(j), ye.get(j + 1))
            {
                let colour = match mu {
                    Some(m) if m.is_finite() => colormap(scale(*m)),
                    _ => UNDEFINED_COLOR,
                };
                cells.push(Rectangle::new([(*xa, *ya), (*xb, *yb)], colour.filled()));
            }
        }
    }
    chart.draw_series(cells).map_err(&err)?;
    let grid: Vec<Vec<f64>> = r
        .map
        .iter()
        .map(|row| row.iter().map(|m| m.unwrap_or(f64::NAN)).collect())
        .collect();
    let segs = contour(&r.rpms, &r.feeds, &grid, 1.0);
    chart
        .draw_series(
            segs.into_iter()
                .map(|s| PathElement::new(s.to_vec(), BLACK.stroke_width(3))),
        )
        .map_err(&err)?;
    if r.rpms.len() < 2 || r.feeds.len() < 2 {
        let mut outlines = Vec::new();
        for (i, row) in r.map.iter().enumerate() {
            for (j, mu) in row.iter().enumerate() {
                if let (true, Some(xa), Some(xb), Some(ya), Some(yb)) = (
                    matches!(mu, Some(m) if *m >= 1.0),
                    xe.get(i),
                    xe.get(i + 1),
                    ye.get(j),
                    ye.get(j + 1),
                ) {
                    outlines.push(Rectangle::new(
                        [(*xa, *ya), (*xb, *yb)],
                        WHITE.stroke_width(2),
                    ));
                }
            }
        }
        chart.draw_series(outlines).map_err(&err)?;
    }
    // Colour bar.
    let mut cb = ChartBuilder::on(&bar)
        .margin_top(50)
        .margin_bottom(65)
        .margin_right(10)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(&err)?;
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc("|mu|max")
        .y_label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(&err)?;
    let n = 100;
    cb.draw_series((0..n).map(|k| {
        let a = lo + (hi - lo) * k as f64 / n as f64;
        let b = lo + (hi - lo) * (k + 1) as f64 / n as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            colormap(scale(0.5 * (a + b))).filled(),
        )
    }))
    .map_err(&err)?;
    if (lo..=hi).contains(&1.0) {
        cb.draw_series(std::iter::once(PathElement::new(
            vec![(0.0, 1.0), (1.0, 1.0)],
            BLACK.stroke_width(3),
        )))
        .map_err(&err)?;
    }
    root.present().map_err(&err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The contour of a plane z = x + y at level 1 on a unit grid lies on x + y = 1.
    #[test]
    fn contour_of_a_plane_lies_on_its_level_line() {
        let xs = [0.0, 0.5, 1.0];
        let ys = [0.0, 0.25, 0.5, 0.75, 1.0];
        let z: Vec<Vec<f64>> = xs
            .iter()
            .map(|x| ys.iter().map(|y| x + y).collect())
            .collect();
        let segs = contour(&xs, &ys, &z, 1.0);
        assert!(!segs.is_empty());
        for s in &segs {
            for (x, y) in s {
                assert!((x + y - 1.0).abs() < 1e-12, "({x}, {y})");
            }
        }
    }

    #[test]
    fn colormap_ends_are_viridis_ends() {
        assert_eq!(colormap(0.0), RGBColor(68, 1, 84));
        assert_eq!(colormap(1.0), RGBColor(253, 231, 37));
        assert_eq!(colormap(f64::NAN), RGBColor(68, 1, 84));
    }
}
