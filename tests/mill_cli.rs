//! `kerf train mill` and `kerf plan mill` as a user runs them (issue 5 sections 2 and 4).
//!
//! * A tiny policy is trained in the test (3 episodes × 10 steps, batch 16, g fixed): the
//!   saved file loads with the environment's sizes, the sidecar JSON holds the settings and the
//!   command, the CSV and JSON histories have one row per episode with the same rewards, the
//!   same seed gives the same weights byte for byte — equal to `kerf_millplan::train` called
//!   with the same settings —, the greedy summary is the library's directly evaluated greedy
//!   plan, and the training curve SVG has its series.
//! * `kerf plan mill` with that policy (fixed_g) and with the naive planner: the printed totals,
//!   a table row and the `--out` JSON equal the library's `MillPlanner` answer to the same
//!   request; the SVG has the six panels of seed 004 Fig. 6 and the |μ| = 1 line; several
//!   planners with one failing print the comparison table and the failure, and exit 2.
//! * Bad inputs exit with code 2 and a message naming the problem.
//!
//! Needs the committed indicator cache to fit the cell (naive refuses to plan otherwise).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    path::{Path, PathBuf},
    process::{Command, Output},
};

use std::sync::Arc;

use kerf_mill::MillCell;
use kerf_millplan::{
    plan::{IndicatorSource, Plan},
    train, DdpgSettings, EnvConfig, IndicatorCache, MillEnv, MillPlanner, MillRequest, Policy,
};

fn kerf(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kerf"))
        .args(args)
        .output()
        .expect("run kerf")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kerf_mill_cli_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Trains the test's tiny fixed-g policy into `dir` (seed `seed`).
fn train_tiny(dir: &Path, name: &str, seed: &str, history: &str) -> Output {
    kerf(&[
        "train",
        "mill",
        "--episodes",
        "3",
        "--steps",
        "10",
        "--batch-size",
        "16",
        "--fixed-g",
        "--seed",
        seed,
        "--out",
        s(&dir.join(format!("{name}.safetensors"))),
        "--history",
        s(&dir.join(history)),
        "--plots",
        s(&dir.join("plots")),
    ])
}

/// The number after `key` in `line` (up to the next space or comma).
fn number_after(line: &str, key: &str) -> f64 {
    let start = line
        .find(key)
        .unwrap_or_else(|| panic!("{key:?} in {line}"))
        + key.len();
    line[start..]
        .split([' ', ','])
        .next()
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("number after {key:?} in {line}"))
}

/// The totals of the `n`-th totals line of a `kerf plan mill` output.
fn totals(stdout: &str, n: usize) -> [f64; 4] {
    totals_of(stdout, "totals:", n)
}

/// The printed totals (time, max |μ|max, min 1/K, reward) are `plan`'s to the printed
/// precision (5.1e-7).
fn assert_totals(printed: [f64; 4], plan: &kerf_millplan::Plan, what: &str) {
    let expected = [
        plan.total_time,
        plan.max_spectral_radius,
        plan.min_condition_indicator,
        plan.total_reward,
    ];
    for (p, e) in printed.iter().zip(expected) {
        assert!((p - e).abs() <= 5.1e-7, "printed {p}, {what} {e}");
    }
}

/// The totals of the `n`-th line starting with `start` of a `kerf plan mill` output.
fn totals_of(stdout: &str, start: &str, n: usize) -> [f64; 4] {
    let line = stdout
        .lines()
        .filter(|l| l.trim_start().starts_with(start))
        .nth(n)
        .unwrap_or_else(|| panic!("{start:?} line {n} in {stdout}"));
    [
        number_after(line, "machining time "),
        number_after(line, "max |μ|max "),
        number_after(line, "min 1/K "),
        number_after(line, "total reward "),
    ]
}

fn write_request(dir: &Path, name: &str, body: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, body).expect("request file");
    path
}

const POINTS: &str =
    "points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.7], [1.8, 0.1, 1.7], [2.1, 0.3, 1.7]]\n";

