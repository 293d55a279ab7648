//! The probe as a test (issue 33, item 8): every class of hostile or heavy input of the
//! independent probe, sent to every planner node over DDS (loopback only, one domain per node:
//! 171 cut, 172 milling, 173 G-code). The executor's share is in `action_e2e.rs`
//! (`every_number_of_a_goal_is_refused_naming_it`), the command line's in `cli_bounds.rs`.
//!
//! Per node, started with `queue_depth:=1`, `plan_timeout:=5.0`, `plan_memory:=256 MiB` and
//! `allowed_file_roots` on a scratch directory:
//!
//! * **numbers**: every numeric leaf of a request message (of each array, its first and last
//!   element) set in turn to each of NaN, ±inf, ±0, 5e-324, ±1e308 and the integer extremes
//!   that its declared rule (`kerf_msgs::numbers`) refuses: INVALID_REQUEST naming the field;
//! * **files**: the request's file field naming a FIFO, a directory, `/dev/zero`, a symlink out
//!   of the roots, a `..` path out of them, a `file://` URI out of them: a named refusal
//!   (never INTERNAL_ERROR, never the file's contents);
//! * **heavy**: a text request over the 4 MiB cap (refused unparsed, its answer carrying the id
//!   of its first line), requests whose plan outgrows the deadline or the memory budget:
//!   TIMEOUT, RESOURCE_LIMIT or a refusal;
//! * **burst**: twelve requests at once against a queue of one: each answered once, those over
//!   the queue QUEUE_FULL in arrival order;
//! * **signal**: the node stopped (what Ctrl-C does) during a heavy plan: it ends within 2 s
//!   with the plan in progress answered.
//!
//! Each case is answered within 15 s, a valid request right after each class succeeds, and this
//! process (the three nodes; plans run in their worker processes) peaks under the memory budget
//! plus its idle size.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    fmt::Debug,
    path::{Path, PathBuf},
    time::{Duration, Instant},
};

use kerf_msgs::{
    msg::{self, CutPlan, GcodePlan, MillPlan},
    numbers::{
        probe::{refused_cases, with_value},
        NumberFields, NumberRules,
    },
    RosType,
};
use kerf_ros::ros2_client::ServiceMapping;
use serde::{de::DeserializeOwned, Serialize};

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use support::planner::{expect, gcode, mill, mjto, Answer, Planner, PlannerClient};

/// Every case is answered within this.
const ANSWER: Duration = Duration::from_secs(15);

/// The nodes' plan_memory (bytes).
const PLAN_MEMORY: u64 = 256 << 20;

/// What this process (three idle planner nodes, their clients and this test) may hold beside
/// the budget: measured 150-230 MiB.
const IDLE_ALLOWANCE_MIB: f64 = 512.0;

/// One planner node's probe: its request message `Req`, its answer `Plan`.
struct Probe<Req, Plan> {
    name: &'static str,
    planner: Planner<Req, Plan>,
    domain: u16,
    /// A message every field of which is given (flags set, arrays non-empty); refused numbers
    /// are answered before planning, so it need not plan.
    numbers_base: Req,
    /// A text request that plans SUCCESS within the node's plan_timeout, `{id}` for its id.
    valid_text: String,
    /// A message naming the file `{}` in its file field, with request id `id`.
    with_file: fn(&str, &str) -> Req,
    /// The extension of the file field's files (`.stl`, …): the hostile files have it, so
    /// that the node's refusal is for what they are, not for their name.
    file_ext: &'static str,
    /// Heavy requests (text), `{id}` for the id.
    heavy: Vec<String>,
    /// The statuses of the answer.
    status: Statuses,
}

/// The status values of one answer type.
#[derive(Clone, Copy)]
struct Statuses {
    success: u8,
    invalid: u8,
    queue_full: u8,
    internal: u8,
}

/// Sets the `request_id` of a message through its YAML form (every request message has one).
fn with_id<Req: Serialize + DeserializeOwned>(m: &Req, id: &str) -> Req {
    let mut v = serde_yaml_ng::to_value(m).unwrap();
    v.as_mapping_mut()
        .unwrap()
        .insert("request_id".into(), id.into());
    serde_yaml_ng::from_value(v).unwrap()
}

