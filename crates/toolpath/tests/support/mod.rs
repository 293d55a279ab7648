//! Test data shared by the integration tests of `kerf_toolpath`.

use kerf_toolpath::{bang_bang_under, CurvatureLimits, FeedLimits, PathSample};

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
