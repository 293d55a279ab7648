//! `kerf plan gcode --normalize L --resample N` (issue 30, item 1): seed 000's preprocessing of
//! a shipped contour before it is planned, the summary printed, the plan made; bad values and
//! programs the seed's preprocessing does not define end with exit code 2 and a message. No DDS:
//! the command plans offline.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[path = "support/scratch.rs"]
mod scratch;

use scratch::scratch;

use std::process::{Command, Output};

const PROGRAMS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/crates/gcode/data/programs");

fn plan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kerf"))
        .args(["plan", "gcode"])
        .args(args)
        .output()
        .expect("run kerf plan gcode")
}

fn program(name: &str) -> String {
    format!("{PROGRAMS}/{name}")
}

fn succeeded(out: &Output) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

fn failed_with(out: &Output, expect: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for e in expect {
        assert!(err.contains(e), "`{e}` not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn the_torch_is_normalized_resampled_and_planned() {
    let torch = program("torch.ngc");
    let out = plan(&[&torch, "--normalize", "100", "--resample", "200"]);
    let s = succeeded(&out);
    // torch.ngc: 15 points in [-16, 16] x [0, 98] mm; the height, 98 mm, is scaled to 100.
    for want in [
        "preprocessing (seed 000 section 4.1): contour of lines 9-22 (G21, mm): 15 points, \
         length 268.1880 mm",
        "normalize to [0, 100]^2 mm: scale factor 1.020408, offset (16.3265, 0.0000) mm; \
         box [-16.0000, 16.0000] x [0.0000, 98.0000] mm -> [0.0000, 32.6531] x [0.0000, \
         100.0000] mm",
        "resample: 15 points -> 200 points, 1.3752 mm apart along the contour; length \
         273.6613 -> 267.4194 mm",
        "carried through: 1 rapids, 0 feed moves with the tool off",
        "the plan below is of the preprocessed program",
    ] {
        assert!(s.contains(want), "`{want}` not in:\n{s}");
    }
    // The plan: the 200 points are 199 G1 lines cut in one run.
    assert!(s.contains("laser-cutter: "), "{s}");
    let cut = s
        .lines()
        .find(|l| l.split_whitespace().nth(1) == Some("cut"))
        .unwrap_or_else(|| panic!("no cut run:\n{s}"));
    let lines = cut.split_whitespace().nth(2).unwrap();
    let (a, b) = lines.split_once('-').unwrap();
    assert_eq!(
        b.parse::<usize>().unwrap() - a.parse::<usize>().unwrap(),
        198,
        "{cut}"
    );
}

#[test]
fn each_flag_works_alone() {
    let w = program("w_shape.ngc");
    let s = succeeded(&plan(&[&w, "--resample", "50"]));
    assert!(s.contains("resample: 5 points -> 50 points"), "{s}");
    assert!(!s.contains("normalize to"), "{s}");
    let s = succeeded(&plan(&[&w, "--normalize", "30"]));
    assert!(
        s.contains("normalize to [0, 30]^2 mm: scale factor 0.500000, offset (0.0000, 0.0000) mm"),
        "{s}"
    );
    assert!(!s.contains("resample:"), "{s}");
    // Without either, nothing is preprocessed.
    let s = succeeded(&plan(&[&w]));
    assert!(!s.contains("preprocessing"), "{s}");
}

#[test]
fn bad_values_are_refused_with_their_range() {
    let w = program("w_shape.ngc");
    for n in ["0", "1", "-3", "NaN", "2.5", "1000001"] {
        failed_with(
            &plan(&[&w, &format!("--resample={n}")]),
            &["--resample", "allowed: [2, 1000000] points"],
        );
    }
    for l in ["NaN", "-1", "0", "inf", "5e-324", "1e7"] {
        failed_with(
            &plan(&[&w, &format!("--normalize={l}")]),
            &["--normalize", "allowed: (0, 1000000] program units"],
        );
    }
}

#[test]
fn what_the_seed_does_not_define_is_refused() {
    // Arcs.
    failed_with(
        &plan(&[&program("arcs.ngc"), "--resample", "200"]),
        &["an arc (G2/G3)", "G01 polylines only"],
    );
    // Two contours.
    let d = scratch("gcode_preprocess", "contours");
    let two = d.join("two.ngc");
    std::fs::write(
        &two,
        "G21 G90\nG0 X0 Y0\nM3\nG1 X20 F1200\nX20 Y20\nM5\nG0 X40 Y0\nM3\nG1 X60 Y0\nX50 Y17\nM5\nM2\n",
    )
    .unwrap();
    failed_with(
        &plan(&[two.to_str().unwrap(), "--normalize", "100"]),
        &["INVALID_REQUEST", "2 contours (lines 4-5, then 9-10)"],
    );
    // A contour that is out of reach once normalized names the preprocessed program.
    failed_with(
        &plan(&[&program("w_shape_inch.ngc"), "--normalize", "100"]),
        &[
            "UNREACHABLE",
            "preprocessed (lines of the preprocessed program)",
        ],
    );
    let _ = std::fs::remove_dir_all(&d);
}