/// A message from YAML: the given fields over the message's defaults (nested mappings merged).
fn yaml<Req: Default + Serialize + DeserializeOwned>(text: &str) -> Req {
    fn overlay(base: &mut serde_yaml_ng::Value, given: serde_yaml_ng::Value) {
        match (base, given) {
            (serde_yaml_ng::Value::Mapping(b), serde_yaml_ng::Value::Mapping(g)) => {
                for (k, v) in g {
                    match b.get_mut(&k) {
                        Some(slot) => overlay(slot, v),
                        None => panic!("no field {k:?}"),
                    }
                }
            }
            (slot, v) => *slot = v,
        }
    }
    let mut v = serde_yaml_ng::to_value(Req::default()).unwrap();
    overlay(&mut v, serde_yaml_ng::from_str(text).unwrap());
    serde_yaml_ng::from_value(v).unwrap_or_else(|e| panic!("{e}: {text}"))
}

/// Waits for the answer to `id` (earlier answers of other ids are a failure).
fn answer<Req: RosType + Serialize + Debug, Plan: Answer>(
    client: &PlannerClient<Req, Plan>,
    id: &str,
) -> (Plan, Duration) {
    let started = Instant::now();
    let plan = client
        .try_next_plan(ANSWER)
        .unwrap_or_else(|| panic!("{id}: no answer within {ANSWER:?}"));
    assert_eq!(plan.request_id(), id, "{}", plan.message());
    (plan, started.elapsed())
}

/// A valid request right after a class of cases plans SUCCESS.
fn still_plans<Req: RosType + Serialize + Debug, Plan: Answer>(
    probe: &Probe<Req, Plan>,
    client: &PlannerClient<Req, Plan>,
    after: &str,
) {
    let id = format!("valid-after-{after}");
    client.send_text(&probe.valid_text.replace("{id}", &id));
    let (plan, took) = answer(client, &id);
    assert_eq!(
        plan.status(),
        probe.status.success,
        "{}: the valid request after the {after} cases: {}",
        probe.name,
        plan.message()
    );
    eprintln!(
        "{}: valid request after {after}: SUCCESS in {took:.2?}",
        probe.name
    );
}

/// The files of the file class: (what, path), under `root` or out of it.
fn hostile_files(dir: &Path, ext: &str) -> (PathBuf, Vec<(&'static str, String)>) {
    let (root, outside) = (dir.join("root"), dir.join("outside"));
    let sub = root.join(format!("sub{ext}"));
    std::fs::create_dir_all(&sub).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    let secret = outside.join(format!("part{ext}"));
    std::fs::write(&secret, "SECRET").unwrap();
    let fifo = root.join(format!("fifo{ext}"));
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) on a NUL-terminated path this test owns.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let link = root.join(format!("link{ext}"));
    std::os::unix::fs::symlink(&secret, &link).unwrap();
    let files = vec![
        ("a FIFO in the root", fifo.display().to_string()),
        ("a directory in the root", sub.display().to_string()),
        ("/dev/zero", "/dev/zero".to_string()),
        ("a symlink out of the root", link.display().to_string()),
        (
            "a .. path out of the root",
            format!("{}/../outside/part{ext}", root.display()),
        ),
        (
            "a file:// URI out of the root",
            format!("file://{}", secret.display()),
        ),
    ];
    (root, files)
}

/// Peak resident memory of this process (MiB).
fn peak_mib() -> f64 {
    support::status_kib("VmHWM:") as f64 / 1024.0
}

