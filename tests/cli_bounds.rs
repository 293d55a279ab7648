//! Issue 33, items 7 and 8: every `kerf` command reads and counts within bounds, run as a user
//! runs the built binary.
//!
//! The arguments come from clap's own model (`kerf cli-model`, hidden): every numeric argument
//! of every command gets NaN, ±inf, 1e308, -1, 0, 5e-324 (and huge counts), every file a command
//! reads gets `/dev/zero`, a FIFO with no writer, a directory, an over-cap file and an over-cap
//! stdin. Each case must end within 15 s (hang guard) with exit code 2 and a message naming the
//! argument or the file, and no panic. A new command or argument is covered from its first
//! commit: a numeric argument without a stated range, or a file argument without a way to run
//! it here ([`input_invocation`]), fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    io::{Read, Write},
    path::{Path, PathBuf},
    process::{Child, Command, Stdio},
    time::{Duration, Instant},
};

/// Hang guard of every case.
const GUARD: Duration = Duration::from_secs(15);

/// Given after the argument under test: clap refuses it as unknown once the value before it
/// was accepted, so that no case runs any work.
const STOP: &str = "--kerf-bounds-stop";

/// Arguments that take a value and are no number and no file the command reads: outputs,
/// names, lists of names, ROS arguments.
const NOT_NUMBERS: &[(&str, &str)] = &[
    ("launch", "urdf_dir"),
    ("launch", "ros_args"),
    ("echo", "topic"),
    ("echo", "ros_type"),
    ("pub", "topic"),
    ("pub", "ros_type"),
    ("plan cut", "out"),
    ("plan cut", "plots"),
    ("plan mill", "out"),
    ("plan mill", "plots"),
    ("plan mill", "planners"),
    ("plan gcode", "method"),
    ("plan gcode", "feed_method"),
    ("plan gcode", "out"),
    ("plan gcode", "plots"),
    ("lobes", "out"),
    ("train mill", "out"),
    ("train mill", "history"),
    ("train mill", "plots"),
    ("train curve", "plots"),
    ("step", "out"),
];

fn kerf() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_kerf"));
    c.env("ROS_DOMAIN_ID", "83")
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .env_remove("ROS_STATIC_PEERS");
    c
}

/// One argument of clap's model.
#[derive(Debug, Clone)]
struct ArgModel {
    path: String,
    id: String,
    long: Option<String>,
    takes_value: bool,
    kind: String,
    help: String,
}

fn model() -> Vec<ArgModel> {
    let out = kerf().arg("cli-model").output().unwrap();
    assert!(out.status.success(), "{out:?}");
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let s = |k: &str| v[k].as_str().unwrap_or_default().to_string();
            ArgModel {
                path: v["path"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|p| p.as_str().unwrap())
                    .collect::<Vec<_>>()
                    .join(" "),
                id: s("id"),
                long: v["long"].as_str().map(String::from),
                takes_value: v["takes_value"].as_bool().unwrap(),
                kind: s("kind"),
                help: s("help"),
            }
        })
        .collect()
}

/// How a case ended.
#[derive(Debug)]
struct Outcome {
    code: Option<i32>,
    stderr: String,
    seconds: f64,
}

