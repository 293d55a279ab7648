//! An installed kerf finds its shipped data beside its binary (issue 12, item 4).
//!
//! The built `kerf` binary is placed as `<tmp>/prefix/bin/kerf`, `launch_scripts/install.sh
//! <tmp>/prefix --data-only` lays the data into `<tmp>/prefix/share/kerf`, and the installed
//! binary, run from another temporary directory with `KERF_DATA_DIR` removed, plans case 1
//! (`kerf plan cut`) and draws stability lobes (`kerf lobes`). That the share directory was
//! used, not the source tree the binary was built from, is shown by breaking a file in the
//! share directory only: the same commands then fail naming that file. A `KERF_DATA_DIR`
//! that is not a kerf data directory is an error naming the variable.
//!
//! Issue 27, item 4: `install.sh PREFIX --binaries-from target/<profile>` installs the node
//! binaries beside `kerf` and the ROS 2 launch file as `PREFIX/share/kerf/launch/kerf.launch.py`;
//! run on a stub of ROS 2's `launch` package (ROS is not installed here), the installed launch
//! file starts `PREFIX/bin/<node>` on the data in `PREFIX/share/kerf`, `kerf launch` from the
//! prefix reads the installed parameters file, and the installed executor starts from that
//! command line (loopback DDS, domain 214). The default mode builds the binaries with cargo
//! (not run here: a release build of five packages).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    io::{BufRead, BufReader},
    path::{Path, PathBuf},
    process::{Command, Output, Stdio},
    time::{Duration, Instant},
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
        "crates/stepping/weights/ddqn_high_arch2.safetensors",
        "crates/cornernet/weights/drls.safetensors",
        "crates/cornernet/weights/drls.json",
        "crates/millplan/data/indicator_cache.bin",
        "crates/gcode/data/programs/w_shape.ngc",
        "launch_scripts/params/irb6660.yaml",
        "launch_scripts/params/laser_cutter.yaml",
        "launch/kerf.launch.py",
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
        &["/tmp/x", "--binaries-from"][..],
        &["/tmp/x", "--data-only", "--binaries-from", "/tmp"][..],
        &["/tmp/x", "--binary-only", "--data-only"][..],
    ] {
        let out = install_sh(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", text(&out));
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("usage:"),
            "{args:?}"
        );
    }
}

/// The node binaries the launch starts, installed beside `kerf`.
const NODES: [&str; 4] = [
    "trajectory_executor",
    "mjto_planner",
    "milling_planner",
    "gcode_planner",
];

/// `target/<profile>/`, next to this test's `deps/` directory: the built `kerf` and node
/// binaries (built with `cargo build -p kerf_<node>`, the same profile, when one is missing).
fn built_binaries() -> PathBuf {
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
    let mut cmd = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
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
    assert!(cmd.status().expect("run cargo build").success());
    dir
}

