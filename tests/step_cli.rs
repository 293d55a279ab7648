//! `kerf step` as a user runs it (issue 29, item 4): the README's examples as written, the JSON
//! trajectory checked against the points and limits from its samples alone, G-code points, and
//! bad input refused with exit code 2 and a message naming the problem.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    path::Path,
    process::{Command, Output},
};

#[path = "support/scratch.rs"]
mod scratch;

use scratch::scratch;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn kerf(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kerf"))
        .current_dir(ROOT)
        .args(args)
        .output()
        .expect("run kerf step")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Every sample's per-axis finite differences within `limits` (v, a, j), each point of
/// `points` passed within `precision` by a sample, rest on the last.
fn judge(json: &Path, points: &[Vec<f64>], limits: &[[f64; 3]], precision: f64) -> usize {
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let period = doc["period"].as_f64().unwrap();
    let x: Vec<Vec<f64>> = doc["samples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            s["position"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        })
        .collect();
    let dist = |a: &[f64], b: &[f64]| -> f64 {
        a.iter()
            .zip(b)
            .map(|(p, q)| (p - q).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    for (k, p) in points.iter().enumerate().skip(1) {
        let best = x.iter().map(|s| dist(s, p)).fold(f64::INFINITY, f64::min);
        assert!(best <= precision * (1.0 + 1e-9), "point {k}: {best}");
        let listed = &doc["points"][k - 1];
        assert_eq!(listed["index"].as_u64().unwrap() as usize, k);
        let step = listed["step"].as_u64().unwrap() as usize;
        assert!(dist(&x[step], p) <= precision * (1.0 + 1e-9));
    }
    assert!(dist(x.last().unwrap(), points.last().unwrap()) <= precision * (1.0 + 1e-9));
    for (i, l) in limits.iter().enumerate() {
        for w in x.windows(4) {
            let v = (w[1][i] - w[0][i]) / period;
            let a = (w[2][i] - 2.0 * w[1][i] + w[0][i]) / period.powi(2);
            let j = (w[3][i] - 3.0 * w[2][i] + 3.0 * w[1][i] - w[0][i]) / period.powi(3);
            assert!(v.abs() <= l[0] * (1.0 + 1e-6), "axis {i}: v {v}");
            assert!(a.abs() <= l[1] * (1.0 + 1e-6) + 1e-9, "axis {i}: a {a}");
            assert!(j.abs() <= l[2] * (1.0 + 1e-6) + 1e-6, "axis {i}: j {j}");
        }
    }
    let steps = doc["steps"].as_u64().unwrap() as usize;
    assert_eq!(x.len(), steps + 1);
    steps
}

fn read_points(file: &str, scale: f64) -> Vec<Vec<f64>> {
    kerf_stepping::points::parse_points(
        &std::fs::read_to_string(Path::new(ROOT).join(file)).unwrap(),
        scale,
    )
    .unwrap()
}

/// The README's `kerf step` examples (`cargo run --release -- step …`), as written.
fn readme_examples() -> Vec<Vec<String>> {
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    readme
        .lines()
        .filter_map(|l| l.strip_prefix("cargo run --release -- step "))
        .map(|rest| {
            std::iter::once("step".to_string())
                .chain(rest.split_whitespace().map(str::to_string))
                .collect()
        })
        .collect()
}

#[test]
fn the_readme_examples_run_as_written_and_their_trajectories_hold() {
    let examples = readme_examples();
    assert!(
        examples.len() >= 3,
        "README has {} kerf step examples",
        examples.len()
    );
    for args in &examples {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = kerf(&refs);
        assert!(o.status.success(), "{args:?}: {}", text(&o));
        let out = &args[args.iter().position(|a| a == "--out").unwrap() + 1];
        let file = &args[1];
        let scale = if args.iter().any(|a| a == "mm") {
            1e-3
        } else {
            1.0
        };
        let points = read_points(file, scale);
        let precision = args
            .iter()
            .position(|a| a == "--precision")
            .map_or(1e-5, |k| args[k + 1].parse().unwrap());
        let limits: Vec<[f64; 3]> = if args.iter().any(|a| a == "--joints") {
            let model = kerf_robot::RobotModel::from_files(
                &Path::new(ROOT).join("urdf/irb6660.urdf"),
                Some(&Path::new(ROOT).join("urdf/irb6660_limits.yaml")),
            )
            .unwrap();
            model
                .joints()
                .iter()
                .map(|j| {
                    [
                        j.max_velocity,
                        j.max_acceleration.unwrap(),
                        j.max_jerk.unwrap(),
                    ]
                })
                .collect()
        } else {
            let l =
                args.iter()
                    .position(|a| a == "--limits")
                    .map_or([8.0 / 60.0, 3.0, 30.0], |k| {
                        let v: Vec<f64> =
                            args[k + 1].split(',').map(|x| x.parse().unwrap()).collect();
                        [v[0], v[1], v[2]]
                    });
            vec![l; points[0].len()]
        };
        let steps = judge(Path::new(out), &points, &limits, precision);
        assert!(text(&o).contains(&format!("{steps} steps")), "{}", text(&o));
    }
}

#[test]
fn a_gcode_programs_points_are_stepped() {
    let dir = scratch("step_cli", "gcode");
    let program = dir.join("square.nc");
    std::fs::write(
        &program,
        "G21 G90\nG0 X0 Y0\nG1 X5 F600\nG3 X10 Y5 I0 J5\nG1 Y8\nM2\n",
    )
    .unwrap();
    let out = dir.join("square.json");
    let o = kerf(&[
        "step",
        program.to_str().unwrap(),
        "--gcode",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("1 move(s) of zero length"),
        "{}",
        text(&o)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let last = doc["samples"].as_array().unwrap().last().unwrap()["position"].clone();
    let end = [0.010, 0.008, 0.0];
    for k in 0..3 {
        assert!((last[k].as_f64().unwrap() - end[k]).abs() <= 1e-5);
    }
}

#[test]
fn bad_points_are_refused_naming_the_problem() {
    let cases: [(&str, &[&str], &str); 6] = [
        ("0\nnan\n", &[], "not finite"),
        ("0 0\n1 1\n1 1\n", &[], "repeated"),
        ("0\n", &[], "a start and at least one point"),
        ("0\n1\n", &["--precision", "0"], "--precision"),
        ("0\n1\n", &["--precision", "-1e-5"], "--precision"),
        (
            "0 -0.2 0.3 0 0.4 0\n0 -0.2 9 0 0.4 0\n",
            &["--joints", "irb6660"],
            "out of reach",
        ),
    ];
    for (k, (points, extra, want)) in cases.iter().enumerate() {
        let dir = scratch("step_cli", &format!("bad{k}"));
        let file = dir.join("points.txt");
        std::fs::write(&file, points).unwrap();
        let out = dir.join("bad.json");
        let mut args = vec![
            "step",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = kerf(&args);
        assert_eq!(o.status.code(), Some(2), "{points:?}: {}", text(&o));
        assert!(
            text(&o).contains(want),
            "{points:?}: want {want:?} in {}",
            text(&o)
        );
    }
}
