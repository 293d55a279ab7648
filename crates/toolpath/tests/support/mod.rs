//! Test data shared by the integration tests of `kerf_toolpath`.

use kerf_toolpath::vec3::distance_to_segment;
use kerf_toolpath::{bang_bang_under, CornerCurve, CurvatureLimits, FeedLimits, PathSample};

/// A zig-zag of short and long segments with right-angle, acute and obtuse corners \[m\].
pub const ZIG_ZAG: [[f64; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [0.02, 0.0, 0.0],
    [0.03, 0.01, 0.0],
    [0.05, 0.01, 0.0],
    [0.05, 0.03, 0.0],
    [0.045, 0.031, 0.0],
];

/// Seed 003's Table 1 with its tangential limits (A_t 800 mm/s², J_t 20 000 mm/s³).
pub fn feed_limits() -> FeedLimits {
    FeedLimits {
        curvature: CurvatureLimits::seed_003_table_1(),
        tangential_acceleration: 0.8,
        tangential_jerk: 20.0,
    }
}

/// Seed 000's limits as the bench reads them (mm and s: v 10 mm/s, a 100 mm/s², j 10 000 mm/s³,
/// T 0.5 ms; normal limits equal to the tangential ones) and its δ = 0.5 mm.
pub fn seed_000_limits() -> (FeedLimits, f64) {
    (
        FeedLimits {
            curvature: CurvatureLimits {
                feed: 0.010,
                interpolation_period: 5e-4,
                chord_error: 5e-4,
                normal_acceleration: 0.1,
                normal_jerk: 10.0,
                servo: None,
            },
            tangential_acceleration: 0.1,
            tangential_jerk: 10.0,
        },
        5e-4,
    )
}

/// The shipped outline files (`data/outlines/*.txt`), sorted.
pub fn outline_files() -> Vec<std::path::PathBuf> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/outlines");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "txt"))
        .collect();
    names.sort();
    names
}

/// The shipped outlines (`data/outlines/*.txt`, mm), by name, sorted.
pub fn outlines() -> Vec<(String, Vec<[f64; 3]>)> {
    outline_files()
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p).unwrap();
            let points =
                kerf_gcode::read_points(text.as_bytes(), kerf_gcode::PointUnit::Millimetre)
                    .unwrap();
            (p.file_stem().unwrap().to_string_lossy().to_string(), points)
        })
        .collect()
}

/// The G01 polyline \[m\] of a shipped program (`crates/gcode/data/programs/{name}.ngc`): every
/// line move's end after the first move's start.
pub fn program_polyline(name: &str) -> Vec<[f64; 3]> {
    use kerf_gcode::{read_program, Motion, ReaderSettings};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let file = root.join(format!("crates/gcode/data/programs/{name}.ngc"));
    let text = std::fs::read_to_string(&file).unwrap();
    let mut polyline = Vec::new();
    for m in read_program(&text, ReaderSettings::default()).unwrap() {
        if let Motion::Line { start, end, .. } = m {
            if polyline.is_empty() {
                polyline.push(start);
            }
            polyline.push(end);
        }
    }
    polyline
}

/// T_lb \[s\] on `samples`: the bang-bang bound under seed 003 eq. 22's limit at every sample
/// (the benches' and tests' bound).
pub fn t_lb(samples: &[PathSample], limits: &FeedLimits) -> f64 {
    let curve: Vec<f64> = samples
        .iter()
        .map(|p| limits.curvature.speed(p.curvature))
        .collect();
    bang_bang_under(samples, curve, limits.tangential_acceleration)
        .unwrap()
        .time
}

/// A corner turning by `deg` degrees in a tilted plane, segments of 10 mm: the points before,
/// at and after the vertex \[m\].
pub fn corner_points(deg: f64) -> [[f64; 3]; 3] {
    let t = deg.to_radians();
    // An orthonormal pair spanning a plane tilted against every axis.
    let e1 = [1.0 / 2f64.sqrt(), 1.0 / 2f64.sqrt(), 0.0];
    let e2 = [-0.6 / 2f64.sqrt(), 0.6 / 2f64.sqrt(), 0.8];
    let v = [0.1, -0.2, 0.3];
    let prev = std::array::from_fn(|d| v[d] - 0.010 * e1[d]);
    let next = std::array::from_fn(|d| v[d] + 0.010 * (t.cos() * e1[d] + t.sin() * e2[d]));
    [prev, v, next]
}

/// The largest distance \[m\] of a corner curve from the two segments a–v and v–b, on 4001
/// equally spaced parameters.
pub fn sampled_deviation(curve: &CornerCurve, a: [f64; 3], v: [f64; 3], b: [f64; 3]) -> f64 {
    (0..=4000)
        .map(|k| {
            let p = curve.point(k as f64 / 4000.0);
            distance_to_segment(p, a, v).min(distance_to_segment(p, v, b))
        })
        .fold(0.0, f64::max)
}