/// A stub of ROS 2's `launch` package (the same as tests/launch_file.rs's) and a runner that
/// prints the processes a launch file starts as JSON, written into `dir`.
fn write_launch_stub(dir: &Path) {
    let files = [
        (
            "launch/__init__.py",
            r#"class LaunchDescription:
    def __init__(self, entities=None):
        self.entities = list(entities or [])
"#,
        ),
        (
            "launch/actions.py",
            r#"class DeclareLaunchArgument:
    def __init__(self, name, default_value=None, **_):
        self.name, self.default_value = name, default_value


class ExecuteProcess:
    def __init__(self, *, cmd, name=None, **_):
        self.cmd, self.name = cmd, name


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
        return context[self.name]
"#,
        ),
        (
            "run_launch.py",
            r#"import importlib.util
import json
import sys

from launch.actions import DeclareLaunchArgument, ExecuteProcess, OpaqueFunction

spec = importlib.util.spec_from_file_location("launch_file", sys.argv[1])
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
entities = module.generate_launch_description().entities
context = {e.name: e.default_value for e in entities if isinstance(e, DeclareLaunchArgument)}
context.update(w.split(":=", 1) for w in sys.argv[2:])
out = []
for e in entities:
    if isinstance(e, OpaqueFunction):
        for p in e.function(context):
            if isinstance(p, ExecuteProcess):
                out.append({"name": p.name, "cmd": [str(c) for c in p.cmd]})
print(json.dumps(out))
"#,
        ),
    ];
    for (rel, text) in files {
        let path = dir.join(rel);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
}

#[test]
fn install_sh_installs_the_node_binaries_and_a_launch_file_that_runs_them() {
    let base = scratch("launch");
    let prefix = base.join("prefix");
    let from = built_binaries();
    let out = install_sh(&[
        prefix.to_str().expect("utf-8 temp dir"),
        "--binaries-from",
        from.to_str().expect("utf-8 target dir"),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let share = prefix.join("share/kerf");
    for bin in NODES.iter().chain(&["kerf"]) {
        let path = prefix.join("bin").join(bin);
        let mode = std::os::unix::fs::PermissionsExt::mode(
            &std::fs::metadata(&path)
                .unwrap_or_else(|e| panic!("{bin} not installed: {e}"))
                .permissions(),
        );
        assert!(mode & 0o111 != 0, "{bin} not executable");
    }
    let launch_file = share.join("launch/kerf.launch.py");
    assert!(launch_file.is_file());
    for rel in [
        "launch_scripts/params/laser_cutter.yaml",
        "launch_scripts/params/irb6660.yaml",
        "urdf/cells/irb6660_plate.yaml",
    ] {
        assert!(share.join(rel).is_file(), "{rel} not installed");
    }

    // The installed launch file, run from another directory without any kerf variable:
    // PREFIX/bin's binaries on PREFIX/share/kerf's data.
    let stub = base.join("stub");
    write_launch_stub(&stub);
    let work = scratch("launch_work");
    let out = Command::new("python3")
        .arg(stub.join("run_launch.py"))
        .arg(&launch_file)
        .args(["robot:=irb6660", "sim:=true"])
        .current_dir(&work)
        .env("PYTHONPATH", &stub)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env_remove("KERF_DATA_DIR")
        .env_remove("KERF_URDF_DIR")
        .output()
        .expect("run python3");
    assert!(out.status.success(), "{}", text(&out));
    let processes: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let processes = processes.as_array().unwrap();
    let names: Vec<&str> = processes
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["trajectory_executor", "milling_planner", "gcode_planner"]
    );
    let prefix_s = prefix.display().to_string();
    let share_s = share.display().to_string();
    for p in processes {
        let cmd: Vec<&str> = p["cmd"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap())
            .collect();
        assert_eq!(
            cmd[0],
            format!("{prefix_s}/bin/{}", p["name"].as_str().unwrap())
        );
        assert!(
            cmd.windows(2).any(|w| w
                == [
                    "--params-file",
                    &format!("{share_s}/launch_scripts/params/irb6660.yaml")
                ]),
            "{cmd:?}"
        );
        // Every path it names is below the prefix.
        for arg in &cmd {
            let named_path = arg
                .split_once(":=")
                .filter(|(name, v)| !name.starts_with("__") && v.starts_with('/'));
            if let Some((_, path)) = named_path {
                assert!(path.starts_with(&share_s), "{arg} is not in {share_s}");
                assert!(Path::new(path).is_file(), "{arg}: no such file");
            }
        }
    }
    let exec: Vec<String> = processes[0]["cmd"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    assert!(exec.contains(&format!("urdf_file:={share_s}/urdf/irb6660.urdf")));
    assert!(exec.contains(&format!(
        "sim_cell:={share_s}/urdf/cells/irb6660_plate.yaml"
    )));

    // kerf launch from the prefix reads the installed parameters file, and its executor's
    // command line is the launch file's.
    let out = Command::new(prefix.join("bin/kerf"))
        .args(["launch", "--robot", "irb6660", "--sim", "--print-config"])
        .current_dir(&work)
        .env_remove("KERF_DATA_DIR")
        .env_remove("KERF_URDF_DIR")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out));
    let config: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        config["params_file"],
        format!("{share_s}/launch_scripts/params/irb6660.yaml")
    );
    let kerf_exec: Vec<&str> = config["nodes"][0]["arguments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    assert_eq!(
        kerf_exec,
        exec[1..].iter().map(String::as_str).collect::<Vec<_>>()
    );

    // The installed executor starts from that command line, on the simulated cell.
    let mut child = Command::new(&exec[0])
        .args(&exec[1..])
        .current_dir(&work)
        .env("ROS_DOMAIN_ID", "214")
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .env_remove("ROS_STATIC_PEERS")
        .env_remove("RMW_IMPLEMENTATION")
        .env_remove("KERF_DATA_DIR")
        .env_remove("KERF_URDF_DIR")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the installed executor");
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let deadline = Instant::now() + Duration::from_secs(60);
    let mut seen = Vec::new();
    let ready = loop {
        match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
            Ok(line) if line.contains("ready") => break line,
            Ok(line) => seen.push(line),
            Err(_) => {
                let _ = child.kill();
                let _ = child.wait();
                panic!("the installed executor did not start: {seen:?}");
            }
        }
    };
    assert!(ready.contains("abb_irb6660_130_3_1"), "{ready}");
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    let deadline = Instant::now() + Duration::from_secs(20);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the installed executor did not stop on Ctrl-C");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "{status}");

    std::fs::remove_dir_all(&base).expect("remove the prefix");
    std::fs::remove_dir_all(&work).expect("remove the work dir");
}

