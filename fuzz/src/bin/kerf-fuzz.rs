//! `kerf-fuzz`: longer runs of the in-house mutation fuzzer, and the generated part of the
//! corpus.
//!
//! ```text
//! cargo run --release -p kerf_fuzz -- run [--seconds N] [--seed S] [TARGET ...]
//! cargo run --release -p kerf_fuzz -- seeds
//! ```
//!
//! `run` fuzzes each target (all by default) for N seconds (60) from its committed corpus and
//! prints executions per target; the first failure ends it with exit code 1, naming the file
//! the input was saved to. `seeds` rewrites the generated seed files of the corpus
//! (`fuzz/corpus/cdr/*.cdr`, `fuzz/corpus/{cut,mill,trajectory}_msg/gen-*`): CDR encodings of
//! real messages and `arbitrary` byte strings; and those of issue 33's targets
//! (`fuzz/corpus/{cut_numbers,mill_numbers,gcode_msg}/`: `gen-*` and the named seeds of
//! `kerf_fuzz::numbers::SEEDS`, found by a search of random bytes; `fuzz/corpus/file_uri/`,
//! `fuzz/corpus/capped_reader/`).

use std::{process::ExitCode, time::Duration};

use byteorder::{BigEndian, LittleEndian};
use kerf_fuzz::{
    corpus_dir,
    mutate::{self, Budget, Rng},
    target, TARGETS,
};
use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    control_msgs::{FollowJointTrajectoryGoal, JointTolerance},
    geometry_msgs::{Point, Pose, Quaternion, Vector3},
    msg,
    srv::ValidateTrajectoryRequest,
    std_msgs::StringMsg,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("run") => run(&args[1..]),
        Some("seeds") => seeds(),
        _ => Err(
            "usage: kerf-fuzz run [--seconds N] [--seed S] [TARGET ...] | kerf-fuzz seeds".into(),
        ),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("kerf-fuzz: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &[String]) -> Result<(), String> {
    let mut seconds = 60.0;
    let mut seed = 1u64;
    let mut names = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--seconds" => {
                seconds = it
                    .next()
                    .and_then(|s| s.parse::<f64>().ok())
                    .filter(|s| s.is_finite() && *s >= 0.0)
                    .ok_or("--seconds takes a number of seconds")?;
            }
            "--seed" => {
                seed = it
                    .next()
                    .and_then(|s| s.parse().ok())
                    .ok_or("--seed takes an unsigned integer")?;
            }
            name => {
                target(name).ok_or_else(|| format!("no target {name:?}"))?;
                names.push(name.to_string());
            }
        }
    }
    if names.is_empty() {
        names = TARGETS.iter().map(|(n, _)| (*n).to_string()).collect();
    }
    println!("target              corpus  executions   exec/s");
    for name in &names {
        let t = target(name).ok_or_else(|| format!("no target {name:?}"))?;
        let corpus: Vec<Vec<u8>> = mutate::load_corpus(&corpus_dir().join(name))
            .map_err(|e| format!("corpus of {name}: {e}"))?
            .into_iter()
            .map(|(_, data)| data)
            .collect();
        let start = std::time::Instant::now();
        let stats = mutate::fuzz(
            name,
            t,
            &corpus,
            seed,
            Budget::Time(Duration::from_secs_f64(seconds)),
        )
        .map_err(|f| f.to_string())?;
        let secs = start.elapsed().as_secs_f64();
        println!(
            "{name:<18} {:>7} {:>11} {:>8.0}",
            stats.replayed,
            stats.executions,
            stats.executions as f64 / secs
        );
    }
    // `file_uri`'s tree of roots (built in the temp directory on its first input).
    kerf_fuzz::files::remove_scratch();
    Ok(())
}

fn write(target: &str, file: &str, data: &[u8]) -> Result<(), String> {
    let dir = corpus_dir().join(target);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let path = dir.join(file);
    std::fs::write(&path, data).map_err(|e| format!("{}: {e}", path.display()))
}

/// A CDR seed: the type-selecting byte of the `cdr` target, then the body.
fn cdr<T: serde::Serialize>(kind: u8, value: &T) -> Result<Vec<u8>, String> {
    let body = if kind & 0x80 == 0 {
        cdr_encoding::to_vec::<T, LittleEndian>(value)
    } else {
        cdr_encoding::to_vec::<T, BigEndian>(value)
    }
    .map_err(|e| e.to_string())?;
    Ok([vec![kind], body].concat())
}

fn point(x: f64, y: f64, z: f64) -> Point {
    Point { x, y, z }
}

