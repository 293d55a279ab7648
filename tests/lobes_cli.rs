//! `kerf lobes` as a user runs it, on a small grid (5 speeds × 3 feeds) of the shipped cell at
//! segment 50, g = 0: both SVG files are written with their axis labels, the printed table
//! parses, and one row agrees with direct calls of the libraries (`kerf_mill` for the state,
//! `kerf_chatter` for the constant-delay lobe, the state-dependent critical depth and |μ| at the
//! cell's depth). Bad inputs exit with code 2 and a message naming the problem.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    path::PathBuf,
    process::{Command, Output},
};

use kerf_chatter::{
    chatter_indicator, lobes::state_dependent_critical_depth, stability_lobes, LobeOptions,
};
use kerf_mill::MillCell;

fn kerf(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kerf"))
        .arg("lobes")
        .args(args)
        .output()
        .expect("run kerf lobes")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kerf_lobes_cli_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A table cell as a depth in mm (`>MAX` = stable up to the max depth → None).
fn depth(cell: &str) -> Option<f64> {
    if cell.starts_with('>') {
        None
    } else {
        Some(cell.parse().expect("depth"))
    }
}

#[test]
fn draws_both_plots_and_prints_a_table_that_matches_the_libraries() {
    let dir = temp_dir("small");
    let out = kerf(&[
        "--segment",
        "50",
        "--g",
        "0",
        "--rpm",
        "2000:4000:5",
        "--feed",
        "0.02:0.06:3",
        "--out",
        dir.to_str().expect("utf-8 temp dir"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");

    // Plots: valid SVG documents with the expected axes.
    for (file, labels) in [
        (
            "lobes_seg50_g0.svg",
            &["spindle speed [rpm]", "critical axial depth a_lim [mm]"][..],
        ),
        (
            "feed_map_seg50_g0.svg",
            &["spindle speed [rpm]", "feed [m/s]", "|mu|max"][..],
        ),
    ] {
        let svg = std::fs::read_to_string(dir.join(file)).expect(file);
        assert!(svg.trim_start().starts_with("<svg"), "{file}");
        assert!(svg.trim_end().ends_with("</svg>"), "{file}");
        for l in labels {
            assert!(svg.contains(l), "{file} lacks the label {l:?}");
        }
    }
    let map = std::fs::read_to_string(dir.join("feed_map_seg50_g0.svg")).expect("map");
    assert!(
        map.matches("<rect").count() >= 15,
        "15 map cells + colour bar"
    );

    // Table: 5 rows of 7 columns.
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(rows.len(), 5, "{stdout}");
    for r in &rows {
        assert_eq!(r.len(), 7, "{r:?}");
    }
    let rpms: Vec<f64> = rows.iter().map(|r| r[0].parse().expect("rpm")).collect();
    assert_eq!(rpms, vec![2000.0, 2500.0, 3000.0, 3500.0, 4000.0]);

    // Direct library calls for the 3000 rpm row.
    let cell = MillCell::default_cell().expect("cell");
    let state = cell.evaluate(50, 0.0, None).expect("state");
    let process = cell.milling_process();
    let settings = *cell.indicator_settings();
    let opts = LobeOptions {
        steps: settings.steps,
        min_depth: 0.0,
        max_depth: 0.02,
        scan_points: 20,
        tolerance: 1e-6,
    };
    assert!(
        stdout.contains(&format!(
            "condition number K = {:.4}",
            state.condition_number
        )),
        "{stdout}"
    );
    let row = &rows[2];
    let rpm = 3000.0;
    let constant = stability_lobes(&state.modal, &process, &[rpm], &opts).expect("lobes")[0]
        .critical_depth
        .map(|d| d * 1e3);
    let printed = depth(row[1]);
    match (printed, constant) {
        (Some(a), Some(b)) => assert!((a - b).abs() < 1e-3, "{a} vs {b} mm"),
        other => panic!("constant a_lim {other:?}"),
    }
    // The nominal feed is seed 004's f0 = 0.04 m/s (inside the cell's range).
    assert!(stdout.contains("nominal feed 0.04 m/s"), "{stdout}");
    let sd = state_dependent_critical_depth(&state.modal, &process, rpm, 0.04, &settings, &opts)
        .expect("state-dependent a_lim")
        .map(|d| d * 1e3);
    match (depth(row[2]), sd) {
        (Some(a), Some(b)) => assert!((a - b).abs() < 1e-3, "{a} vs {b} mm"),
        other => panic!("state-dependent a_lim {other:?}"),
    }
    let mut direct = Vec::new();
    for (k, feed) in [0.02, 0.04, 0.06].into_iter().enumerate() {
        let mu = chatter_indicator(&state.modal, &process, rpm, feed, &settings)
            .expect("indicator")
            .spectral_radius;
        let printed: f64 = row[3 + k].parse().expect("mu");
        assert!(
            (printed - mu).abs() < 1e-4 * mu,
            "feed {feed}: printed {printed}, direct {mu}"
        );
        direct.push(mu);
    }
    // Feed lower bound from the direct values.
    let expected = if direct.iter().all(|m| *m < 1.0) {
        "all".to_string()
    } else if direct[2] >= 1.0 {
        "none".to_string()
    } else {
        let first = (0..3)
            .rev()
            .take_while(|&i| direct[i] < 1.0)
            .last()
            .expect("a stable feed");
        format!("{:.4}", [0.02, 0.04, 0.06][first])
    };
    assert_eq!(row[6], expected, "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_inputs_exit_2_with_a_message() {
    let dir = temp_dir("bad");
    let d = dir.to_str().expect("utf-8 temp dir");
    let small = ["--rpm", "2000:4000:2", "--feed", "0.02:0.06:2"];
    let cases: [(&[&str], &str); 7] = [
        (
            &["--segment", "100", "--g", "0"],
            "the path has 100 segments",
        ),
        (&["--segment", "50", "--g", "2.7"], "joint_5"),
        (
            &["--segment", "50", "--g", "0", "--rpm", "4000:2000:5"],
            "MIN 4000 > MAX 2000",
        ),
        (&["--segment", "50", "--g", "NaN"], "must be finite"),
        (
            &["--segment", "50", "--g", "0", "--feed", "NaN:0.06:3"],
            "MIN is NaN",
        ),
        (
            &["--segment", "50", "--g", "0", "--rpm", "2000:4000:0"],
            "COUNT must be >= 1",
        ),
        (
            &["--segment", "50", "--g", "0", "--format", "png"],
            "png not built in; use svg",
        ),
    ];
    for (args, needle) in cases {
        let mut all: Vec<&str> = args.to_vec();
        if !args.contains(&"--rpm") && !args.contains(&"--feed") {
            all.extend(small);
        }
        all.extend(["--out", d]);
        let out = kerf(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    // The unreachable g names the joint's excess over its limit.
    let out = kerf(&["--segment", "50", "--g", "2.7", "--out", d]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("outside") && stderr.contains("by 0.33"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