/// Runs every class against one planner node.
fn run_probe<Req, Plan>(probe: &Probe<Req, Plan>)
where
    Req: RosType + Serialize + DeserializeOwned + NumberRules + NumberFields + Debug + Clone,
    Plan: Answer,
{
    let name = probe.name;
    let dir = support::scratch("probe_e2e", name);
    let (root, files) = hostile_files(&dir, probe.file_ext);
    let env = support::loopback(probe.domain, ServiceMapping::Enhanced);
    let params = [
        "queue_depth:=1".to_string(),
        "plan_timeout:=5.0".to_string(),
        format!("plan_memory:={PLAN_MEMORY}"),
        format!("allowed_file_roots:=['{}']", root.display()),
    ];
    let mut words: Vec<&str> = Vec::new();
    for p in &params {
        words.push("-p");
        words.push(p);
    }
    let client = PlannerClient::start(&probe.planner, &env, &words);
    still_plans(probe, &client, "start");

    // Numbers.
    if let Err(e) = probe.numbers_base.check_numbers() {
        panic!("{name}: the numbers base is refused: {e}");
    }
    let cases = refused_cases(&probe.numbers_base);
    assert!(
        cases.len() > 40,
        "{name}: only {} number cases",
        cases.len()
    );
    let started = Instant::now();
    for (k, (path, value)) in cases.iter().enumerate() {
        let Ok(m) = with_value(&probe.numbers_base, path, *value) else {
            continue; // a value its field's type cannot hold (it cannot be sent either)
        };
        let id = format!("number-{k}");
        client.send(with_id(&m, &id));
        let (plan, _) = answer(&client, &id);
        let needle = format!("`{path}`");
        expect(&plan, &id, probe.status.invalid, &[needle.as_str()]);
    }
    eprintln!(
        "{name}: {} number cases refused naming the field in {:.2?}",
        cases.len(),
        started.elapsed()
    );
    still_plans(probe, &client, "numbers");

    // Files.
    for (what, file) in &files {
        let id = format!("file-{what}");
        client.send((probe.with_file)(&id, file));
        let (plan, took) = answer(&client, &id);
        assert_ne!(plan.status(), probe.status.success, "{name}: {what}");
        assert_ne!(
            plan.status(),
            probe.status.internal,
            "{name}: {what}: {}",
            plan.message()
        );
        assert!(!plan.message().contains("SECRET"), "{}", plan.message());
        eprintln!(
            "{name}: {what}: {} in {took:.2?}: {}",
            Plan::name_of(plan.status()).unwrap_or("?"),
            plan.message()
        );
    }
    still_plans(probe, &client, "files");

    // A text request over the 4 MiB cap: refused before it is parsed, the answer carrying the
    // id its first line gives.
    let over = format!(
        "request_id: over-cap\n#{}\n",
        "x".repeat(kerf_ros::planner::MAX_TEXT_REQUEST_BYTES)
    );
    client.send_text(&over);
    let (plan, took) = answer(&client, "over-cap");
    expect(&plan, "over-cap", probe.status.invalid, &["over the limit"]);
    eprintln!("{name}: a text request over the cap: INVALID_REQUEST in {took:.2?}");

    // Heavy requests.
    for (k, text) in probe.heavy.iter().enumerate() {
        let id = format!("heavy-{k}");
        client.send_text(&text.replace("{id}", &id));
        let (plan, took) = answer(&client, &id);
        assert_ne!(
            plan.status(),
            probe.status.internal,
            "{name}: heavy {k}: {}",
            plan.message()
        );
        eprintln!(
            "{name}: heavy {k}: {} in {took:.2?}: {}",
            Plan::name_of(plan.status()).unwrap_or("?"),
            plan.message()
        );
    }
    still_plans(probe, &client, "heavy requests");

    // A burst against a queue of one.
    let n = 12;
    for k in 0..n {
        client.send_text(&probe.valid_text.replace("{id}", &format!("burst-{k:02}")));
    }
    let mut order = Vec::new();
    for _ in 0..n {
        let plan = client
            .try_next_plan(ANSWER + Duration::from_secs(5 * n))
            .unwrap_or_else(|| panic!("{name}: burst: only {order:?} answered"));
        order.push((plan.request_id().to_string(), plan.status()));
    }
    let mut ids: Vec<&str> = order.iter().map(|(id, _)| id.as_str()).collect();
    let busy: Vec<&str> = order
        .iter()
        .filter(|(_, s)| *s == probe.status.queue_full)
        .map(|(id, _)| id.as_str())
        .collect();
    let mut sorted = busy.clone();
    sorted.sort_unstable();
    assert_eq!(
        busy, sorted,
        "{name}: QUEUE_FULL answers out of arrival order"
    );
    assert!(!busy.is_empty(), "{name}: no QUEUE_FULL in {order:?}");
    assert!(
        order
            .iter()
            .all(|(_, s)| *s == probe.status.success || *s == probe.status.queue_full),
        "{name}: {order:?}"
    );
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(
        ids.len(),
        n as usize,
        "{name}: each answered once: {order:?}"
    );
    eprintln!(
        "{name}: burst of {n}: {} QUEUE_FULL in arrival order",
        busy.len()
    );
    still_plans(probe, &client, "burst");

    // Memory: the plans ran in the workers.
    let peak = peak_mib();
    eprintln!("{name}: this process's peak RSS so far {peak:.0} MiB");
    assert!(
        peak < (PLAN_MEMORY >> 20) as f64 + IDLE_ALLOWANCE_MIB,
        "{name}: peak RSS {peak:.0} MiB"
    );

    // Stopped during a heavy plan: the answer is read while the node stops.
    let heavy = probe.heavy.last().unwrap().replace("{id}", "stopped");
    client.send_text(&heavy);
    std::thread::sleep(Duration::from_millis(500));
    let t0 = Instant::now();
    client.request_stop();
    let mut answered = None;
    while !client.has_stopped() {
        assert!(
            t0.elapsed() < Duration::from_secs(2),
            "{name}: still running 2 s after stop"
        );
        answered = answered.or_else(|| client.try_next_plan(Duration::ZERO));
        std::thread::sleep(Duration::from_millis(5));
    }
    let stopped_in = t0.elapsed();
    let plan = answered
        .or_else(|| client.try_next_plan(Duration::from_millis(500)))
        .unwrap_or_else(|| panic!("{name}: the plan in progress was not answered"));
    assert_eq!(plan.request_id(), "stopped");
    eprintln!(
        "{name}: stopped in {stopped_in:.2?} with the plan in progress answered {}: {}",
        Plan::name_of(plan.status()).unwrap_or("?"),
        plan.message()
    );
    client.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

/// The laser cutter's numbers base: six points along case 1's flange on the shipped B-pillar,
/// every group given.
const CUT_NUMBERS: &str = "
request_id: numbers
points: [{x: 0.6, y: -0.17763205, z: 0.0}, {x: 0.61, y: -0.17763205, z: 0.0},
  {x: 0.62, y: -0.17763205, z: 0.0}, {x: 0.63, y: -0.17763205, z: 0.0},
  {x: 0.64, y: -0.17763205, z: 0.0}, {x: 0.65, y: -0.17763205, z: 0.0}]
axes: [{x: 0.0, y: 0.0, z: 1.0}, {x: 0.0, y: 0.0, z: 1.0}, {x: 0.0, y: 0.0, z: 1.0},
  {x: 0.0, y: 0.0, z: 1.0}, {x: 0.0, y: 0.0, z: 1.0}, {x: 0.0, y: 0.0, z: 1.0}]
feedrate: 0.3
feed_acceleration: 8.0
feed_jerk: 80.0
sample_period: 0.01
max_lead_angle: 0.1
max_tilt_angle: 0.1
mesh: package://kerf/urdf/meshes/bpillar.obj
workpiece_pose: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {x: 0.0, y: 0.0, z: 0.0, w: 1.0}}
control_points: 0
max_iterations: 10
gfd_q4_steps: 13
gfd_q5_steps: 9
gfd_q6_steps: 5
gfd_q4_half_range: 0.35
gfd_q5_half_range: 0.3
rto_indices: [0, 5]
rto_spacing: 0.15
rto_angle: 0.35
has_reference_standoff: true
reference_standoff: -0.07
clearance: 0.001
cl_tolerance: 0.00015
time_budget: 4.0
";