/// The README's line-format request as a message (`slot-3`).
fn cut_request() -> msg::CutRequest {
    msg::CutRequest {
        request_id: "slot-3".into(),
        points: vec![
            point(0.600, -0.1776, 0.0),
            point(0.603, -0.1776, 0.0),
            point(0.606, -0.1776, 0.0),
        ],
        axes: vec![
            Vector3 {
                x: 0.0,
                y: 0.0,
                z: 1.0
            };
            3
        ],
        feedrate: 0.3333,
        sample_period: 0.004,
        max_lead_angle: 0.087,
        max_tilt_angle: 0.087,
        mesh: "package://kerf/urdf/meshes/bpillar.obj".into(),
        workpiece_pose: Pose {
            position: point(0.0, 0.0, 0.0),
            orientation: Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            },
        },
        rto_indices: vec![0, 2],
        ..Default::default()
    }
}

/// The README's milling request as a message (`job-17`), with every group given.
fn mill_request() -> msg::MillRequest {
    msg::MillRequest {
        request_id: "job-17".into(),
        points: vec![
            point(1.4, -0.3, 1.7),
            point(1.6, -0.1, 1.7),
            point(1.8, 0.1, 1.7),
            point(2.1, 0.3, 1.7),
        ],
        segments: 20,
        has_process: true,
        teeth: 2,
        tool_radius: 0.01,
        axial_depth: 0.002,
        kt: 6e8,
        kn: 2e8,
        entry_angle: 0.0,
        exit_angle: std::f64::consts::PI,
        has_limits: true,
        spindle_min_rpm: 1000.0,
        spindle_max_rpm: 10000.0,
        feed_min: 0.01,
        feed_max: 0.1,
        g_min: -1.0,
        g_max: 1.0,
        max_spindle_step_rpm: 500.0,
        max_feed_step: 0.01,
        max_g_step: 0.1,
        has_initial_state: true,
        initial_spindle_rpm: 2000.0,
        initial_feed: 0.04,
        initial_g: 0.0,
        planner: "naive".into(),
        policy_file: String::new(),
        time_budget: 30.0,
        has_tolerances: true,
        path_tolerance: 5e-5,
        min_condition_indicator: 0.1,
        start: msg::MillRequest::START_NONE.into(),
        start_positions: Vec::new(),
        allow_chatter: false,
        entry: String::new(),
    }
}

/// The README's move of the laser cutter: two points, at rest at both ends.
fn trajectory() -> JointTrajectory {
    let p = |q1: f64, sec: i32| JointTrajectoryPoint {
        positions: vec![q1, 0.0, 0.0, 0.0, 0.0, 0.0],
        velocities: vec![0.0; 6],
        accelerations: Vec::new(),
        effort: Vec::new(),
        time_from_start: RosDuration { sec, nanosec: 0 },
    };
    JointTrajectory {
        joint_names: ["q1", "q2", "q3", "q4", "q5", "q6"]
            .map(String::from)
            .to_vec(),
        points: vec![p(0.0, 0), p(0.3, 2)],
        ..Default::default()
    }
}

fn seeds() -> Result<(), String> {
    let traj = trajectory();
    let goal = FollowJointTrajectoryGoal {
        trajectory: traj.clone(),
        path_tolerance: vec![JointTolerance {
            name: "q1".into(),
            position: 0.01,
            velocity: 0.0,
            acceleration: -1.0,
        }],
        goal_time_tolerance: RosDuration {
            sec: 0,
            nanosec: 500_000_000,
        },
        ..Default::default()
    };
    let text = StringMsg {
        data: "request_id: job-1\nplanner: naive\npoints: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\n"
            .into(),
    };
    write("cdr", "cut_request.cdr", &cdr(0, &cut_request())?)?;
    write("cdr", "cut_request_be.cdr", &cdr(0x80, &cut_request())?)?;
    write("cdr", "mill_request.cdr", &cdr(1, &mill_request())?)?;
    write("cdr", "trajectory.cdr", &cdr(2, &traj)?)?;
    write("cdr", "goal.cdr", &cdr(3, &goal)?)?;
    write(
        "cdr",
        "validate.cdr",
        &cdr(4, &ValidateTrajectoryRequest { trajectory: traj })?,
    )?;
    write("cdr", "string.cdr", &cdr(5, &text)?)?;
    // `arbitrary` inputs: zeros (every choice the first), ones, and pseudo-random bytes.
    let mut rng = Rng::new(2024);
    for target in ["cut_msg", "mill_msg", "trajectory_msg"] {
        write(target, "gen-zeros", &[0u8; 256])?;
        write(target, "gen-ones", &[0xffu8; 256])?;
        for k in 0..3 {
            let bytes: Vec<u8> = (0..512).map(|_| rng.next_u64() as u8).collect();
            write(target, &format!("gen-random-{k}"), &bytes)?;
        }
    }
    issue_33_seeds()?;
    println!("wrote the generated seeds under {}", corpus_dir().display());
    Ok(())
}

