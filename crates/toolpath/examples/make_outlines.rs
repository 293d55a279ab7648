//! Writes the free-form closed outlines of `crates/toolpath/data/outlines/` (issue 14, item 7:
//! "free-form closed outlines resampled to 200 points in [0, 100]², the seed-000 format"): each
//! a closed curve given in polar or parametric form, traced densely, resampled to 200 points
//! equally spaced in arc length (the last point is the first: the outline is closed), scaled to
//! fit [0, 100]² mm with its aspect kept, one `x y` per line with 6 decimals.
//!
//! ```sh
//! cargo run -p kerf_toolpath --example make_outlines
//! ```

#![allow(clippy::expect_used)] // an example reports failures by panicking

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;

/// A closed curve at parameter t ∈ [0, 1).
type Curve = fn(f64) -> [f64; 2];

/// Temple H. Fay's butterfly (1989): r = e^{sin θ} − 2 cos 4θ + sin⁵((2θ − π)/24), θ ∈ [0, 12π).
fn butterfly(t: f64) -> [f64; 2] {
    let th = 12.0 * PI * t;
    let r = th.sin().exp() - 2.0 * (4.0 * th).cos() + ((2.0 * th - PI) / 24.0).sin().powi(5);
    [r * th.cos(), r * th.sin()]
}

/// The heart curve x = 16 sin³ t, y = 13 cos t − 5 cos 2t − 2 cos 3t − cos 4t.
fn heart(t: f64) -> [f64; 2] {
    let a = TAU * t;
    [
        16.0 * a.sin().powi(3),
        13.0 * a.cos() - 5.0 * (2.0 * a).cos() - 2.0 * (3.0 * a).cos() - (4.0 * a).cos(),
    ]
}

/// A five-petal rose with an offset, r = 2 + cos 5θ.
fn rose(t: f64) -> [f64; 2] {
    let th = TAU * t;
    let r = 2.0 + (5.0 * th).cos();
    [r * th.cos(), r * th.sin()]
}

/// A gear-like outline, r = 1 + 0.15 tanh(4 sin 12θ).
fn gear(t: f64) -> [f64; 2] {
    let th = TAU * t;
    let r = 1.0 + 0.15 * (4.0 * (12.0 * th).sin()).tanh();
    [r * th.cos(), r * th.sin()]
}

fn resample(curve: Curve, points: usize) -> Vec<[f64; 2]> {
    let dense = 200_000;
    let trace: Vec<[f64; 2]> = (0..=dense)
        .map(|k| curve(k as f64 / dense as f64))
        .collect();
    let mut s = vec![0.0];
    for w in trace.windows(2) {
        let d = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
        s.push(s[s.len() - 1] + d);
    }
    let total = s[s.len() - 1];
    let mut out = Vec::with_capacity(points);
    let mut k = 0;
    for i in 0..points {
        let target = total * i as f64 / (points - 1) as f64;
        while k + 1 < s.len() - 1 && s[k + 1] < target {
            k += 1;
        }
        let u = ((target - s[k]) / (s[k + 1] - s[k])).clamp(0.0, 1.0);
        out.push([
            trace[k][0] + u * (trace[k + 1][0] - trace[k][0]),
            trace[k][1] + u * (trace[k + 1][1] - trace[k][1]),
        ]);
    }
    // Closed: the last point is the first.
    out[points - 1] = out[0];
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &out {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let scale = 100.0 / (hi[0] - lo[0]).max(hi[1] - lo[1]);
    out.iter()
        .map(|p| [(p[0] - lo[0]) * scale, (p[1] - lo[1]) * scale])
        .collect()
}

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/outlines");
    std::fs::create_dir_all(&dir).expect("data directory");
    let curves: [(&str, Curve); 4] = [
        ("butterfly", butterfly),
        ("heart", heart),
        ("rose", rose),
        ("gear", gear),
    ];
    for (name, curve) in curves {
        let points = resample(curve, 200);
        let mut text = format!(
            "# {name}: closed outline, 200 points equally spaced in arc length, mm in [0, 100]^2\n\
             # (crates/toolpath/examples/make_outlines.rs)\n"
        );
        for p in points {
            let _ = writeln!(text, "{:.6} {:.6}", p[0], p[1]);
        }
        let path = dir.join(format!("{name}.txt"));
        std::fs::write(&path, text).expect("write outline");
        println!("{}", path.display());
    }
}
