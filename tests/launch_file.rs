//! One way to launch (issue 27, item 4): `kerf launch` and `launch_scripts/kerf.launch.py`
//! read the same parameters file per cell and start the same nodes with the same command
//! lines.
//!
//! ROS is not installed here, so the launch file runs on a stub of the `launch` package that
//! this test writes into a temporary directory: `generate_launch_description()` runs, its
//! `OpaqueFunction` is called with the given launch arguments and the `ExecuteProcess`
//! command lines are printed as JSON. Those command lines are compared with
//! `kerf launch --print-config` (every node's arguments and effective parameters), and
//! started for real — the built node binaries next to this test's `target/<profile>/`, on
//! loopback DDS in domains 210-219 — to see the nodes come up in the file's namespace,
//! connected to the executor; `kerf launch` with the same file brings up the same set. Bad
//! settings are refused by both launchers naming the key. The README's launch examples run
//! as written (with the built `kerf` for `kerf` / `cargo run --release --`), and the shipped
//! start poses are clear of the robots' cells.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;

use std::{
    collections::BTreeMap,
    path::{Path, PathBuf},
    process::{Command, Output, Stdio},
    sync::OnceLock,
    time::{Duration, Instant},
};

use kerf_ros::{names, ros2_client::ServiceMapping, ParamValue, RosArgs};
use serde_json::Value as Json;
use support::{assert_clean_exit, client_node, interrupt, loopback, Killed, Lines};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const KERF: &str = env!("CARGO_BIN_EXE_kerf");
/// The node binaries a launch starts.
const NODES: [&str; 4] = [
    "trajectory_executor",
    "mjto_planner",
    "milling_planner",
    "gcode_planner",
];
/// Start-up of a node (a planner forks its worker), discovery.
const UP: Duration = Duration::from_secs(60);
/// A clean exit after Ctrl-C (a planner lingers 1.5 s for its answers).
const EXIT: Duration = Duration::from_secs(20);