/// Case 1 (the text of `crates/mjto/cases/case1.yaml`) with `factor` times its CL points (and
/// axes) along the same flange, its RTO indices scaled: the same cut, a much heavier plan.
fn dense(case1: &str, factor: usize) -> String {
    use serde_yaml_ng::Value;
    let mut v: Value = serde_yaml_ng::from_str(&case1.replace("{id}", "dense")).unwrap();
    let vector = |p: &Value| -> Vec<f64> {
        p.as_sequence()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    for key in ["points", "axes"] {
        let given: Vec<Vec<f64>> = v[key].as_sequence().unwrap().iter().map(vector).collect();
        let mut out: Vec<Vec<f64>> = Vec::new();
        for w in given.windows(2) {
            for k in 0..factor {
                let t = k as f64 / factor as f64;
                out.push(
                    w[0].iter()
                        .zip(&w[1])
                        .map(|(a, b)| a + t * (b - a))
                        .collect(),
                );
            }
        }
        out.push(given.last().unwrap().clone());
        v[key] = serde_yaml_ng::to_value(out).unwrap();
    }
    let rto: Vec<u64> = v["options"]["rto_indices"]
        .as_sequence()
        .unwrap()
        .iter()
        .map(|i| i.as_u64().unwrap() * factor as u64)
        .collect();
    v["options"]["rto_indices"] = serde_yaml_ng::to_value(rto).unwrap();
    v["request_id"] = Value::String("{id}".into());
    serde_yaml_ng::to_string(&v).unwrap()
}

#[test]
fn the_cut_planner_answers_every_class_of_the_probe() {
    let case1 = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/mjto/cases/case1.yaml"
    ))
    .unwrap()
    .replace("request_id: bpillar-case1-side-trim", "request_id: {id}");
    run_probe(&Probe {
        name: "cut",
        planner: mjto(),
        domain: 171,
        numbers_base: yaml::<msg::CutRequest>(CUT_NUMBERS),
        valid_text: case1.clone(),
        with_file: |id, file| msg::CutRequest {
            mesh: file.into(),
            ..with_id(&yaml::<msg::CutRequest>(CUT_NUMBERS), id)
        },
        file_ext: ".stl",
        heavy: vec![dense(&case1, 20)],
        status: Statuses {
            success: CutPlan::SUCCESS,
            invalid: CutPlan::INVALID_REQUEST,
            queue_full: CutPlan::QUEUE_FULL,
            internal: CutPlan::INTERNAL_ERROR,
        },
    });
}

