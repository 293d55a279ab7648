//! Policy files (kerf_millplan::policy): save/load round trip, the plain
//! forward pass against candle's, and every way a file can be bad.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::{Path, PathBuf};

use kerf_millplan::ddpg::DdpgSettings;
use kerf_millplan::nets::{matrix, Mlp, OutputActivation};
use kerf_millplan::policy::{metadata_path, Policy, PolicyMetadata, POLICY_FORMAT};
use kerf_millplan::rng::Rng;
use kerf_millplan::{train, Environment, MillPlanError, Transition};

/// A fresh temporary directory for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "kerf_millplan_policy_{name}_{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The metadata of a 2×256 actor for 4 observations and 3 actions (the
/// milling environment's sizes).
fn metadata(observation_dim: usize, action_dim: usize, hidden: Vec<usize>) -> PolicyMetadata {
    PolicyMetadata {
        format: POLICY_FORMAT.to_string(),
        crate_version: env!("CARGO_PKG_VERSION").to_string(),
        observation_dim,
        action_dim,
        hidden_sizes: hidden.clone(),
        seed: 17,
        settings: DdpgSettings::default()
            .with_hidden_sizes(hidden)
            .with_seed(17),
        environment: "test actor".to_string(),
        episodes: 0,
        final_reward: None,
        observation_layout: Vec::new(),
    }
}

/// A randomly initialized actor with larger hidden weights than DDPG's
/// output init, so the outputs are far from 0 and the test is sensitive.
fn actor(observation_dim: usize, action_dim: usize, hidden: &[usize]) -> Mlp {
    let mut sizes = vec![observation_dim];
    sizes.extend_from_slice(hidden);
    sizes.push(action_dim);
    let mut rng = Rng::new(17);
    let net = Mlp::new(&sizes, OutputActivation::Tanh, &mut rng).expect("actor");
    // Scale the output layer up (×200) so that tanh is exercised beyond
    // its linear range.
    let mut params = net.parameters().expect("parameters");
    if let Some((w, b)) = params.last_mut() {
        w.iter_mut().for_each(|v| *v *= 200.0);
        b.iter_mut().for_each(|v| *v *= 200.0);
    }
    Mlp::from_parameters(&sizes, OutputActivation::Tanh, params).expect("actor")
}

fn observations(n: usize, dim: usize) -> Vec<Vec<f32>> {
    let mut rng = Rng::new(99);
    (0..n)
        .map(|_| (0..dim).map(|_| rng.uniform(-1.0, 1.0) as f32).collect())
        .collect()
}

fn saved_policy(dir: &Path) -> (Policy, PathBuf) {
    let net = actor(4, 3, &[256, 256]);
    let mut policy = Policy::from_actor(&net, metadata(4, 3, vec![256, 256])).expect("policy");
    let path = dir.join("actor.safetensors");
    policy.save(&path).expect("save");
    (policy, path)
}