/// The default mode builds the five packages in one `cargo build --release --locked` and
/// installs what it built. Run with a stand-in `cargo` on `PATH` that records its arguments
/// and leaves a script for each binary in `$CARGO_TARGET_DIR/release` (a real release build of
/// five packages takes too long for a test); that every package and binary named exists is
/// checked against `cargo metadata`.
#[test]
fn install_sh_builds_the_binaries_in_one_cargo_build_by_default() {
    let base = scratch("default");
    let fake = base.join("fakebin");
    std::fs::create_dir_all(&fake).unwrap();
    let log = base.join("cargo.log");
    std::fs::write(
        fake.join("cargo"),
        format!(
            "#!/usr/bin/env bash\n\
             echo \"$*\" > {log}\n\
             mkdir -p \"$CARGO_TARGET_DIR/release\"\n\
             for b in kerf trajectory_executor mjto_planner milling_planner gcode_planner; do\n\
             \x20 printf '#!/bin/sh\\necho %s\\n' \"$b\" > \"$CARGO_TARGET_DIR/release/$b\"\n\
             \x20 chmod 755 \"$CARGO_TARGET_DIR/release/$b\"\n\
             done\n",
            log = log.display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(
        fake.join("cargo"),
        std::os::unix::fs::PermissionsExt::from_mode(0o755),
    )
    .unwrap();
    let prefix = base.join("prefix");
    let path = format!(
        "{}:{}",
        fake.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = Command::new("bash")
        .arg(Path::new(ROOT).join("launch_scripts/install.sh"))
        .arg(&prefix)
        .arg("--binary-only")
        .env("PATH", path)
        .env("CARGO_TARGET_DIR", base.join("target"))
        .output()
        .expect("run install.sh");
    assert!(out.status.success(), "{}", text(&out));
    let args = std::fs::read_to_string(&log).unwrap();
    let mut packages = Vec::new();
    let mut words = args.split_whitespace();
    assert_eq!(
        words.by_ref().take(3).collect::<Vec<_>>(),
        ["build", "--release", "--locked"],
        "{args}"
    );
    while let Some(w) = words.next() {
        assert_eq!(w, "-p", "{args}");
        packages.push(words.next().unwrap().to_string());
    }
    for (bin, package) in NODES.iter().chain(&["kerf"]).map(|b| {
        let package = if *b == "kerf" {
            "kerf".to_string()
        } else {
            format!("kerf_{b}")
        };
        (*b, package)
    }) {
        assert!(packages.contains(&package), "{package} not built: {args}");
        let installed = prefix.join("bin").join(bin);
        let out = Command::new(&installed).output().unwrap();
        assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), bin);
    }
    assert!(
        !prefix.join("share").exists(),
        "--binary-only installed data"
    );
    // The packages and binaries exist in the workspace.
    let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args([
            "metadata",
            "--no-deps",
            "--format-version",
            "1",
            "--offline",
        ])
        .current_dir(ROOT)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out));
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for package in &packages {
        let p = meta["packages"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == package.as_str())
            .unwrap_or_else(|| panic!("no package {package} in the workspace"));
        let bins: Vec<&str> = p["targets"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|t| t["kind"].as_array().unwrap().iter().any(|k| k == "bin"))
            .map(|t| t["name"].as_str().unwrap())
            .collect();
        let want = package.strip_prefix("kerf_").unwrap_or(package);
        assert!(
            bins.contains(&want),
            "{package} has no binary {want}: {bins:?}"
        );
    }
    std::fs::remove_dir_all(&base).expect("remove the scratch dir");
}