/// Waits for `child` within [`GUARD`] (killing it past that), collecting stderr.
fn finish(mut child: Child, what: &str) -> Outcome {
    let start = Instant::now();
    let mut err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return Outcome {
                code: status.code(),
                stderr: reader.join().unwrap(),
                seconds: start.elapsed().as_secs_f64(),
            };
        }
        if start.elapsed() > GUARD {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {GUARD:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn run(args: &[String], stdin: Stdio) -> Outcome {
    let child = kerf()
        .args(args)
        .stdin(stdin)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    finish(child, &args.join(" "))
}

/// The ranges `[a, b]` / `(a, b]` stated in `text`, in order.
fn ranges(text: &str) -> Vec<(f64, bool, f64)> {
    let mut out = Vec::new();
    for (i, c) in text.char_indices() {
        if c != '[' && c != '(' {
            continue;
        }
        let rest = &text[i + 1..];
        let Some(end) = rest.find(']') else { continue };
        let Some((a, b)) = rest[..end].split_once(", ") else {
            continue;
        };
        if let (Ok(a), Ok(b)) = (a.parse::<f64>(), b.parse::<f64>()) {
            out.push((a, c == '(', b));
        }
    }
    out
}

fn within(v: f64, (a, open, b): (f64, bool, f64)) -> bool {
    (if open { v > a } else { v >= a }) && v <= b
}

/// Whether the checked parsers accept `text` as a real in `range`: finite and normal (or 0).
fn accepted(text: &str, range: (f64, bool, f64)) -> bool {
    let v: f64 = text.parse().unwrap();
    v.is_finite() && (v == 0.0 || v.is_normal()) && within(v, range)
}

/// The hostile numbers.
const NUMBERS: &[&str] = &["NaN", "inf", "-inf", "1e308", "-1", "0", "5e-324"];

/// The hostile counts, besides [`NUMBERS`].
const HUGE_COUNTS: &[&str] = &["1000000000000", "18446744073709551616"];

fn numeric_arguments(args: &[ArgModel]) -> Vec<&ArgModel> {
    args.iter()
        .filter(|a| a.takes_value && matches!(a.kind.as_str(), "real" | "count" | "grid" | "point"))
        .collect()
}

/// Runs `kerf PATH --ARG=value STOP`: accepted values reach STOP, the others are refused
/// naming the argument and the range its `--help` states.
fn check_value(a: &ArgModel, value: &str, accept: bool, range_text: &str) {
    let long = a.long.as_deref().expect("numeric arguments are options");
    let mut argv: Vec<String> = a.path.split(' ').map(String::from).collect();
    argv.push(format!("--{long}={value}"));
    argv.push(STOP.into());
    let o = run(&argv, Stdio::null());
    let what = format!("kerf {} --{long}={value}", a.path);
    assert!(!o.stderr.contains("panicked"), "{what}: {}", o.stderr);
    assert_eq!(o.code, Some(2), "{what}: {}", o.stderr);
    if accept {
        assert!(
            o.stderr.contains(&format!("unexpected argument '{STOP}'")),
            "{what} should be accepted: {}",
            o.stderr
        );
    } else {
        assert!(
            o.stderr.contains("invalid value")
                && o.stderr.contains(&format!("--{long}"))
                && o.stderr.contains(&format!("allowed: {range_text}")),
            "{what} should be refused naming --{long} and `{range_text}`: {}",
            o.stderr
        );
    }
}

/// The range text after `allowed: ` in a refusal, to compare with `--help`.
fn allowed(stderr: &str) -> String {
    let at = stderr.find("allowed: ").expect("a stated range") + "allowed: ".len();
    stderr[at..].lines().next().unwrap().trim().to_string()
}

#[test]
fn every_numeric_argument_is_range_checked() {
    let args = model();
    let numeric = numeric_arguments(&args);
    assert!(numeric.len() > 30, "{numeric:?}");
    // Every other argument that takes a value is a file the command reads, an enum, or named.
    for a in &args {
        if a.takes_value && a.kind == "other" {
            assert!(
                NOT_NUMBERS.contains(&(a.path.as_str(), a.id.as_str())),
                "kerf {} {}: takes a value that is no checked number, no input file and no enum; \
                 give it a range (src/bounds.rs) or add it to NOT_NUMBERS",
                a.path,
                a.id
            );
        }
    }
    let mut cases = 0;
    for a in &numeric {
        let long = a.long.clone().unwrap();
        // The refusal of NaN states the range; --help states the same.
        let probe = match a.kind.as_str() {
            "grid" => "NaN:1:1".to_string(),
            "point" => "NaN,NaN,NaN".to_string(),
            _ => "NaN".to_string(),
        };
        let mut argv: Vec<String> = a.path.split(' ').map(String::from).collect();
        argv.push(format!("--{long}={probe}"));
        let o = run(&argv, Stdio::null());
        let range_text = allowed(&o.stderr);
        assert!(
            a.help.contains(&range_text),
            "kerf {} --{long}: --help does not state `{range_text}`: {}",
            a.path,
            a.help
        );
        let stated = ranges(&range_text);
        match a.kind.as_str() {
            "grid" => {
                // MIN:MAX:COUNT: the bounds' range, then the count's.
                let (values, count) = (stated[0], stated[1]);
                for v in NUMBERS.iter().chain(HUGE_COUNTS) {
                    let as_bound = v.parse::<f64>().is_ok() && accepted(v, values);
                    check_value(a, &format!("{v}:{v}:1"), as_bound, &range_text);
                    let as_count = accepted_count(v, count);
                    check_value(a, &format!("1:1:{v}"), as_count, &range_text);
                    cases += 2;
                }
            }
            "point" => {
                // x,y,z: each coordinate in the stated range; two coordinates are refused.
                let range = *stated.last().unwrap();
                for v in NUMBERS {
                    check_value(a, &format!("0,{v},0"), accepted(v, range), &range_text);
                    cases += 1;
                }
                check_value(a, "0,0", false, &range_text);
                cases += 1;
            }
            kind => {
                let count = kind == "count";
                let range = *stated.last().unwrap();
                let values: Vec<&str> = if count {
                    NUMBERS.iter().chain(HUGE_COUNTS).copied().collect()
                } else {
                    NUMBERS.to_vec()
                };
                for v in values {
                    let ok = if count {
                        accepted_count(v, range)
                    } else {
                        accepted(v, range)
                    };
                    check_value(a, v, ok, &range_text);
                    cases += 1;
                }
            }
        }
    }
    eprintln!("{cases} numeric cases over {} arguments", numeric.len());
}

fn accepted_count(v: &str, range: (f64, bool, f64)) -> bool {
    v.bytes().all(|b| b.is_ascii_digit())
        && v.parse::<u64>()
            .is_ok_and(|n| within(n as f64, range) && (n as f64) <= range.2)
}

/// A scratch directory, removed first.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kerf_cli_bounds_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn repo(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(rel)
        .display()
        .to_string()
}

/// The command line that reads `FILE` through the input argument `id` of `path` early,
/// with `{}` for the file; `None` for an input this test does not know yet (a failure).
fn input_invocation(path: &str, id: &str, dir: &Path) -> Option<Vec<String>> {
    let small = dir.join("small.yaml").display().to_string();
    let out = dir.join("out").display().to_string();
    let policy = dir.join("p.safetensors").display().to_string();
    let v: Vec<String> = match (path, id) {
        ("pub", "file") => vec!["pub".into(), "/kerf_bounds/none".into(), "{}".into()],
        ("plan cut", "request") => vec!["plan", "cut", "--request", "{}"]
            .into_iter()
            .map(String::from)
            .collect(),
        ("plan cut", "urdf") => vec![
            "plan".into(),
            "cut".into(),
            "--request".into(),
            small,
            "--limits".into(),
            repo("urdf/laser_cutter_limits.yaml"),
            "--urdf".into(),
            "{}".into(),
        ],
        ("plan cut", "limits") => vec![
            "plan".into(),
            "cut".into(),
            "--request".into(),
            small,
            "--urdf".into(),
            repo("urdf/laser_cutter.urdf"),
            "--limits".into(),
            "{}".into(),
        ],
        ("plan mill", "request") => vec!["plan", "mill", "--request", "{}"]
            .into_iter()
            .map(String::from)
            .collect(),
        ("plan mill", "ddpg_policy" | "fixed_g_policy") => vec![
            "plan".into(),
            "mill".into(),
            "--request".into(),
            small,
            format!("--{}", id.replace('_', "-")),
            "{}".into(),
        ],
        ("lobes", "cell") => vec![
            "lobes".into(),
            "--segment".into(),
            "0".into(),
            "--g".into(),
            "0".into(),
            "--out".into(),
            out,
            "--cell".into(),
            "{}".into(),
        ],
        ("demo cut" | "demo mill", "request") => {
            let what = path.split(' ').nth(1).unwrap();
            vec!["demo".into(), what.into(), "--request".into(), "{}".into()]
        }
        ("train mill", "cell" | "cache") => vec![
            "train".into(),
            "mill".into(),
            "--out".into(),
            policy,
            format!("--{id}"),
            "{}".into(),
        ],
        ("train curve", "history") => vec![
            "train".into(),
            "curve".into(),
            "--plots".into(),
            out,
            "--history".into(),
            "{}".into(),
        ],
        // Not in clap's model: the ROS arguments after --ros-args.
        ("launch", "params_file") => vec!["launch", "--ros-args", "--params-file", "{}"]
            .into_iter()
            .map(String::from)
            .collect(),
        ("plan gcode", "file") => vec!["plan".into(), "gcode".into(), "{}".into()],
        ("step", "points") => vec!["step".into(), "{}".into(), "--out".into(), out],
        ("step", "network") => vec![
            "step".into(),
            repo("crates/stepping/data/axis_dense.txt"),
            "--controller".into(),
            "ddqn".into(),
            "--out".into(),
            out,
            "--network".into(),
            "{}".into(),
        ],
        _ => return None,
    };
    Some(v)
}

/// A FIFO at `path`.
fn mkfifo(path: &Path) {
    assert!(Command::new("mkfifo").arg(path).status().unwrap().success());
}

/// Feeds `child`'s stdin with endless YAML-ish bytes until it stops reading.
fn flood(child: &mut Child) -> std::thread::JoinHandle<()> {
    let mut stdin = child.stdin.take().unwrap();
    std::thread::spawn(move || {
        let chunk = "a: 1\n".repeat(13_000);
        while stdin.write_all(chunk.as_bytes()).is_ok() {}
    })
}

/// Every input case of one file argument.
fn input_cases(path: &str, id: &str, dir: &Path) -> usize {
    let template = input_invocation(path, id, dir).unwrap_or_else(|| {
        panic!(
            "kerf {path}: the input argument `{id}` has no invocation in input_invocation; add \
             one so that it is tested"
        )
    });
    let fifo = dir.join(format!("fifo_{}_{id}", path.replace(' ', "_")));
    mkfifo(&fifo);
    let big = dir.join("big.yaml");
    let given = |file: &str| -> Vec<String> {
        template
            .iter()
            .map(|a| {
                if a == "{}" {
                    file.to_string()
                } else {
                    a.clone()
                }
            })
            .collect()
    };
    let mut n = 0;
    for file in [
        "/dev/zero".to_string(),
        fifo.display().to_string(),
        dir.display().to_string(),
        big.display().to_string(),
    ] {
        let o = run(&given(&file), Stdio::null());
        let what = format!("kerf {} ({id} = {file})", given(&file).join(" "));
        assert!(!o.stderr.contains("panicked"), "{what}: {}", o.stderr);
        assert_eq!(o.code, Some(2), "{what}: {}", o.stderr);
        assert!(o.stderr.contains(&file), "{what}: not named: {}", o.stderr);
        eprintln!("{what}: exit 2 in {:.2} s", o.seconds);
        n += 1;
    }
    // Over-cap stdin: endless bytes on a pipe, as /dev/stdin (and - where accepted).
    for file in ["/dev/stdin", "-"] {
        let mut child = kerf()
            .args(given(file))
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let feeder = flood(&mut child);
        let what = format!("kerf {} < endless pipe", given(file).join(" "));
        let o = finish(child, &what);
        feeder.join().unwrap();
        assert!(!o.stderr.contains("panicked"), "{what}: {}", o.stderr);
        assert_eq!(o.code, Some(2), "{what}: {}", o.stderr);
        let named = if file == "-" {
            o.stderr.contains("standard input") || o.stderr.contains(" -")
        } else {
            o.stderr.contains(file)
        };
        assert!(named, "{what}: not named: {}", o.stderr);
        eprintln!("{what}: exit 2 in {:.2} s", o.seconds);
        n += 1;
    }
    let _ = std::fs::remove_file(&fifo);
    n
}

fn input_dir(name: &str) -> PathBuf {
    let dir = scratch(name);
    std::fs::write(dir.join("small.yaml"), "request_id: x\n").unwrap();
    // Over every cap (the largest is 64 MiB): 1 GiB, sparse.
    std::fs::File::create(dir.join("big.yaml"))
        .unwrap()
        .set_len(1 << 30)
        .unwrap();
    dir
}

#[test]
fn every_input_is_read_within_bounds() {
    let dir = input_dir("inputs");
    let inputs: Vec<ArgModel> = model().into_iter().filter(|a| a.kind == "input").collect();
    assert!(inputs.len() >= 12, "{inputs:?}");
    let mut n = 0;
    for a in &inputs {
        n += input_cases(&a.path, &a.id, &dir);
    }
    n += input_cases("launch", "params_file", &dir);
    eprintln!("{n} input cases over {} arguments", inputs.len() + 1);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_long_lobes_run_shows_progress_and_stops_on_ctrl_c() {
    let dir = scratch("lobes_sigint");
    // 10 000 speeds: minutes of work at about 50 ms a speed.
    let mut child = kerf()
        .args([
            "lobes",
            "--segment",
            "0",
            "--g",
            "0",
            "--rpm",
            "1000:30000:10000",
        ])
        .arg("--out")
        .arg(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = child.stderr.take().unwrap();
    let start = Instant::now();
    let mut seen = String::new();
    let mut buf = [0u8; 256];
    while !seen.contains("speeds,") {
        assert!(
            start.elapsed() < GUARD,
            "no progress line within {GUARD:?}: {seen}"
        );
        let n = err.read(&mut buf).unwrap();
        assert!(n > 0, "stderr closed: {seen}");
        seen.push_str(&String::from_utf8_lossy(&buf[..n]));
    }
    assert!(seen.contains("/10000 speeds"), "{seen}");
    let interrupted = Instant::now();
    assert!(Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    child.stderr = Some(err);
    let o = finish(child, "kerf lobes after SIGINT");
    eprintln!(
        "progress after {:.2} s; SIGINT ended it in {:.3} s",
        interrupted.duration_since(start).as_secs_f64(),
        o.seconds
    );
    assert_eq!(o.code, Some(130), "{}", o.stderr);
    assert!(o.stderr.contains("kerf lobes") || o.stderr.contains("interrupted"));
    assert!(o.stderr.contains("interrupted (Ctrl-C)"), "{}", o.stderr);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rates_are_bounded_by_what_a_period_runs() {
    for (sim, param, value) in [
        (false, "control_rate", "1000000000.0"),
        (false, "control_rate", "2000.0"),
        (false, "action_monitor_rate", "500.0"),
        (true, "sim_physics_rate", "1000000000.0"),
        (true, "sim_physics_rate", "2.5e8"),
        (true, "sim_physics_rate", "10000.0"),
    ] {
        let mut argv: Vec<String> = vec!["launch".into()];
        if sim {
            argv.push("--sim".into());
        }
        argv.extend([
            "--ros-args".into(),
            "-p".into(),
            format!("{param}:={value}"),
        ]);
        let o = run(&argv, Stdio::null());
        let what = argv.join(" ");
        assert!(!o.stderr.contains("panicked"), "{what}: {}", o.stderr);
        assert_eq!(o.code, Some(2), "{what}: {}", o.stderr);
        assert!(
            o.stderr.contains(param) && o.stderr.contains(" Hz"),
            "{what}: {}",
            o.stderr
        );
        eprintln!("{what}: {}", o.stderr.trim());
    }
}