/// Save → load gives the same metadata and bit-identical actions; the plain
/// forward pass agrees with candle's forward pass of the same network to
/// f32 rounding (a second, independent implementation).
#[test]
fn round_trip_identical_actions_and_candle_agreement() {
    let dir = temp_dir("round_trip");
    let net = actor(4, 3, &[256, 256]);
    let mut policy = Policy::from_actor(&net, metadata(4, 3, vec![256, 256])).expect("policy");
    let path = dir.join("actor.safetensors");
    policy.save(&path).expect("save");
    assert!(path.exists() && metadata_path(&path).exists());
    assert_eq!(metadata_path(&path), dir.join("actor.json"));
    let loaded = Policy::load(&path).expect("load");
    assert_eq!(loaded.metadata(), policy.metadata());
    let mut max_diff = 0f32;
    let mut saturated = 0usize;
    for obs in observations(50, 4) {
        let a = policy.act(&obs).expect("act");
        let b = loaded.act(&obs).expect("act");
        assert_eq!(
            a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            b.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(a.len(), 3);
        assert!(a.iter().all(|v| (-1.0..=1.0).contains(v)));
        saturated += a.iter().filter(|v| v.abs() > 0.5).count();
        let c = net
            .forward(&matrix(obs.clone(), 1, 4).expect("matrix"))
            .and_then(|t| {
                t.flatten_all()
                    .and_then(|t| t.to_vec1::<f32>())
                    .map_err(|e| MillPlanError::Backend(e.to_string()))
            })
            .expect("candle forward");
        for (x, y) in a.iter().zip(&c) {
            max_diff = max_diff.max((x - y).abs());
        }
    }
    println!(
        "plain vs candle forward: max |Δa| = {max_diff:e}; {saturated} of 150 entries |a| > 0.5"
    );
    assert!(
        max_diff < 1e-4,
        "plain and candle forward differ by {max_diff}"
    );
    assert!(saturated > 20, "outputs too close to 0 to test tanh");
    // The sidecar is readable JSON with the documented fields.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(metadata_path(&path)).expect("read"))
            .expect("json");
    assert_eq!(json["format"], POLICY_FORMAT);
    assert_eq!(json["observation_dim"], 4);
    assert_eq!(json["action_dim"], 3);
    assert_eq!(json["settings"]["actor_learning_rate"], 1e-4);
    assert_eq!(json["environment"], "test actor");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A 100-step rollout of the 2×256 actor is fast: measured and reported;
/// asserted with a generous bound (50 ms, the budget for a whole
/// plan) that holds in the dev profile on a loaded 2-core machine.
#[test]
fn hundred_actions_are_fast() {
    let net = actor(4, 3, &[256, 256]);
    let policy = Policy::from_actor(&net, metadata(4, 3, vec![256, 256])).expect("policy");
    let obs = observations(100, 4);
    let start = std::time::Instant::now();
    let mut checksum = 0f32;
    for o in &obs {
        checksum += policy.act(o).expect("act")[0];
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "100 actions (2×256): {:.3} ms (checksum {checksum})",
        elapsed * 1e3
    );
    assert!(elapsed < 0.05, "100 actions took {elapsed} s");
}

fn policy_reason(err: MillPlanError) -> String {
    match err {
        MillPlanError::Policy { reason, .. } => reason,
        other => panic!("expected a Policy error, got {other}"),
    }
}

#[test]
fn missing_files_are_policy_errors() {
    let dir = temp_dir("missing");
    let err = Policy::load(&dir.join("nothing.safetensors")).expect_err("missing");
    let text = err.to_string();
    assert!(text.contains("nothing.safetensors"), "{text}");
    assert!(policy_reason(err).contains("not found"));

    let (_, path) = saved_policy(&dir);
    std::fs::remove_file(metadata_path(&path)).expect("remove sidecar");
    let reason = policy_reason(Policy::load(&path).expect_err("no sidecar"));
    assert!(
        reason.contains("sidecar") && reason.contains("not found"),
        "{reason}"
    );

    // Giving the sidecar instead of the weights.
    let reason = policy_reason(Policy::load(&dir.join("actor.json")).expect_err("json"));
    assert!(reason.contains(".json"), "{reason}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn corrupted_files_are_policy_errors() {
    let dir = temp_dir("corrupt");
    let (_, path) = saved_policy(&dir);
    let good = std::fs::read(&path).expect("read");

    // Truncated weights.
    std::fs::write(&path, &good[..good.len() / 2]).expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("truncated"));
    assert!(reason.contains("not a valid safetensors file"), "{reason}");
    // Garbage.
    std::fs::write(&path, b"this is not a tensor file").expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("garbage"));
    assert!(reason.contains("not a valid safetensors file"), "{reason}");
    // Empty.
    std::fs::write(&path, b"").expect("write");
    assert!(Policy::load(&path).is_err());
    std::fs::write(&path, &good).expect("restore");
    assert!(Policy::load(&path).is_ok());

    // A NaN written into the data section (the last 4 bytes are the last
    // bias entry of the sorted layout or some weight: any f32).
    let mut nan = good.clone();
    let n = nan.len();
    nan[n - 4..].copy_from_slice(&f32::NAN.to_le_bytes());
    std::fs::write(&path, &nan).expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("NaN"));
    assert!(reason.contains("NaN"), "{reason}");
    std::fs::write(&path, &good).expect("restore");

    // Corrupt sidecar: not JSON, wrong format, missing field.
    let sidecar = metadata_path(&path);
    let json = std::fs::read_to_string(&sidecar).expect("read");
    std::fs::write(&sidecar, "{ not json").expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("bad json"));
    assert!(reason.contains("not valid"), "{reason}");
    std::fs::write(&sidecar, json.replace(POLICY_FORMAT, "something else v9")).expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("format"));
    assert!(reason.contains("something else v9"), "{reason}");
    std::fs::write(&sidecar, json.replace("\"seed\": 17,", "")).expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("missing field"));
    assert!(reason.contains("seed"), "{reason}");
    std::fs::write(&sidecar, &json).expect("restore");
    assert!(Policy::load(&path).is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Weights and sidecar that disagree: the sidecar claims other sizes, the
/// file has other tensors, or other dtypes.
#[test]
fn inconsistent_files_are_policy_errors() {
    let dir = temp_dir("inconsistent");
    let (_, path) = saved_policy(&dir);
    let sidecar = metadata_path(&path);
    let json = std::fs::read_to_string(&sidecar).expect("read");

    // Sidecar says 5 observations: l0.weight is 256×4, not 256×5.
    std::fs::write(
        &sidecar,
        json.replace("\"observation_dim\": 4", "\"observation_dim\": 5"),
    )
    .expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("obs size"));
    assert!(
        reason.contains("l0.weight") && reason.contains("[256, 4]") && reason.contains("[256, 5]"),
        "{reason}"
    );
    // Sidecar says one hidden layer (consistently in both places): extra
    // tensors l2.*.
    let mut meta: PolicyMetadata = serde_json::from_str(&json).expect("json");
    meta.hidden_sizes = vec![256];
    meta.settings.hidden_sizes = vec![256];
    std::fs::write(&sidecar, serde_json::to_string(&meta).expect("json")).expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("layers"));
    assert!(reason.contains("unexpected tensors"), "{reason}");
    // Hidden sizes disagreeing inside the sidecar.
    meta.settings.hidden_sizes = vec![256, 256];
    std::fs::write(&sidecar, serde_json::to_string(&meta).expect("json")).expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("hidden mismatch"));
    assert!(reason.contains("hidden sizes"), "{reason}");
    std::fs::write(&sidecar, &json).expect("restore");

    // Weights of a network with other sizes under the same sidecar.
    let other = actor(4, 2, &[256, 256]);
    let mut other_policy =
        Policy::from_actor(&other, metadata(4, 2, vec![256, 256])).expect("policy");
    let other_path = dir.join("other.safetensors");
    other_policy.save(&other_path).expect("save");
    std::fs::copy(&other_path, &path).expect("copy");
    let reason = policy_reason(Policy::load(&path).expect_err("act size"));
    assert!(
        reason.contains("l2.weight") && reason.contains("[2, 256]"),
        "{reason}"
    );

    // A missing tensor and an f64 tensor.
    let device = candle_core::Device::Cpu;
    let mut tensors = candle_core::safetensors::load(&other_path, &device).expect("load");
    tensors.remove("l1.bias");
    candle_core::safetensors::save(&tensors, &path).expect("save");
    std::fs::write(
        &sidecar,
        json.replace("\"action_dim\": 3", "\"action_dim\": 2"),
    )
    .expect("write");
    let reason = policy_reason(Policy::load(&path).expect_err("missing tensor"));
    assert!(reason.contains("l1.bias is missing"), "{reason}");
    let mut tensors = candle_core::safetensors::load(&other_path, &device).expect("load");
    let b = tensors["l1.bias"]
        .to_dtype(candle_core::DType::F64)
        .expect("f64");
    tensors.insert("l1.bias".to_string(), b);
    candle_core::safetensors::save(&tensors, &path).expect("save");
    let reason = policy_reason(Policy::load(&path).expect_err("dtype"));
    assert!(reason.contains("F64"), "{reason}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A policy for 4 observations and 3 actions meets an environment with
/// other sizes, and observations of the wrong length or with NaN.
#[test]
fn size_mismatch_with_the_environment() {
    let dir = temp_dir("sizes");
    let (policy, path) = saved_policy(&dir);
    assert!(policy.check_sizes(4, 3).is_ok());
    let reason = policy_reason(policy.check_sizes(4, 2).expect_err("actions"));
    assert!(
        reason.contains("actions of 3") && reason.contains("4 and 2"),
        "{reason}"
    );
    let reason = policy_reason(Policy::load_for(&path, 5, 3).expect_err("observations"));
    assert!(reason.contains("observations of 4"), "{reason}");
    assert!(Policy::load_for(&path, 4, 3).is_ok());
    let reason = policy_reason(policy.act(&[0.0; 5]).expect_err("length"));
    assert!(reason.contains("5 entries"), "{reason}");
    assert!(matches!(
        policy.act(&[0.0, f32::NAN, 0.0, 0.0]),
        Err(MillPlanError::InvalidParameter { .. })
    ));
    // Rollout checks the sizes before touching the environment.
    let mut env = Line { x: 0.0, resets: 0 };
    let reason = policy_reason(policy.rollout(&mut env).expect_err("rollout"));
    assert!(reason.contains("1 and 1"), "{reason}");
    assert_eq!(env.resets, 0);
    // A policy file path ending in .json is refused at save.
    let mut p = policy.clone();
    assert!(p.save(&dir.join("actor.json")).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

/// 1-D environment: x += 0.1 a, reward −x², 10 steps.
struct Line {
    x: f64,
    resets: usize,
}

impl Environment for Line {
    fn observation_dim(&self) -> usize {
        1
    }
    fn action_dim(&self) -> usize {
        1
    }
    fn max_steps(&self) -> usize {
        10
    }
    fn reset(&mut self) -> Result<Vec<f32>, MillPlanError> {
        self.resets += 1;
        self.x = 0.5;
        Ok(vec![0.5])
    }
    fn step(&mut self, action: &[f32]) -> Result<Transition, MillPlanError> {
        let a = action.first().copied().unwrap_or(0.0);
        self.x = (self.x + 0.1 * f64::from(a)).clamp(-1.0, 1.0);
        Ok(Transition {
            observation: vec![self.x as f32],
            reward: -self.x * self.x,
            done: false,
        })
    }
}

/// From a training run: the policy of the agent acts like the agent's own
/// candle actor, the sidecar records the run, and a saved-and-loaded policy
/// rolls out the same episode (same actions, same reward).
#[test]
fn trained_agent_round_trip() {
    let dir = temp_dir("trained");
    let settings = DdpgSettings::default()
        .with_episodes(8)
        .with_steps_per_episode(10)
        .with_hidden_sizes(vec![16, 16])
        .with_batch_size(16)
        .with_seed(5);
    let mut env = Line { x: 0.0, resets: 0 };
    let agent = train(&mut env, &settings, &mut |_| {}).expect("train");
    let mut policy = Policy::from_agent(&agent, "line, 10 steps").expect("policy");
    let meta = policy.metadata().clone();
    assert_eq!(meta.settings, settings);
    assert_eq!(meta.episodes, 8);
    assert_eq!(meta.seed, 5);
    assert_eq!(
        meta.final_reward,
        agent.history().last().map(|r| r.total_reward)
    );
    for obs in observations(20, 1) {
        let a = policy.act(&obs).expect("act");
        let b = agent.act(&obs).expect("agent act");
        assert!((a[0] - b[0]).abs() < 1e-5, "{a:?} vs {b:?}");
    }
    let path = dir.join("line.safetensors");
    policy.save(&path).expect("save");
    let loaded = Policy::load_for(&path, 1, 1).expect("load");
    let r1 = policy.rollout(&mut env).expect("rollout");
    let r2 = loaded.rollout(&mut env).expect("rollout");
    assert_eq!(r1, r2);
    assert_eq!(r1.actions.len(), 10);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 11, row 6: a FIFO named as a policy (or as its sidecar) is refused at once, never
/// opened; the planner does not hang.
#[test]
fn a_fifo_is_no_policy() {
    let dir = temp_dir("fifo");
    let weights = dir.join("pipe.safetensors");
    let make_fifo = |p: &Path| {
        let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path we own.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    };
    make_fifo(&weights);
    let (tx, rx) = std::sync::mpsc::channel();
    let w = weights.clone();
    std::thread::spawn(move || {
        let _ = tx.send(Policy::load(&w).map(|_| ()));
    });
    let e = rx
        .recv_timeout(std::time::Duration::from_secs(10))
        .expect("loading a FIFO as a policy hung")
        .unwrap_err();
    assert!(matches!(e, MillPlanError::Policy { .. }), "{e}");
    assert!(e.to_string().contains("FIFO"), "{e}");
    // A real weights file whose sidecar is a FIFO.
    let real = dir.join("real.safetensors");
    std::fs::write(&real, b"not read").unwrap();
    make_fifo(&metadata_path(&real));
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(Policy::load(&real).map(|_| ()));
    });
    let e = rx
        .recv_timeout(std::time::Duration::from_secs(10))
        .expect("loading a FIFO sidecar hung")
        .unwrap_err();
    assert!(e.to_string().contains("FIFO"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