/// The seeds of the targets of issue 33, item 8 (a generator of their own, so that the seeds
/// above stay as they were).
fn issue_33_seeds() -> Result<(), String> {
    let mut rng = Rng::new(2033);
    for target in ["cut_numbers", "mill_numbers", "gcode_msg"] {
        write(target, "gen-zeros", &[0u8; 256])?;
        write(target, "gen-ones", &[0xffu8; 256])?;
        for k in 0..3 {
            write(
                target,
                &format!("gen-random-{k}"),
                &random_bytes(&mut rng, 512),
            )?;
        }
    }
    for (target, file, gives) in kerf_fuzz::numbers::SEEDS {
        let data = search(&mut rng, *gives).ok_or_else(|| format!("no bytes give {file}"))?;
        write(target, file, &data)?;
    }
    for (file, data) in FILE_URI_SEEDS {
        write("file_uri", file, data)?;
    }
    for (file, data) in capped_reader_seeds() {
        write("capped_reader", file, &data)?;
    }
    Ok(())
}

/// `n` bytes of `rng`.
fn random_bytes(rng: &mut Rng, n: usize) -> Vec<u8> {
    (0..n).map(|_| rng.next_u64() as u8).collect()
}

/// The first of up to 10^7 random byte strings (of 64 to 512 bytes) that `gives` accepts.
fn search(rng: &mut Rng, gives: fn(&[u8]) -> bool) -> Option<Vec<u8>> {
    (0..10_000_000).find_map(|_| {
        let n = 64 + rng.below(449);
        let bytes = random_bytes(rng, n);
        gives(&bytes).then_some(bytes)
    })
}

/// Seeds of `file_uri`: control bytes stand for the pieces of `kerf_fuzz::files` (0x01 root
/// `a`, 0x04 the root given through a link, 0x05 `bb`, 0x0a `/part.ngc`, 0x0b `/link-out`,
/// 0x0c `/link-dir-out/secret.ngc`, 0x0d `/loop`, 0x0f `/sock`, 0x13 `/big.ngc`, 0x14
/// `/empty.ngc`, 0x1a a 256-byte component); the length of a seed picks the read's cap.
const FILE_URI_SEEDS: &[(&str, &[u8])] = &[
    ("etc-passwd-relative", b"../../etc/passwd"),
    ("dev-zero", b"file:///dev/zero"),
    ("package-escape", b"package://kerf/../Cargo.toml"),
    (
        "package-shipped",
        b"package://kerf/crates/gcode/data/programs/arcs.ngc",
    ),
    ("root-part", b"\x01\x0a"),
    // Read whole (cap 4096, 0 bytes of 29) and at exactly its size (cap 30).
    ("root-part-read", b"\x01//part.ngc"),
    ("root-empty-read", b"\x01\x14"),
    ("root-part-exact-cap", b"\x01/././/part.ngc"),
    ("root-link-out", b"\x01\x0b"),
    ("root-link-dir-out", b"\x01\x0c"),
    ("root-dotdot-outside", b"\x01/../outside/secret.ngc"),
    ("file-uri-percent", b"file://\x01/sub/%2e%2e/part.ngc"),
    ("nul", b"\x01/part.ngc\0.stl"),
    (
        "long",
        b"\x01/\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a\x1a",
    ),
    ("sibling-of-root", b"\x05/part.ngc"),
    ("root-through-link", b"\x04\x0a"),
    ("loop", b"\x01\x0d"),
    ("socket", b"\x01\x0f"),
    ("over-cap", b"\x01\x13"),
    ("localhost", b"file://localhost\x01/part.ngc"),
    ("other-scheme", b"http://example.com/part.ngc"),
];

/// Seeds of `capped_reader` (its layout: cap, stack, length, ops, chunks, data).
fn capped_reader_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let seed = |cap: u16, stack: u8, length: u8, ops: &[u8], chunks: [u8; 4], data: &[u8]| {
        let mut out = cap.to_le_bytes().to_vec();
        out.extend([stack, length, ops.len() as u8]);
        out.extend_from_slice(ops);
        out.extend_from_slice(&chunks);
        out.extend_from_slice(data);
        out
    };
    // Ops: read 8 (0x20), fill_buf + consume 4 (0x0d), read_until (0x02), read_to_end (0x03).
    let ops = [0x20, 0x0d, 0x02, 0x03];
    let line = b"G1 X1 F100\nG1 Y1\n";
    vec![
        ("empty", seed(0, 0, 0, &[], [0; 4], b"")),
        ("under-cap", seed(64, 1, 0, &ops, [1, 7, 64, 3], line)),
        ("exact-cap", seed(30, 1, 1, &ops, [1, 7, 64, 3], line)),
        ("cap-plus-one", seed(30, 1, 2, &ops, [1, 7, 64, 3], line)),
        ("endless-zeros", seed(4096, 0, 3, &[0x03], [255; 4], &[0])),
        (
            "buffer-over-cap",
            seed(17, 2 | (3 << 2), 2, &ops, [5; 4], line),
        ),
        (
            "plain-chunks",
            seed(100, 0, 3, &[0xfc, 0x00, 0x04], [1, 2, 3, 200], line),
        ),
    ]
}