/// The milling planner's numbers base: every group given.
const MILL_NUMBERS: &str = "
request_id: numbers
points: [{x: 1.4, y: -0.3, z: 1.7}, {x: 2.1, y: 0.3, z: 1.7}]
segments: 10
has_process: true
teeth: 2
tool_radius: 0.04
axial_depth: 0.003
kt: 6.44e8
kn: 2.37e8
entry_angle: 2.356194490192345
exit_angle: 3.141592653589793
has_limits: true
spindle_min_rpm: 2000.0
spindle_max_rpm: 4000.0
feed_min: 0.0
feed_max: 0.06
g_min: -3.0
g_max: 3.0
max_spindle_step_rpm: 20.0
max_feed_step: 0.001
max_g_step: 0.2
has_initial_state: true
initial_spindle_rpm: 2000.0
initial_feed: 0.04
initial_g: 0.0
planner: naive
time_budget: 4.0
has_tolerances: true
path_tolerance: 0.00005
min_condition_indicator: 0.01
";

/// A milling text request on the seed 004 path (the default cell's) with `planner` and
/// `segments`.
fn mill_text(planner: &str, segments: usize) -> String {
    let points: Vec<String> = kerf_millplan::MillRequest::default()
        .points
        .iter()
        .map(|p| format!("[{:?}, {:?}, {:?}]", p[0], p[1], p[2]))
        .collect();
    format!(
        "request_id: {{id}}\nplanner: {planner}\nsegments: {segments}\npoints: [{}]\n",
        points.join(", ")
    )
}

/// A milling path of `n` points along a line over the default cell's table.
fn mill_line(n: usize) -> String {
    let points: Vec<String> = (0..n)
        .map(|k| format!("[{:.5}, -0.3, 1.7]", 1.4 + 0.6 * k as f64 / n as f64))
        .collect();
    format!(
        "request_id: {{id}}\nplanner: naive\npoints: [{}]\n",
        points.join(", ")
    )
}