#[test]
fn trains_a_policy_and_plans_with_it_as_the_library_does() {
    let dir = temp_dir("train_plan");

    // --- Training: files, sizes, settings, history, determinism, curve.
    let out = train_tiny(&dir, "p", "3", "h.csv");
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    for k in 1..=3 {
        assert!(
            stderr.contains(&format!("episode {k}/3: reward")),
            "{stderr}"
        );
    }
    assert!(stderr.contains("left"), "{stderr}");
    assert!(stdout.contains("greedy rollout"), "{stdout}");
    let weights = dir.join("p.safetensors");
    let policy = Policy::load(&weights).expect("the saved policy loads");
    assert_eq!(policy.observation_dim(), 37);
    assert_eq!(policy.action_dim(), 2, "fixed g: action (dΩ, df)");
    let meta = policy.metadata();
    assert_eq!(meta.hidden_sizes, vec![256, 256]);
    assert_eq!(meta.episodes, 3);
    assert_eq!(meta.seed, 3);
    assert_eq!(meta.settings.steps_per_episode, 10);
    assert_eq!(meta.settings.batch_size, 16);
    assert_eq!(meta.settings.actor_learning_rate, 1e-4);
    assert!(
        meta.environment.contains("fixed_g: true"),
        "{}",
        meta.environment
    );
    assert!(
        meta.environment.contains("--episodes 3 --steps 10"),
        "{}",
        meta.environment
    );
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("p.json")).expect("sidecar"))
            .expect("sidecar JSON");
    assert_eq!(sidecar["settings"]["episodes"], 3);
    assert_eq!(sidecar["settings"]["discount"], 0.99);

    let csv = std::fs::read_to_string(dir.join("h.csv")).expect("history");
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 3, "{csv}");
    let rewards: Vec<f64> = rows.iter().map(|r| r[3].parse().expect("reward")).collect();
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[0], (k + 1).to_string());
        assert_eq!(r[2], "10", "steps per episode");
        let mean = rewards[..=k].iter().sum::<f64>() / (k + 1) as f64;
        let avg: f64 = r[4].parse().expect("moving average");
        assert!(
            (avg - mean).abs() < 1e-12 * mean.abs().max(1.0),
            "{avg} vs {mean}"
        );
    }
    assert!(
        rewards.iter().all(|r| r.is_finite() && *r < 0.0),
        "{rewards:?}"
    );
    assert!(
        (meta.final_reward.expect("final reward") - rewards[2]).abs() < 1e-12,
        "sidecar final reward = last history reward"
    );

    // Same seed, JSON history: the same weights byte for byte and the same rewards.
    let again = train_tiny(&dir, "q", "3", "h.json");
    assert!(again.status.success(), "{}", text(&again).1);
    assert_eq!(
        std::fs::read(&weights).expect("p"),
        std::fs::read(dir.join("q.safetensors")).expect("q"),
        "training is deterministic for a seed"
    );
    let json: Vec<kerf_millplan::EpisodeReport> =
        serde_json::from_str(&std::fs::read_to_string(dir.join("h.json")).expect("json"))
            .expect("JSON history");
    assert_eq!(json.len(), 3);
    for (r, x) in json.iter().zip(&rewards) {
        assert_eq!(r.total_reward, *x);
    }

    // The library trained the same way gives the same weights, and the CLI's greedy summary
    // is the library's directly evaluated greedy plan.
    let cell = Arc::new(MillCell::default_cell().expect("cell"));
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).expect("cache");
    let config = EnvConfig {
        fixed_g: true,
        ..EnvConfig::default()
    };
    let mut env = MillEnv::new(cell.clone(), Some(Arc::new(cache)), config).expect("env");
    let settings = DdpgSettings::default()
        .with_episodes(3)
        .with_steps_per_episode(10)
        .with_batch_size(16)
        .with_seed(3);
    let agent = train(&mut env, &settings, &mut |_| {}).expect("library training");
    let mut lib_policy = Policy::from_agent(&agent, "test").expect("policy");
    lib_policy
        .save(&dir.join("lib.safetensors"))
        .expect("save library policy");
    assert_eq!(
        std::fs::read(&weights).expect("p"),
        std::fs::read(dir.join("lib.safetensors")).expect("lib"),
        "the CLI trains exactly as kerf_millplan::train with the same settings"
    );
    let rollout = env
        .rollout(|obs, _| lib_policy.act(obs))
        .expect("greedy rollout");
    let summary = stdout
        .lines()
        .find(|l| l.starts_with("greedy rollout"))
        .expect("summary line");
    if rollout.completed {
        let greedy = Plan::evaluate(&cell, &config.weights, &rollout.states(), "fixed_g")
            .expect("direct evaluation");
        for (key, v) in [
            ("machining time ", greedy.total_time),
            ("max |μ|max ", greedy.max_spectral_radius),
            ("min 1/K ", greedy.min_condition_indicator),
            ("total reward ", greedy.total_reward),
        ] {
            let printed = number_after(summary, key);
            assert!((printed - v).abs() <= 5.1e-5, "{key}: {printed} vs {v}");
        }
    } else {
        assert!(summary.contains("left the feasible set"), "{summary}");
    }

    let curve = std::fs::read_to_string(dir.join("plots/training_curve.svg")).expect("curve");
    assert!(curve.trim_start().starts_with("<svg") && curve.trim_end().ends_with("</svg>"));
    for label in [
        "episode reward",
        "moving average (50 episodes)",
        "mean actor loss",
        "episode",
    ] {
        assert!(curve.contains(label), "training curve lacks {label:?}");
    }

    // The same curve from the saved JSON history, without training.
    let out = kerf(&[
        "train",
        "curve",
        "--history",
        s(&dir.join("h.json")),
        "--plots",
        s(&dir.join("curve")),
        "--window",
        "2",
    ]);
    assert!(out.status.success(), "{}", text(&out).1);
    let curve = std::fs::read_to_string(dir.join("curve/training_curve.svg")).expect("curve");
    for label in [
        "episode reward",
        "moving average (2 episodes)",
        "h.json (3 episodes)",
    ] {
        assert!(curve.contains(label), "history curve lacks {label:?}");
    }

    // --- Planning with it (fixed_g), against the library.
    let request_path = write_request(
        &dir,
        "fixed.yaml",
        &format!(
            "request_id: cli-test\n{POINTS}planner: fixed_g\npolicy_file: {}\nallow_chatter: true\n",
            s(&weights)
        ),
    );
    let plots = dir.join("plan_plots");
    let out_json = dir.join("plan.json");
    let out = kerf(&[
        "plan",
        "mill",
        "--request",
        s(&request_path),
        "--plots",
        s(&plots),
        "--out",
        s(&out_json),
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let planner = MillPlanner::with_default_cell().expect("planner");
    let request = MillRequest::from_file(&request_path).expect("request");
    let lib_out = planner.plan(&request).expect("library plan");
    let lib = &lib_out.plan;
    assert_eq!(lib.segments.len(), 100);
    assert_totals(totals(&stdout, 0), lib, "library");
    // The same totals as executed (time-scaled to the joint limits, from rest to rest).
    let executed = &lib_out.executed.plan;
    assert_totals(
        totals_of(&stdout, "as executed", 0),
        executed,
        "library as executed",
    );
    assert!(executed.total_time > lib.total_time, "at least the ramps");
    assert!(
        stdout.contains(&format!(
            "{} of 100 segments slowed",
            lib_out.executed.scaling.slowed_segments()
        )),
        "{stdout}"
    );
    assert!(stdout.contains(&format!(
        "chatter-free {}",
        if lib.chatter_free { "yes" } else { "no" }
    )));
    // Every 10th segment and the last: 11 rows; row 50 equals the library's segment 50.
    let table: Vec<Vec<f64>> = stdout
        .lines()
        .filter_map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect();
            (v.len() == 8).then_some(v)
        })
        .collect();
    assert_eq!(
        table.iter().map(|r| r[0] as usize).collect::<Vec<_>>(),
        vec![0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 99],
        "{stdout}"
    );
    let row = &table[5];
    let seg = &lib.segments[50];
    for (v, e, tol) in [
        (row[1], seg.rpm, 0.0051),
        (row[2], seg.feed, 5.1e-6),
        (row[3], seg.g, 5.1e-5),
        (row[4], seg.spectral_radius, 5.1e-5),
        (row[5], seg.condition_indicator, 5.1e-5),
        (row[6], seg.time, 5.1e-5),
        (row[7], seg.reward.total, 5.1e-5),
    ] {
        assert!((v - e).abs() <= tol, "row 50: printed {v}, library {e}");
    }
    // The --out JSON holds the library's numbers exactly.
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out_json).expect("plan.json"))
            .expect("JSON");
    let p0 = &doc["plans"][0];
    assert_eq!(doc["request_id"], "cli-test");
    assert_eq!(p0["planner"], "fixed_g");
    assert_eq!(
        p0["totals"]["machining_time_s"].as_f64(),
        Some(lib.total_time)
    );
    assert_eq!(
        p0["totals"]["total_reward"].as_f64(),
        Some(lib.total_reward)
    );
    assert_eq!(p0["segments"].as_array().map(Vec::len), Some(100));
    assert_eq!(
        p0["segments"][37]["feed_m_per_s"].as_f64(),
        Some(lib.segments[37].feed)
    );
    // The trajectory the robot runs (executed), and the planned one under its own key.
    let f = |v: &serde_json::Value| v.as_f64().expect("number");
    for (key, t) in [
        ("trajectory", &lib_out.executed.scaling.trajectory),
        ("planned_trajectory", &lib_out.trajectory),
    ] {
        let points = p0[key]["points"].as_array().expect(key);
        assert_eq!(points.len(), t.points().len(), "{key}");
        for (a, b) in points.iter().zip(t.points()) {
            assert_eq!(f(&a["time_from_start_s"]), b.time_from_start, "{key}");
            assert_eq!(f(&a["velocities_rad_per_s"][4]), b.velocities[4], "{key}");
            assert_eq!(f(&a["positions_rad"][0]), b.positions[0], "{key}");
        }
    }
    let run = p0["trajectory"]["points"].as_array().expect("trajectory");
    assert_eq!(
        run.last().map(|p| f(&p["time_from_start_s"])),
        Some(lib_out.executed.scaling.duration())
    );
    // The machining time is the time in the material; the trajectory adds its run-in and
    // run-out (issue 28).
    assert!(
        (f(&p0["executed"]["totals"]["machining_time_s"]) - lib_out.executed.plan.total_time).abs()
            <= 1e-9
    );
    assert_eq!(
        f(&p0["executed"]["time_scaling"]["duration_s"]),
        lib_out.executed.scaling.duration()
    );
    assert_eq!(
        p0["executed"]["chatter_judge"]["samples"].as_u64(),
        Some(lib_out.executed.chatter.samples as u64)
    );
    for k in [0, run.len() - 1] {
        assert!(run[k]["velocities_rad_per_s"]
            .as_array()
            .expect("velocities")
            .iter()
            .all(|v| f(v) == 0.0));
    }
    assert_eq!(
        p0["executed"]["totals"]["max_spectral_radius"].as_f64(),
        Some(executed.max_spectral_radius)
    );
    assert_eq!(
        p0["executed"]["segments"][37]["feed_m_per_s"].as_f64(),
        Some(executed.segments[37].feed)
    );
    assert_eq!(
        p0["executed"]["time_scaling"]["slowed_segments"].as_u64(),
        Some(lib_out.executed.scaling.slowed_segments() as u64)
    );
    let svg = std::fs::read_to_string(plots.join("mill_plan_fixed_g.svg")).expect("plan svg");
    for label in [
        "(a) step reward",
        "(b) chatter indicator",
        "(c) condition indicator",
        "(d) spindle speed",
        "(e) feed",
        "(f) redundancy angle",
        "stability limit |mu|max = 1",
        "Omega [rpm]",
        "fixed_g",
    ] {
        assert!(svg.contains(label), "plan plot lacks {label:?}");
    }

    // --- Several planners, one failing: the others still run, the table compares them.
    let missing = dir.join("missing.safetensors");
    let out = kerf(&[
        "plan",
        "mill",
        "--request",
        s(&request_path),
        "--planners",
        "fixed_g,ddpg,naive",
        "--ddpg-policy",
        s(&missing),
        "--plots",
        s(&plots),
    ]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("1 of 3 planners failed: ddpg (POLICY_ERROR)"),
        "{stderr}"
    );
    assert!(
        stdout.contains("ddpg: failed: POLICY_ERROR (3)")
            && stdout.contains("weights file not found"),
        "{stdout}"
    );
    assert!(
        stdout.contains("comparison (2 of 3 planners planned):"),
        "{stdout}"
    );
    let mut naive_request = request.clone();
    naive_request.planner = "naive".to_string();
    naive_request.policy_file = None;
    let naive_out = planner.plan(&naive_request).expect("library naive");
    let naive = &naive_out.plan;
    let printed = totals(&stdout, 1);
    assert!((printed[0] - naive.total_time).abs() <= 5.1e-7, "{stdout}");
    assert!(
        (printed[3] - naive.total_reward).abs() <= 5.1e-7,
        "{stdout}"
    );
    // Both Markdown rows, with the library's formatting, as planned and (second table) as
    // executed.
    let (planned_table, executed_table) = stdout
        .split_once(
            "as executed (time-scaled to the joint limits; machining time in the material):\n",
        )
        .unwrap_or_else(|| panic!("no executed comparison table in {stdout}"));
    for (table, plans) in [
        (planned_table, [lib, naive]),
        (
            executed_table,
            [&lib_out.executed.plan, &naive_out.executed.plan],
        ),
    ] {
        for p in plans {
            let row = kerf_millplan::comparison_table(&[p.row()]);
            let row = row.lines().nth(2).expect("row");
            assert!(table.contains(row), "{row} in {table}");
        }
    }
    // The trajectories' durations, each planner's on its own line.
    for out in [&lib_out, &naive_out] {
        let line = format!(
            "{}: {:.3} s, ",
            out.planner.name(),
            out.executed.scaling.duration()
        );
        assert!(stdout.contains(&line), "{line} in {stdout}");
    }
    let cmp = std::fs::read_to_string(plots.join("mill_plan_comparison.svg")).expect("overlay");
    assert!(
        cmp.contains("fixed_g") && cmp.contains("naive"),
        "overlay legend"
    );
    assert!(!plots.join("mill_plan_ddpg.svg").exists());

    // --- --indicator cache: the library's cached evaluation, and the note says so.
    let naive_path = write_request(&dir, "naive.yaml", &format!("{POINTS}planner: naive\n"));
    let out = kerf(&[
        "plan",
        "mill",
        "--request",
        s(&naive_path),
        "--indicator",
        "cache",
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let cached = MillPlanner::with_default_cell()
        .expect("planner")
        .with_indicator_source(IndicatorSource::Cache)
        .plan(&MillRequest::from_file(&naive_path).expect("request"))
        .expect("library cached plan");
    assert!(!cached.indicator.cached_segments.is_empty());
    assert!(stdout.contains(&cached.indicator.note), "{stdout}");
    let printed = totals(&stdout, 0);
    assert!(
        (printed[1] - cached.plan.max_spectral_radius).abs() <= 5.1e-7,
        "{stdout}"
    );
    let printed = totals_of(&stdout, "as executed", 0);
    assert!(
        (printed[1] - cached.executed.plan.max_spectral_radius).abs() <= 5.1e-7,
        "{stdout}"
    );
    assert!(!cached.executed.cached_segments.is_empty());
    assert!(
        stdout.contains(&format!(
            "|μ|max of {} segments from the indicator cache",
            cached.executed.cached_segments.len()
        )),
        "{stdout}"
    );

    // --- The fixed-g policy is refused by ddpg (3 actions): incompatible policy file.
    let out = kerf(&[
        "plan",
        "mill",
        "--request",
        s(&request_path),
        "--planners",
        "ddpg",
        "--ddpg-policy",
        s(&weights),
    ]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("POLICY_ERROR (3)") && stderr.contains("actions of 2 entries"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_inputs_exit_2_with_a_message() {
    let dir = temp_dir("bad");
    let req = |name: &str, body: &str| write_request(&dir, name, body);
    let non_planar = req(
        "non_planar.yaml",
        "points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.75], [1.8, 0.1, 1.7], [2.1, 0.3, 1.6]]\nplanner: naive\n",
    );
    let unreachable = req(
        "far.yaml",
        "points: [[4.4, -0.3, 1.7], [4.6, -0.1, 1.7], [4.8, 0.1, 1.7]]\nplanner: naive\n",
    );
    let nan = req(
        "nan.yaml",
        "points: [[1.4, -0.3, 1.7], [1.6, -0.1, .nan]]\n",
    );
    let min_max = req(
        "minmax.yaml",
        &format!("{POINTS}limits: {{feed: [0.06, 0.01]}}\nplanner: naive\n"),
    );
    let unknown = req("unknown.yaml", &format!("{POINTS}colour: red\n"));
    let broken = req(
        "broken.yaml",
        "points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.7]\n",
    );
    let one = req("one.yaml", "points: [[1.4, -0.3, 1.7]]\n");
    let no_policy = req(
        "nopolicy.yaml",
        &format!(
            "{POINTS}planner: ddpg\npolicy_file: {}\n",
            s(&dir.join("absent.safetensors"))
        ),
    );
    let good = req("good.yaml", &format!("{POINTS}planner: naive\n"));
    let missing = dir.join("missing.yaml");
    let nan_history = req(
        "nan.csv",
        "episode,episodes,steps,total_reward,mean_critic_loss,mean_actor_loss,noise_std,\
         elapsed_s,remaining_s\n1,2,10,-3.5,,,0.1,1,1\n2,2,10,NaN,0.2,0.3,0.1,2,0\n",
    );
    fn plan(r: &Path) -> Vec<&str> {
        vec!["plan", "mill", "--request", s(r)]
    }
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (plan(&missing), &["cannot read", "missing.yaml"]),
        (plan(&non_planar), &["INVALID_REQUEST (1)", "not coplanar"]),
        (plan(&unreachable), &["UNREACHABLE (2)", "beyond the reach"]),
        (
            plan(&nan),
            &["INVALID_REQUEST (1)", "points[1][2]", "must be finite"],
        ),
        (
            plan(&min_max),
            &["INVALID_REQUEST (1)", "limits.feed", "min > max"],
        ),
        (
            plan(&unknown),
            &["INVALID_REQUEST (1)", "unknown field `colour`"],
        ),
        (plan(&broken), &["INVALID_REQUEST (1)", "line 2"]),
        (plan(&one), &["a path needs at least 2 points"]),
        (
            plan(&no_policy),
            &["POLICY_ERROR (3)", "weights file not found"],
        ),
        (
            [plan(&good), vec!["--planners", "naive,foo"]].concat(),
            &["--planners", "unknown planner `foo`"],
        ),
        (
            [plan(&good), vec!["--out", "plan.txt"]].concat(),
            &["--out plan.txt", "must end in .json, .yaml or .yml"],
        ),
        (
            vec![
                "train",
                "curve",
                "--history",
                s(&nan_history),
                "--plots",
                "c",
            ],
            &["episode 2: total_reward is NaN, must be finite"],
        ),
        (
            vec!["train", "mill", "--out", "p.json"],
            &["must not end in .json"],
        ),
        (
            vec!["train", "mill", "--out", "/dev/null/x/p.safetensors"],
            &["--out /dev/null/x/p.safetensors: cannot write"],
        ),
        (
            vec!["train", "mill", "--out", "q.safetensors", "--episodes", "0"],
            &[
                "invalid value '0' for '--episodes <EPISODES>'",
                "allowed: [1, 1000000]",
            ],
        ),
        (
            vec![
                "train",
                "mill",
                "--out",
                "q.safetensors",
                "--actor-lr",
                "NaN",
            ],
            &[
                "invalid value 'NaN' for '--actor-lr <ACTOR_LR>'",
                "must be finite",
            ],
        ),
        (
            vec!["train", "mill", "--out", "q.safetensors", "--alpha", "1.5"],
            &[
                "invalid value '1.5' for '--alpha <ALPHA>'",
                "allowed: (0, 1]",
            ],
        ),
        (
            vec![
                "train",
                "mill",
                "--out",
                "q.safetensors",
                "--cache",
                s(&good),
            ],
            &["--cache", "not a cache file"],
        ),
    ];
    for (args, needles) in cases {
        let out = Command::new(env!("CARGO_BIN_EXE_kerf"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .expect("run kerf");
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stdout}\n{stderr}");
        for n in needles {
            assert!(stderr.contains(n), "{args:?}: {n:?} not in {stderr}");
        }
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    // Refused before training: no policy file was left behind.
    assert!(!dir.join("q.safetensors").exists());
    assert!(!dir.join("q.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
