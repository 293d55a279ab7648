//! An installed kerf finds its shipped data beside its binary (issue 12, item 4).
//!
//! The built `kerf` binary is placed as `<tmp>/prefix/bin/kerf`, `launch_scripts/install.sh
//! <tmp>/prefix --data-only` lays the data into `<tmp>/prefix/share/kerf`, and the installed
//! binary, run from another temporary directory with `KERF_DATA_DIR` removed, plans case 1
//! (`kerf plan cut`) and draws stability lobes (`kerf lobes`). That the share directory was
//! used, not the source tree the binary was built from, is shown by breaking a file in the
//! share directory only: the same commands then fail naming that file. A `KERF_DATA_DIR`
//! that is not a kerf data directory is an error naming the variable.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    path::{Path, PathBuf},
    process::{Command, Output},
};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// A fresh directory under the system temp dir.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kerf_install_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

/// Runs `launch_scripts/install.sh` with `args`.
fn install_sh(args: &[&str]) -> Output {
    Command::new("bash")
        .arg(Path::new(ROOT).join("launch_scripts/install.sh"))
        .args(args)
        .output()
        .expect("run install.sh")
}

/// Runs the installed `kerf` in `cwd` without any kerf data variable, plus `env`.
fn run(kerf: &Path, cwd: &Path, args: &[&str], env: &[(&str, &Path)]) -> Output {
    let mut cmd = Command::new(kerf);
    cmd.args(args)
        .current_dir(cwd)
        .env_remove("KERF_DATA_DIR")
        .env_remove("KERF_URDF_DIR");
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("run the installed kerf")
}

fn text(out: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// `kerf plan cut` of case 1, from the installed share directory.
const PLAN_CUT: [&str; 6] = [
    "plan",
    "cut",
    "--request",
    "case1.yaml",
    "--out",
    "plan.json",
];

/// The cheapest `kerf lobes` of tests/lobes_cli.rs.
const LOBES: [&str; 11] = [
    "lobes",
    "--segment",
    "50",
    "--g",
    "0",
    "--rpm",
    "2000:4000:5",
    "--feed",
    "0.02:0.06:3",
    "--out",
    "lobes",
];

#[test]
fn an_installed_kerf_plans_case_1_and_draws_lobes_from_another_directory() {
    let base = scratch("prefix");
    let prefix = base.join("prefix");
    let bin = prefix.join("bin");
    std::fs::create_dir_all(&bin).expect("bin dir");
    let kerf = bin.join("kerf");
    std::fs::copy(env!("CARGO_BIN_EXE_kerf"), &kerf).expect("copy the built kerf");

    let out = install_sh(&[prefix.to_str().expect("utf-8 temp dir"), "--data-only"]);
    assert!(out.status.success(), "{}", text(&out));
    let share = prefix.join("share/kerf");
    for rel in [
        "urdf/laser_cutter.urdf",
        "urdf/laser_cutter_limits.yaml",
        "urdf/irb6660.urdf",
        "urdf/irb6660_limits.yaml",
        "urdf/irb6660_milling.yaml",
        "urdf/meshes/bpillar.obj",
        "crates/mjto/cases/case1.yaml",
        "crates/millplan/policies/ddpg.safetensors",
        "crates/millplan/policies/ddpg.json",
        "crates/millplan/policies/fixed_g.safetensors",
        "crates/millplan/data/indicator_cache.bin",
        "crates/gcode/data/programs/w_shape.ngc",
        "launch_scripts/params/irb6660.yaml",
    ] {
        assert!(share.join(rel).is_file(), "{rel} not installed");
    }

    // Another working directory, holding only the request (its mesh is package://kerf/...).
    let work = scratch("work");
    std::fs::copy(
        share.join("crates/mjto/cases/case1.yaml"),
        work.join("case1.yaml"),
    )
    .expect("copy case 1");

    let out = run(&kerf, &work, &PLAN_CUT, &[]);
    assert!(out.status.success(), "{}", text(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("request 'bpillar-case1-side-trim': SUCCESS (0)"),
        "{stdout}"
    );
    assert!(work.join("plan.json").is_file());

    let out = run(&kerf, &work, &LOBES, &[]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(work.join("lobes").read_dir().expect("lobes dir").count() >= 2);

    // The share directory is what was used: break its files (the source tree's stay intact)
    // and the same commands fail naming the broken file.
    let limits = share.join("urdf/laser_cutter_limits.yaml");
    std::fs::write(&limits, "joint_limits: [not, a, map").expect("break the limits");
    let out = run(&kerf, &work, &PLAN_CUT, &[]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let cell = share.join("urdf/irb6660_milling.yaml");
    std::fs::write(&cell, "robot: [").expect("break the cell");
    let out = run(&kerf, &work, &LOBES, &[]);
    assert!(!out.status.success(), "{}", text(&out));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&cell.display().to_string()),
        "the error names the installed cell file: {stderr}"
    );
    // The mesh is resolved there too: with the share's mesh gone, case 1 cannot load it.
    std::fs::copy(
        Path::new(ROOT).join("urdf/laser_cutter_limits.yaml"),
        &limits,
    )
    .expect("restore the limits");
    let mesh = share.join("urdf/meshes/bpillar.obj");
    std::fs::remove_file(&mesh).expect("remove the installed mesh");
    let out = run(&kerf, &work, &PLAN_CUT, &[]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("MESH_ERROR") && stderr.contains(&mesh.display().to_string()),
        "the error names the installed mesh: {stderr}"
    );

    // KERF_DATA_DIR wins, and a directory without kerf's data is an error naming it.
    let out = run(&kerf, &work, &PLAN_CUT, &[("KERF_DATA_DIR", &work)]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("KERF_DATA_DIR") && stderr.contains(&work.display().to_string()),
        "{stderr}"
    );
    // ... and a good one is used instead of the share directory.
    let out = run(
        &kerf,
        &work,
        &PLAN_CUT,
        &[("KERF_DATA_DIR", Path::new(ROOT))],
    );
    assert!(out.status.success(), "{}", text(&out));

    std::fs::remove_dir_all(&base).expect("remove the prefix");
    std::fs::remove_dir_all(&work).expect("remove the work dir");
}

#[test]
fn install_sh_refuses_bad_arguments() {
    for args in [
        &[][..],
        &["/tmp/x", "--both"][..],
        &["--data-only"][..],
        &["/tmp/x", "--data-only", "extra"][..],
    ] {
        let out = install_sh(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", text(&out));
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("usage:"),
            "{args:?}"
        );
    }
}