#[test]
fn the_milling_planner_answers_every_class_of_the_probe() {
    run_probe(&Probe {
        name: "mill",
        planner: mill(),
        domain: 172,
        numbers_base: yaml::<msg::MillRequest>(MILL_NUMBERS),
        valid_text: mill_text("naive", 100),
        with_file: |id, file| msg::MillRequest {
            planner: "ddpg".into(),
            policy_file: file.into(),
            ..with_id(&yaml::<msg::MillRequest>(MILL_NUMBERS), id)
        },
        file_ext: ".safetensors",
        heavy: vec![mill_line(20_000), mill_text("dp", 2_000)],
        status: Statuses {
            success: MillPlan::SUCCESS,
            invalid: MillPlan::INVALID_REQUEST,
            queue_full: MillPlan::QUEUE_FULL,
            internal: MillPlan::INTERNAL_ERROR,
        },
    });
}

/// The G-code planner's numbers base (laser cutter): every group given.
const GCODE_NUMBERS: &str = "
request_id: numbers
machine: laser-cutter
program: \"G21 G90\\nG1 X10 F600\\nG1 Y10\\n\"
tolerance: 0.0001
has_limits: true
max_feed: 0.16
tangential_acceleration: 8.0
tangential_jerk: 80.0
normal_acceleration: 8.0
normal_jerk: 80.0
chord_error: 0.00001
contour_error: 0.00005
rapid_feed: 0.1
has_placement: true
origin: {x: 0.3, y: 0.3, z: 0.5}
redundancy_angle: 0.0
standoff_axis: -0.08
time_budget: 4.0
";

/// A G-code text request for `program` (YAML-quoted).
fn gcode_text(program: &str) -> String {
    format!("request_id: {{id}}\nprogram: {program:?}\n")
}

#[test]
fn the_gcode_planner_answers_every_class_of_the_probe() {
    // The probe's heavy programs: the 60-byte helix, 10^5 full circles, a 10^5-line zig-zag,
    // 1 500 corners smoothed by NURBS.
    let helix = gcode_text("G21 G17\nG1 X10 Y0 F3000\nG2 X10 Y0 Z-5 I-10 J0 P10000\n");
    let mut circles = String::from("G21 G17\nG1 X10 Y0 F3000\n");
    for _ in 0..100_000 {
        circles.push_str("G2 X10 Y0 I-10 J0\n");
    }
    let mut zigzag = String::from("G21\nG1 F3000\n");
    for k in 0..100_000 {
        zigzag.push_str(&format!("G1 X{} Y{}\n", k % 2 * 20, k % 1000));
    }
    let mut corners = String::from("G21\nG1 F3000\n");
    for k in 0..1500 {
        corners.push_str(&format!("G1 X{} Y{}\n", (k % 2) * 10, (k / 2) % 100));
    }
    let nurbs = format!("request_id: {{id}}\nmethod: nurbs\nprogram: {corners:?}\n");
    run_probe(&Probe {
        name: "gcode",
        planner: gcode(),
        domain: 173,
        numbers_base: yaml::<msg::GcodeRequest>(GCODE_NUMBERS),
        valid_text: gcode_text("G21 G90 G17\nM3\nG1 X20 Y0 F3000\nG1 X20 Y15\nG3 X15 Y20 R5\nG1 X0 Y20\nG1 X0 Y0\nM5\nM30\n"),
        with_file: |id, file| msg::GcodeRequest {
            program: String::new(),
            program_uri: file.into(),
            ..with_id(&yaml::<msg::GcodeRequest>(GCODE_NUMBERS), id)
        },
        file_ext: ".ngc",
        heavy: vec![
            helix,
            gcode_text(&circles),
            gcode_text(&zigzag),
            nurbs,
        ],
        status: Statuses {
            success: GcodePlan::SUCCESS,
            invalid: GcodePlan::INVALID_REQUEST,
            queue_full: GcodePlan::QUEUE_FULL,
            internal: GcodePlan::INTERNAL_ERROR,
        },
    });
}
