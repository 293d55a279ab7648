//! `kerf plan gcode` on the probe's inputs (issue 33): the 53-byte helix ends with
//! RESOURCE_LIMIT and exit code 2 (not an abort), a FIFO, /dev/zero on standard input and a
//! bad `--plan-memory` end with exit code 2 and a message at once, and a valid program read
//! from standard input plans. No DDS: the command plans offline.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::io::Write;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn plan(args: &[&str], stdin: Stdio) -> (Output, Duration) {
    let started = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_kerf"))
        .args(["plan", "gcode"])
        .args(args)
        .stdin(stdin)
        .output()
        .expect("run kerf plan gcode");
    (out, started.elapsed())
}

fn failed_with(out: &Output, took: Duration, expect: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(expect), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(took < Duration::from_secs(15), "hang guard: {err}");
}

fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("kerf_plan_gcode_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn the_helix_ends_with_resource_limit_not_an_abort() {
    let d = scratch("helix");
    let helix = d.join("helix.ngc");
    std::fs::write(
        &helix,
        "G21 G17\nG1 X10 Y0 F3000\nG2 X10 Y0 Z-5 I-10 J0 P10000\n",
    )
    .unwrap();
    let (out, took) = plan(
        &[helix.to_str().unwrap(), "--plan-memory", "268435456"],
        Stdio::null(),
    );
    failed_with(&out, took, "RESOURCE_LIMIT (7): FILE ");
    failed_with(&out, took, "helix.ngc: memory budget of 256.0 MiB exceeded");
    let (out, took) = plan(
        &[helix.to_str().unwrap(), "--plan-memory", "5"],
        Stdio::null(),
    );
    failed_with(&out, took, "allowed: [16777216, 1099511627776] bytes");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn fifos_and_endless_input_end_at_once() {
    let d = scratch("fifo");
    let fifo = d.join("part.ngc");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) on a NUL-terminated path we own.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let (out, took) = plan(&[fifo.to_str().unwrap()], Stdio::null());
    // No writer: read at once as an empty program, named.
    failed_with(&out, took, "FILE ");
    failed_with(&out, took, "part.ngc");
    let zero = std::fs::File::open("/dev/zero").unwrap();
    let (out, took) = plan(&["-"], Stdio::from(zero));
    failed_with(&out, took, "line longer than 65536 bytes");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_program_on_standard_input_plans() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_kerf"))
        .args(["plan", "gcode", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"M3\nG1 X20 F3000\nG1 Y20\nM5\n")
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("laser-cutter: 4 lines"), "{text}");
}

/// Issue 30, item 3: `--method drls-net` plans with the committed network and prints the
/// corners predicted and the fallbacks; `--out` writes them as `corner_fallbacks`.
#[test]
fn drls_net_prints_and_writes_its_fallbacks() {
    let d = scratch("drls");
    let program = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/gcode/data/programs/w_shape.ngc"
    );
    let json = d.join("plan.json");
    let (out, _) = plan(
        &[
            program,
            "--method",
            "drls-net",
            "--out",
            json.to_str().unwrap(),
        ],
        Stdio::null(),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("drls-net: 3 corners predicted, 0 fell back to the NURBS swarm"),
        "{text}"
    );
    let answer: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(answer["method"], "drls-net");
    assert_eq!(answer["corner_fallbacks"], 0);
    let _ = std::fs::remove_dir_all(&d);
}
