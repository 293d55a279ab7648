//! Program files through one reader (issue 33, item 4): a FIFO, a device, a directory and a
//! file over the cap are refused at once, naming the file, without blocking; a regular
//! program file still plans.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;
use std::time::{Duration, Instant};

use kerf_budget::Budget;
use kerf_gcodeplan::{plan_request, GcodePlanError, GcodeRequest, MachineBase, MachineKind};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kerf_gcode_files_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn file_request(path: &std::path::Path) -> GcodeRequest {
    GcodeRequest {
        request_id: "file".into(),
        program_file: Some(path.display().to_string()),
        ..GcodeRequest::default()
    }
}

fn refused(base: &MachineBase, path: &std::path::Path, expect: &str) {
    let started = Instant::now();
    let e = plan_request(&file_request(path), base, &Budget::unlimited()).unwrap_err();
    assert!(
        started.elapsed() < Duration::from_secs(15),
        "hang guard: {}",
        path.display()
    );
    match &e {
        GcodePlanError::InvalidRequest { field, reason } => {
            assert!(field.contains("program_file"), "{e}");
            assert!(reason.contains(expect), "{e}");
        }
        other => panic!("{}: {other:?}", path.display()),
    }
}

#[test]
fn fifos_devices_directories_and_oversized_files_are_refused_at_once() {
    let base = MachineBase::load(MachineKind::LaserCutter).unwrap();
    let d = scratch("refused");
    // A FIFO nobody writes: opening it would block forever.
    let fifo = d.join("part.ngc");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) on a NUL-terminated path we own.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    refused(&base, &fifo, "FIFO");
    // The same through file://, and through a symbolic link.
    let link = d.join("link.ngc");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    refused(&base, &link, "FIFO");
    let e = plan_request(
        &GcodeRequest {
            program_file: Some(format!("file://{}", fifo.display())),
            ..GcodeRequest::default()
        },
        &base,
        &Budget::unlimited(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("FIFO"), "{e}");
    refused(
        &base,
        std::path::Path::new("/dev/zero"),
        "not a regular file",
    );
    refused(&base, &d, "a directory");
    // A sparse file one byte over the cap: refused by its size, not read.
    let big = d.join("big.ngc");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(kerf_gcodeplan::MAX_PROGRAM_BYTES + 1)
        .unwrap();
    refused(&base, &big, "over the limit of 268435456 bytes");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_regular_program_file_still_plans_as_a_stream() {
    let base = MachineBase::load(MachineKind::LaserCutter).unwrap();
    let d = scratch("plans");
    let f = d.join("square.ngc");
    std::fs::write(
        &f,
        "G21 G90\nM3\nG1 X20 F3000\nG1 Y20\nG1 X0\nG1 Y0\nM5\nM30\n",
    )
    .unwrap();
    let plan = plan_request(&file_request(&f), &base, &Budget::unlimited()).unwrap();
    assert_eq!(plan.lines, 8);
    assert!(plan.duration > 0.0);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn program_files_resolve_through_the_shared_resolver() {
    let source = |file: &str| {
        GcodeRequest {
            program_file: Some(file.to_string()),
            ..GcodeRequest::default()
        }
        .source()
    };
    for (file, path) in [
        ("file:///tmp/a%20b.ngc", "/tmp/a b.ngc"),
        ("file://localhost/tmp/x.ngc", "/tmp/x.ngc"),
        ("parts/x.ngc", "parts/x.ngc"),
    ] {
        assert_eq!(
            source(file).unwrap(),
            kerf_gcodeplan::ProgramSource::File(PathBuf::from(path)),
            "{file}"
        );
    }
    for file in ["file://otherhost/x.ngc", "http://host/x.ngc"] {
        let e = source(file).unwrap_err();
        assert!(matches!(e, GcodePlanError::InvalidRequest { .. }), "{e}");
        assert!(e.to_string().contains(file), "{e}");
    }
}