/// The stub of ROS 2's `launch` package and the script that runs a launch file on it.
const STUB: [(&str, &str); 4] = [
    (
        "launch/__init__.py",
        r#""""A stub of ROS 2's `launch` package (tests/launch_file.rs)."""


class LaunchDescription:
    def __init__(self, entities=None):
        self.entities = list(entities or [])
"#,
    ),
    (
        "launch/actions.py",
        r#"class DeclareLaunchArgument:
    def __init__(self, name, default_value=None, **_):
        self.name = name
        self.default_value = default_value


class ExecuteProcess:
    def __init__(self, *, cmd, name=None, output=None, **_):
        self.cmd = cmd
        self.name = name
        self.output = output


class OpaqueFunction:
    def __init__(self, *, function, **_):
        self.function = function
"#,
    ),
    (
        "launch/substitutions.py",
        r#"class LaunchConfiguration:
    def __init__(self, name):
        self.name = name

    def perform(self, context):
        return context.launch_configurations[self.name]
"#,
    ),
    (
        "run_launch.py",
        r#""""python3 run_launch.py FILE [name:=value ...]: runs FILE's generate_launch_description()
on the stub `launch` package beside this script, calls its OpaqueFunctions with the launch
arguments (declared defaults, then the given values) and prints the ExecuteProcess actions as
JSON ([{"name", "cmd"}]). A RuntimeError of the launch file exits 2 with its message."""
import importlib.util
import json
import sys

from launch.actions import DeclareLaunchArgument, ExecuteProcess, OpaqueFunction


class Context:
    def __init__(self, configurations):
        self.launch_configurations = configurations


def main():
    path, words = sys.argv[1], sys.argv[2:]
    spec = importlib.util.spec_from_file_location("launch_file", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    declared = {
        e.name: e.default_value
        for e in description.entities
        if isinstance(e, DeclareLaunchArgument)
    }
    given = {}
    for w in words:
        name, sep, value = w.partition(":=")
        if not sep or name not in declared:
            sys.exit(f"run_launch: {w!r} is not name:=value of a declared argument")
        given[name] = value
    context = Context({**declared, **given})
    processes = []
    pending = list(description.entities)
    try:
        while pending:
            e = pending.pop(0)
            if isinstance(e, OpaqueFunction):
                pending[0:0] = list(e.function(context) or [])
            elif isinstance(e, ExecuteProcess):
                processes.append({"name": e.name, "cmd": [str(c) for c in e.cmd]})
    except RuntimeError as err:
        print(f"launch error: {err}", file=sys.stderr)
        sys.exit(2)
    print(json.dumps(processes))


main()
"#,
    ),
];

/// The directory holding the stub (written once per test process, in
/// `target/tmp/launch_file_stub`).
fn stub() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        // Rewritten by every run, in cargo's directory for test scratch files.
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("launch_file_stub");
        for (rel, text) in STUB {
            let path = dir.join(rel);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        }
        dir
    })
}

/// `target/<profile>/`, next to this test's `deps/` directory, holding the node binaries;
/// they are built there (`cargo build -p kerf_trajectory_executor …`, the same profile) when
/// one is missing. A test of the root package cannot name another package's binary with
/// `CARGO_BIN_EXE_*`.
fn bin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let me = std::env::current_exe().expect("test executable");
        let dir = me
            .parent()
            .and_then(Path::parent)
            .expect("target/<profile>")
            .to_path_buf();
        if NODES.iter().all(|n| dir.join(n).is_file()) {
            return dir;
        }
        let profile = dir
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("debug")
            .to_string();
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut cmd = Command::new(cargo);
        cmd.arg("build").current_dir(ROOT);
        for n in NODES {
            cmd.args(["-p", &format!("kerf_{n}")]);
        }
        match profile.as_str() {
            "debug" => {}
            "release" => {
                cmd.arg("--release");
            }
            other => {
                cmd.args(["--profile", other]);
            }
        }
        let status = cmd.status().expect("run cargo build of the node binaries");
        assert!(status.success(), "cargo build of the node binaries failed");
        for n in NODES {
            assert!(dir.join(n).is_file(), "{n} missing after the build");
        }
        dir
    })
}

fn text(out: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Runs a launch file on the stub with `args` (`name:=value`), without any kerf data
/// variable.
fn launch_py(file: &Path, args: &[String]) -> Output {
    Command::new("python3")
        .arg(stub().join("run_launch.py"))
        .arg(file)
        .args(args)
        .env("PYTHONPATH", stub())
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env_remove("KERF_DATA_DIR")
        .env_remove("KERF_URDF_DIR")
        .output()
        .expect("run python3")
}

/// The source tree's launch file.
fn source_launch_file() -> PathBuf {
    Path::new(ROOT).join("launch_scripts/kerf.launch.py")
}

/// The processes the source tree's launch file starts with `args` (the built binaries):
/// (node name, command line).
fn py_nodes(args: &[&str]) -> Vec<(String, Vec<String>)> {
    let mut args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    args.push(format!("bin_dir:={}", bin_dir().display()));
    let out = launch_py(&source_launch_file(), &args);
    assert!(
        out.status.success(),
        "kerf.launch.py {args:?}: {}",
        text(&out)
    );
    let v: Json = serde_json::from_slice(&out.stdout).unwrap();
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let cmd: Vec<String> = p["cmd"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| c.as_str().unwrap().to_string())
                .collect();
            (p["name"].as_str().unwrap().to_string(), cmd)
        })
        .collect()
}

/// `kerf launch` with `args`, without any kerf data variable.
fn kerf_launch(args: &[&str]) -> Command {
    let mut cmd = Command::new(KERF);
    cmd.arg("launch")
        .args(args)
        .env_remove("KERF_DATA_DIR")
        .env_remove("KERF_URDF_DIR")
        .env_remove("ROS_STATIC_PEERS")
        .env_remove("RMW_IMPLEMENTATION");
    cmd
}

/// `kerf launch --print-config` with `args`.
fn print_config(args: &[&str]) -> Json {
    let out = kerf_launch(args).arg("--print-config").output().unwrap();
    assert!(out.status.success(), "kerf launch {args:?}: {}", text(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn param_json(v: &ParamValue) -> Json {
    match v {
        ParamValue::Bool(b) => Json::from(*b),
        ParamValue::Integer(i) => Json::from(*i),
        ParamValue::Double(d) => Json::from(*d),
        ParamValue::String(s) => Json::from(s.clone()),
        ParamValue::BoolArray(a) => Json::from(a.clone()),
        ParamValue::IntegerArray(a) => Json::from(a.clone()),
        ParamValue::DoubleArray(a) => Json::from(a.clone()),
        ParamValue::StringArray(a) => Json::from(a.clone()),
    }
}

/// What a node started with `cmd` is, as a kerf node reads its command line: name,
/// namespace, where `~/joint_trajectory` resolves, the effective parameters (files read).
fn effective(cmd: &[String]) -> (String, String, String, BTreeMap<String, Json>) {
    let exe = Path::new(&cmd[0]).file_name().unwrap().to_str().unwrap();
    let args = RosArgs::parse(cmd[1..].iter().cloned()).unwrap();
    let name = args.node_name(exe).unwrap();
    let ns = args.namespace(exe, "/").unwrap();
    let fqn = names::expand("~", &ns, &name).unwrap();
    let params = args.params_for(&fqn, &name).unwrap();
    let trajectory = names::resolve("~/joint_trajectory", &ns, &name, &args.remaps).unwrap();
    let params = params
        .iter()
        .map(|(k, v)| (k.clone(), param_json(v)))
        .collect();
    (name, ns, trajectory, params)
}

/// Checks that `kerf.launch.py` with `py_args` and `kerf launch` with `kerf_args` start the
/// same nodes with the same command lines and effective configuration; returns the latter.
fn same_launch(py_args: &[&str], kerf_args: &[&str]) -> Json {
    let py = py_nodes(py_args);
    let config = print_config(kerf_args);
    let kerf = config["nodes"].as_array().unwrap();
    let names = |v: Vec<&str>| v.join(", ");
    assert_eq!(
        names(py.iter().map(|(n, _)| n.as_str()).collect()),
        names(
            kerf.iter()
                .map(|n| n["executable"].as_str().unwrap())
                .collect()
        ),
        "the node sets of kerf.launch.py {py_args:?} and kerf launch {kerf_args:?}"
    );
    for ((name, cmd), k) in py.iter().zip(kerf) {
        assert_eq!(cmd[0], bin_dir().join(name).display().to_string());
        let kerf_argv: Vec<&str> = k["arguments"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_str().unwrap())
            .collect();
        assert_eq!(
            cmd[1..].iter().map(String::as_str).collect::<Vec<_>>(),
            kerf_argv,
            "{name}: the command lines of kerf.launch.py {py_args:?} and kerf launch \
             {kerf_args:?}"
        );
        let (node, ns, trajectory, params) = effective(cmd);
        assert_eq!(k["name"], node.as_str());
        assert_eq!(k["namespace"], ns.as_str(), "{name}");
        assert_eq!(k["joint_trajectory"], trajectory.as_str(), "{name}");
        let kerf_params: BTreeMap<String, Json> = k["parameters"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(a, b)| (a.clone(), b.clone()))
            .collect();
        assert_eq!(kerf_params, params, "{name}: the effective parameters");
    }
    config
}

/// A cell file: the shipped laser cutter's, its `kerf_launch` settings replaced by
/// `settings` (indented lines), and `extra` sections appended.
fn cell_file(dir: &Path, name: &str, settings: &str, extra: &str) -> PathBuf {
    let shipped =
        std::fs::read_to_string(Path::new(ROOT).join("launch_scripts/params/laser_cutter.yaml"))
            .unwrap();
    let at = shipped.find("/**/trajectory_executor:").unwrap();
    let text = format!(
        "kerf_launch:\n  ros__parameters:\n{settings}\n{}\n{extra}",
        &shipped[at..]
    );
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The settings of the test cell: the laser cutter in `/cell`, both its planners.
const CELL: &str = "    robot: laser_cutter\n    namespace: /cell\n    \
                    planners: [mjto_planner, gcode_planner]\n";
/// A planner section: the G-code planner's queue, which the node reports when it starts.
const GCODE_SECTION: &str = "/**/gcode_planner:\n  ros__parameters:\n    queue_depth: 3\n";

#[test]
fn both_launchers_give_every_node_the_same_command_line() {
    let t = Instant::now();
    let dir = support::scratch("launch_file", "same");
    let cell = cell_file(&dir, "cell.yaml", CELL, GCODE_SECTION);
    let cell_s = cell.display().to_string();
    let planning = cell_file(
        &dir,
        "planning.yaml",
        &format!("{CELL}    executor: false\n    connect_planners: true\n"),
        "",
    );
    let planning_s = planning.display().to_string();
    let pf = |p: &str| format!("params_file:={p}");
    let (cell_arg, planning_arg) = (pf(&cell_s), pf(&planning_s));
    // The shipped robots: the executor alone, with the planners, in the simulated cell.
    let c = same_launch(
        &["robot:=laser_cutter", "with_planner:=false"],
        &["--robot", "laser_cutter"],
    );
    assert_eq!(c["nodes"].as_array().unwrap().len(), 1);
    let exec = &c["nodes"][0]["parameters"];
    assert_eq!(
        exec["initial_positions"],
        serde_json::json!([0.8, 0.7, 1.5, 0.0, 0.0, -0.05])
    );
    assert_eq!(exec["hardware"], "mock");
    let c = same_launch(
        &["robot:=irb6660"],
        &["--robot", "irb6660", "--with-planner"],
    );
    let nodes: Vec<&str> = c["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        nodes,
        ["trajectory_executor", "milling_planner", "gcode_planner"]
    );
    for n in &c["nodes"].as_array().unwrap()[1..] {
        assert_eq!(
            n["joint_trajectory"], "/trajectory_executor/joint_trajectory",
            "{n}"
        );
    }
    let c = same_launch(
        &["robot:=irb6660", "sim:=true"],
        &["--robot", "irb6660", "--sim"],
    );
    let exec = &c["nodes"][0]["parameters"];
    assert_eq!(exec["hardware"], "sim");
    assert!(exec["sim_cell"]
        .as_str()
        .unwrap()
        .ends_with("urdf/cells/irb6660_plate.yaml"));
    // A cell file: its namespace, its planners and their sections, every node given the file.
    let c = same_launch(&[&cell_arg], &["--params-file", &cell_s, "--with-planner"]);
    assert_eq!(c["namespace"], "/cell");
    for n in c["nodes"].as_array().unwrap() {
        assert_eq!(n["namespace"], "/cell", "{n}");
        assert_eq!(
            n["joint_trajectory"], "/cell/trajectory_executor/joint_trajectory",
            "{n}"
        );
        let args: Vec<&str> = n["arguments"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_str().unwrap())
            .collect();
        assert!(
            args.windows(2).any(|w| w == ["--params-file", &cell_s]),
            "{n}"
        );
    }
    assert_eq!(c["nodes"][2]["parameters"]["queue_depth"], 3);
    assert_eq!(c["nodes"][2]["parameters"]["machine"], "laser-cutter");
    // Picking nodes of the cell, and a planning host's file (planners only).
    same_launch(
        &[&cell_arg, "nodes:=gcode_planner,trajectory_executor"],
        &[
            "--params-file",
            &cell_s,
            "--only",
            "gcode_planner,trajectory_executor",
        ],
    );
    let c = same_launch(
        &[&planning_arg, "with_planner:=false"],
        &["--params-file", &planning_s],
    );
    let nodes: Vec<&str> = c["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(nodes, ["mjto_planner", "gcode_planner"]);
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "both launchers agree on 6 launches in {:.1} s",
        t.elapsed().as_secs_f64()
    );
}

/// Waits until every one of `needles` has appeared in a line of `lines`.
fn wait_all(lines: &mut Lines, needles: &[&str], within: Duration) -> Vec<String> {
    let deadline = Instant::now() + within;
    let mut found: Vec<Option<String>> = vec![None; needles.len()];
    while found.iter().any(Option::is_none) {
        let line = lines.wait_for("", deadline.saturating_duration_since(Instant::now()));
        for (f, n) in found.iter_mut().zip(needles) {
            if f.is_none() && line.contains(n) {
                *f = Some(line.clone());
            }
        }
    }
    found.into_iter().flatten().collect()
}

/// Waits until a client on `domain` sees the laser cell's nodes in `ns`: the executor's joint
/// states, status and input, both planners' plans, a writer on the executor's input (the
/// executor writes none there: a planner's, each planner's log line says where it writes);
/// and nothing of them in another namespace.
fn wait_for_cell(domain: u16, ns: &str) {
    let env = loopback(domain, ServiceMapping::Enhanced);
    let client = client_node("launch_file_check", &env);
    let input = format!("{ns}/trajectory_executor/joint_trajectory");
    let deadline = Instant::now() + UP;
    loop {
        let topics = client.discovered_topics();
        let has = |prefix: &str| topics.iter().any(|(t, _)| t.starts_with(prefix));
        let up = has(&format!("{ns}/joint_states"))
            && has(&format!("{ns}/trajectory_executor/trajectory_status"))
            && has(&format!("{ns}/mjto_planner/"))
            && has(&format!("{ns}/gcode_planner/"))
            && has(&input)
            && client.discovered_reader_count(&input) >= 1;
        if up {
            let stray: Vec<&String> = topics
                .iter()
                .map(|(t, _)| t)
                .filter(|t| {
                    NODES.iter().any(|n| t.contains(&format!("/{n}/"))) && !t.starts_with(ns)
                })
                .collect();
            assert!(stray.is_empty(), "nodes outside {ns}: {stray:?}");
            return;
        }
        assert!(
            Instant::now() < deadline,
            "the cell did not come up in {ns} on domain {domain}; discovered: {topics:?}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// DDS on loopback in `domain`, nothing of the caller's ROS environment.
fn dds(cmd: &mut Command, domain: u16) -> &mut Command {
    cmd.env("ROS_DOMAIN_ID", domain.to_string())
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .env_remove("ROS_STATIC_PEERS")
        .env_remove("RMW_IMPLEMENTATION")
        .env_remove("KERF_DATA_DIR")
        .env_remove("KERF_URDF_DIR")
        .stdin(Stdio::null())
}

#[test]
fn the_launch_files_nodes_come_up_in_the_files_namespace_as_with_kerf_launch() {
    let dir = support::scratch("launch_file", "run");
    let cell = cell_file(&dir, "cell.yaml", CELL, GCODE_SECTION);
    let cell_s = cell.display().to_string();

    // kerf.launch.py's command lines, each node its own process (domain 210).
    let t = Instant::now();
    let mut children: Vec<(String, Killed, Lines)> = Vec::new();
    for (name, cmd) in py_nodes(&[&format!("params_file:={cell_s}")]) {
        let mut c = Command::new(&cmd[0]);
        c.args(&cmd[1..]).stdout(Stdio::null());
        dds(&mut c, 210);
        let (child, lines) = Lines::spawn(c);
        children.push((name, child, lines));
    }
    let names: Vec<&str> = children.iter().map(|(n, _, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["trajectory_executor", "mjto_planner", "gcode_planner"]
    );
    for (name, _, lines) in &mut children {
        let needle = if name == "trajectory_executor" {
            "ready"
        } else {
            "serving"
        };
        let line = lines.wait_for(needle, UP);
        assert!(line.contains(&format!("[cell.{name}]")), "{line}");
        if name == "gcode_planner" {
            // Its section of the file reached it.
            assert!(line.contains("queue_depth 3"), "{line}");
        }
        if name != "trajectory_executor" {
            assert!(
                line.contains("trajectories on /cell/trajectory_executor/joint_trajectory"),
                "{line}"
            );
        }
    }
    wait_for_cell(210, "/cell");
    for (_, child, _) in &children {
        interrupt(&child.0);
    }
    for (name, child, lines) in &mut children {
        lines.wait_for("shutting down", EXIT);
        assert_clean_exit(&mut child.0, EXIT);
        eprintln!("{name}: clean exit");
    }
    eprintln!(
        "kerf.launch.py's processes up in /cell and stopped in {:.1} s",
        t.elapsed().as_secs_f64()
    );

    // kerf launch with the same file: the same nodes in the same namespace (domain 211).
    let t = Instant::now();
    let mut cmd = kerf_launch(&["--params-file", &cell_s, "--with-planner"]);
    dds(&mut cmd, 211).stdout(Stdio::null());
    let (mut launch, mut lines) = Lines::spawn(cmd);
    let seen = wait_all(
        &mut lines,
        &[
            "kerf launch: trajectory_executor, mjto_planner, gcode_planner in /cell",
            "[cell.trajectory_executor]: ready",
            "[cell.mjto_planner]: serving",
            "[cell.gcode_planner]: serving",
        ],
        UP,
    );
    assert!(seen[3].contains("queue_depth 3"), "{}", seen[3]);
    wait_for_cell(211, "/cell");
    interrupt(&launch.0);
    assert_clean_exit(&mut launch.0, EXIT);
    eprintln!(
        "kerf launch's nodes up in /cell and stopped in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_launch_settings_are_refused_by_both_launchers_naming_the_key() {
    let dir = support::scratch("launch_file", "bad");
    let cases: [(&str, &str, &[&str], &[&str]); 9] = [
        (
            "    namespace: cell\n",
            "kerf_launch.namespace: 'cell' must start with '/' (e.g. /cell)",
            &[],
            &[],
        ),
        (
            "    namespace: /cell/\n",
            "kerf_launch.namespace: '/cell/' must not end with '/'",
            &[],
            &[],
        ),
        (
            "    planners: [mjto_planner, cutter_planner]\n",
            "kerf_launch.planners: unknown planner 'cutter_planner'",
            &[],
            &[],
        ),
        (
            "    robot: laser_cutter\n    planners: [milling_planner]\n",
            "kerf_launch.planners: milling_planner does not plan for laser_cutter",
            &[],
            &[],
        ),
        (
            "    robot: laser_cutter\n",
            "robot irb6660 contradicts",
            &["robot:=irb6660"],
            &["--robot", "irb6660"],
        ),
        (
            "    executor: on\n",
            "kerf_launch.executor: expected true or false, got 'on'",
            &[],
            &[],
        ),
        (
            "    executor: false\n    planners: []\n",
            "nothing to launch",
            &[],
            &[],
        ),
        ("    hosts: 2\n", "kerf_launch.hosts: unknown key", &[], &[]),
        (
            "    planners: [gcode_planner]\n",
            "node 'mjto_planner' is not in the cell",
            &["nodes:=mjto_planner"],
            &["--only", "mjto_planner"],
        ),
    ];
    for (i, (settings, needle, py_extra, kerf_extra)) in cases.iter().enumerate() {
        let file = cell_file(&dir, &format!("bad{i}.yaml"), settings, "");
        let file_s = file.display().to_string();
        let mut py_args = vec![
            format!("params_file:={file_s}"),
            format!("bin_dir:={}", bin_dir().display()),
        ];
        py_args.extend(py_extra.iter().map(|s| s.to_string()));
        let out = launch_py(&source_launch_file(), &py_args);
        assert_eq!(out.status.code(), Some(2), "{settings}: {}", text(&out));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(needle) && err.contains(&file_s),
            "kerf.launch.py, {settings}: {err}"
        );
        let mut args = vec!["--params-file", &file_s];
        args.extend(kerf_extra.iter());
        let out = kerf_launch(&args).arg("--print-config").output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{settings}: {}", text(&out));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(needle) && err.contains(&file_s),
            "kerf launch, {settings}: {err}"
        );
        // Refused before any node starts.
        let out = dds(&mut kerf_launch(&args), 219).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{settings}: {}", text(&out));
        assert!(
            !String::from_utf8_lossy(&out.stderr).contains("ready"),
            "{}",
            text(&out)
        );
    }
    // The launch arguments themselves.
    for (args, needle) in [
        (&["robot:=ur5"][..], "robot must be laser_cutter or irb6660"),
        (&["nodes:=planner"][..], "nodes: unknown node 'planner'"),
        (
            &["sim_mode:=dynamic"][..],
            "sim_mode:=dynamic needs sim:=true",
        ),
        (
            &["with_planner:=maybe"][..],
            "with_planner must be true or false",
        ),
    ] {
        let mut a: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        a.push(format!("bin_dir:={}", bin_dir().display()));
        let out = launch_py(&source_launch_file(), &a);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", text(&out));
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(needle),
            "{args:?}: {}",
            text(&out)
        );
    }
    let out = launch_py(
        &source_launch_file(),
        &["bin_dir:=/nonexistent".to_string()],
    );
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("/nonexistent/trajectory_executor not found"),
        "{}",
        text(&out)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The executor's `initial_positions` in a robot's shipped parameters file.
fn shipped_start(robot: &str) -> Vec<f64> {
    let file = format!("{ROOT}/launch_scripts/params/{robot}.yaml");
    let args = RosArgs::parse(["--ros-args", "--params-file", &file]).unwrap();
    args.params_for("/trajectory_executor", "trajectory_executor")
        .unwrap()
        .f64_array("initial_positions")
        .unwrap()
        .unwrap()
}

#[test]
fn the_shipped_start_poses_are_clear_of_each_robots_cell() {
    for (robot, cell, clearance) in [
        ("laser_cutter", "laser_bpillar", 0.05),
        ("irb6660", "irb6660_plate", 0.15),
    ] {
        let start = shipped_start(robot);
        let mut sim = kerf_cell::Cell::from_files(
            &Path::new(ROOT).join(format!("urdf/{robot}.urdf")),
            &Path::new(ROOT).join(format!("urdf/cells/{cell}.yaml")),
            kerf_cell::CellSettings::default(),
        )
        .unwrap();
        let state = sim.reset(&start).unwrap();
        assert!(state.contacts.is_empty(), "{robot}: {:?}", state.contacts);
        let distances = sim.distances();
        let (shape, object, d) = distances
            .iter()
            .filter_map(|(s, o, d)| d.map(|d| (s, o, d)))
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .unwrap();
        eprintln!("{robot} at {start:?}: nearest {shape} to {object}, {d:.3} m");
        assert!(
            d >= clearance,
            "{robot}: {shape} is {d} m from {object}, under {clearance} m"
        );
    }
}

/// The lines of README.md's fenced block that starts after the line `opening` (exclusive)
/// and ends at the line `closing`.
fn readme_block(opening: &str, closing: &str) -> String {
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    let start = readme
        .find(opening)
        .unwrap_or_else(|| panic!("README.md has no line {opening:?}"))
        + opening.len()
        + 1;
    let len = readme[start..]
        .find(&format!("\n{closing}\n"))
        .unwrap_or_else(|| panic!("README.md: no {closing:?} after {opening:?}"));
    readme[start..start + len + 1].to_string()
}

/// README.md holds `line` as written.
fn readme_line(line: &str) -> String {
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    assert!(
        readme.lines().any(|l| l.trim_end() == line),
        "README.md has no line {line:?}"
    );
    line.to_string()
}

/// A README command line (`[VAR=value ...] kerf ARGS`) as a command of the built `kerf`, in
/// loopback `domain` (its own `ROS_DOMAIN_ID` replaced).
fn readme_kerf(line: &str, domain: u16) -> Command {
    let mut words = line.split_whitespace().peekable();
    let mut env = Vec::new();
    while let Some(w) = words.peek() {
        match w.split_once('=') {
            Some((k, v)) if k.chars().all(|c| c.is_ascii_uppercase() || c == '_') => {
                env.push((k.to_string(), v.to_string()));
                words.next();
            }
            _ => break,
        }
    }
    let first = words.next().unwrap();
    let rest: Vec<&str> = if first == "cargo" {
        let w: Vec<&str> = words.collect();
        assert_eq!(&w[..3], ["run", "--release", "--"], "{line}");
        w[3..].to_vec()
    } else {
        assert_eq!(first, "kerf", "{line}");
        words.collect()
    };
    let mut cmd = Command::new(KERF);
    cmd.args(rest);
    for (k, v) in env {
        if k != "ROS_DOMAIN_ID" {
            cmd.env(k, v);
        }
    }
    dds(&mut cmd, domain);
    cmd
}

#[test]
fn the_readmes_launch_examples_run_as_written() {
    // "Across hosts": the executor on one host, the MJTO planner on another, one file.
    let t = Instant::now();
    let host_a =
        readme_line("ROS_DOMAIN_ID=42 kerf launch --robot laser_cutter --only trajectory_executor");
    let host_b =
        readme_line("ROS_DOMAIN_ID=42 kerf launch --robot laser_cutter --only mjto_planner");
    let (mut a, mut a_lines) = Lines::spawn(readme_kerf(&host_a, 212));
    let (mut b, mut b_lines) = Lines::spawn(readme_kerf(&host_b, 212));
    a_lines.wait_for("[trajectory_executor]: ready", UP);
    let line = b_lines.wait_for("[mjto_planner]: serving", UP);
    assert!(
        line.contains("trajectories on /trajectory_executor/joint_trajectory"),
        "{line}"
    );
    let env = loopback(212, ServiceMapping::Enhanced);
    let client = client_node("readme_check", &env);
    let deadline = Instant::now() + UP;
    loop {
        let topics = client.discovered_topics();
        let writer = topics
            .iter()
            .any(|(t, _)| t == "/trajectory_executor/joint_trajectory");
        if writer && client.discovered_reader_count("/trajectory_executor/joint_trajectory") >= 1 {
            assert!(
                !topics.iter().any(|(t, _)| t.starts_with("/gcode_planner/")),
                "{topics:?}"
            );
            break;
        }
        assert!(Instant::now() < deadline, "not connected: {topics:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
    drop(client);
    for child in [&a, &b] {
        interrupt(&child.0);
    }
    assert_clean_exit(&mut a.0, EXIT);
    assert_clean_exit(&mut b.0, EXIT);
    eprintln!(
        "across hosts: connected and stopped in {:.1} s",
        t.elapsed().as_secs_f64()
    );

    // "Two commands" and "Watching and driving the executor": the IRB 6660 from its shipped
    // start pose, a move published with kerf pub, run to its end.
    let t = Instant::now();
    let launch_line = readme_line(
        "ROS_DOMAIN_ID=42 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST cargo run --release -- launch --robot irb6660",
    );
    let (mut launch, mut lines) = Lines::spawn(readme_kerf(&launch_line, 213));
    lines.wait_for("[trajectory_executor]: ready", UP);
    let dir = support::scratch("launch_file", "readme");
    let doc = readme_block("cat > move.yaml <<'YAML'", "YAML");
    let file = dir.join("move.yaml");
    std::fs::write(&file, doc).unwrap();
    let pub_line =
        readme_line("cargo run --release -- pub /trajectory_executor/joint_trajectory move.yaml");
    let out = readme_kerf(&pub_line, 213)
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out));
    // Its statuses: ACCEPTED (1), then SUCCEEDED (3) at the end of the 2 s move.
    let out = readme_kerf(
        "kerf echo /trajectory_executor/trajectory_status --transient-local -n 2 --timeout 30",
        213,
    )
    .output()
    .unwrap();
    assert!(out.status.success(), "{}", text(&out));
    let yaml = String::from_utf8_lossy(&out.stdout);
    let statuses: Vec<&str> = yaml.lines().filter(|l| l.starts_with("status: ")).collect();
    assert_eq!(statuses, ["status: 1", "status: 3"], "{yaml}");
    interrupt(&launch.0);
    assert_clean_exit(&mut launch.0, EXIT);
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "the README's move ran from the shipped start pose in {:.1} s",
        t.elapsed().as_secs_f64()
    );
}
