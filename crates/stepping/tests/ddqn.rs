//! The DDQN agent of seed 002: network files are validated, a save/load
//! round trip is exact, episodes start anywhere in RPRO's recorded run,
//! training on those replays learns more than "accelerate", the closed
//! loop's paper-style completion counts to the last point without a stop,
//! the committed weights run raw in closed loop and behind RPRO's shield,
//! the shield does not let an agent stall, and training is deterministic
//! for a seed.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use kerf_rng::Rng;
use kerf_stepping::{
    database::{self, Density},
    ddqn::{
        self, env, features,
        file::{self, NETWORK_FORMAT},
        metrics, Agent, Architecture, DdqnSettings, Shielded, Weights,
    },
    run, Action, Course, Decision, Lattice, RproSettings, State, StepError,
};
use safetensors::{tensor::TensorView, Dtype};

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kerf_stepping_ddqn_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn course(path: usize, limits: usize) -> Course {
    let lat = Lattice::new(database::limit_grid()[limits], database::PERIOD).unwrap();
    Course::new(
        lat,
        database::path(15, Density::High, path),
        database::PRECISION,
    )
    .unwrap()
}

/// A safetensors file with the given tensors (name, shape) of zeros and
/// metadata.
fn raw_file(path: &Path, tensors: &[(&str, Vec<usize>)], meta: &[(&str, &str)]) {
    let data: Vec<Vec<u8>> = tensors
        .iter()
        .map(|(_, s)| vec![0u8; 4 * s.iter().product::<usize>()])
        .collect();
    let views: Vec<(String, TensorView<'_>)> = tensors
        .iter()
        .zip(&data)
        .map(|((n, s), d)| {
            (
                n.to_string(),
                TensorView::new(Dtype::F32, s.clone(), d).unwrap(),
            )
        })
        .collect();
    let meta = meta
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    std::fs::write(path, safetensors::serialize(views, Some(meta)).unwrap()).unwrap();
}

fn arch2_tensors() -> Vec<(&'static str, Vec<usize>)> {
    vec![
        ("l0.weight", vec![24, 3]),
        ("l0.bias", vec![24]),
        ("l1.weight", vec![24, 24]),
        ("l1.bias", vec![24]),
        ("l2.weight", vec![3, 24]),
        ("l2.bias", vec![3]),
    ]
}

fn network_error(path: &Path) -> String {
    match Agent::load(path) {
        Err(StepError::Network { reason }) => reason,
        other => panic!(
            "{}: expected a network error, got {other:?}",
            path.display()
        ),
    }
}

#[test]
fn bad_network_files_are_refused_with_a_reason() {
    let meta = [("format", NETWORK_FORMAT), ("architecture", "2")];
    // The well-formed all-zero file loads: the refusals below are the
    // defects, not the fixture.
    let good = tmp("good.safetensors");
    raw_file(&good, &arch2_tensors(), &meta);
    assert!(Agent::load(&good).is_ok());

    // Wrong size: architecture 4's 20-wide layers under architecture 2.
    let wrong = tmp("wrong_size.safetensors");
    let mut t = arch2_tensors();
    t[2].1 = vec![20, 20];
    raw_file(&wrong, &t, &meta);
    assert!(network_error(&wrong).contains("shape"));

    // Missing tensor.
    let missing = tmp("missing.safetensors");
    let mut t = arch2_tensors();
    t.pop();
    raw_file(&missing, &t, &meta);
    assert!(network_error(&missing).contains("l2.bias"));

    // Extra tensor.
    let extra = tmp("extra.safetensors");
    let mut t = arch2_tensors();
    t.push(("l3.weight", vec![3, 3]));
    raw_file(&extra, &t, &meta);
    assert!(network_error(&extra).contains("l3.weight"));

    // Architecture outside Table 2, absent, or contradicting its width.
    let bad_arch = tmp("arch13.safetensors");
    raw_file(
        &bad_arch,
        &arch2_tensors(),
        &[("format", NETWORK_FORMAT), ("architecture", "13")],
    );
    assert!(network_error(&bad_arch).contains("architecture"));
    let no_arch = tmp("noarch.safetensors");
    raw_file(&no_arch, &arch2_tensors(), &[("format", NETWORK_FORMAT)]);
    assert!(network_error(&no_arch).contains("architecture"));
    let contradict = tmp("contradict.safetensors");
    raw_file(
        &contradict,
        &arch2_tensors(),
        &[
            ("format", NETWORK_FORMAT),
            ("architecture", "2"),
            ("activation", "relu"),
        ],
    );
    assert!(network_error(&contradict).contains("activation"));
    let other_format = tmp("format.safetensors");
    raw_file(&other_format, &arch2_tensors(), &[("architecture", "2")]);
    assert!(network_error(&other_format).contains("format"));

    // Truncated, empty, garbage, missing, a directory.
    let bytes = std::fs::read(&good).unwrap();
    for (name, data) in [
        ("truncated", bytes[..bytes.len() - 7].to_vec()),
        ("header_only", bytes[..12].to_vec()),
        ("empty", vec![]),
        ("garbage", b"not a network at all".to_vec()),
    ] {
        let p = tmp(&format!("{name}.safetensors"));
        std::fs::write(&p, data).unwrap();
        let reason = network_error(&p);
        assert!(reason.contains("not a valid safetensors file"), "{reason}");
    }
    network_error(&tmp("does_not_exist.safetensors"));
    network_error(&std::env::temp_dir());

    // A non-finite weight.
    let nan = tmp("nan.safetensors");
    let mut w = Weights::init(Architecture::new(2).unwrap(), &mut Rng::new(1));
    let agent = Agent::new(w.clone(), BTreeMap::new()).unwrap();
    agent.save(&nan).unwrap();
    let mut bytes = std::fs::read(&nan).unwrap();
    let n = bytes.len();
    bytes[n - 4..].copy_from_slice(&f32::NAN.to_le_bytes());
    std::fs::write(&nan, bytes).unwrap();
    assert!(network_error(&nan).contains("NaN"));
    // … and in memory.
    let mut layers = w.layers().to_vec();
    layers[1].bias[0] = f32::INFINITY;
    assert!(Weights::from_layers(w.architecture(), layers).is_err());
    w = Weights::init(Architecture::new(3).unwrap(), &mut Rng::new(1));
    assert_eq!(w.layers()[0].weight.len(), 20 * 3);
}

#[test]
fn save_and_load_give_identical_q_values() {
    for number in [1, 2, 11, 12] {
        let arch = Architecture::new(number).unwrap();
        let w = Weights::init(arch, &mut Rng::new(number as u64));
        let info: BTreeMap<String, String> = [("note".to_string(), format!("arch {number}"))]
            .into_iter()
            .collect();
        let agent = Agent::new(w, info.clone()).unwrap();
        let path = tmp(&format!("round_trip_{number}.safetensors"));
        agent.save(&path).unwrap();
        let back = Agent::load(&path).unwrap();
        assert_eq!(back, agent);
        assert_eq!(back.info(), &info);
        assert_eq!(back.architecture().hidden(), arch.hidden());
        let c = course(7, 20);
        let mut rng = Rng::new(5);
        for _ in 0..50 {
            let d = Decision {
                step: 0,
                state: State {
                    q: rng.below(40_000).unwrap() as i64,
                    n: 2 * rng.below(100).unwrap() as i64,
                    m: rng.below(9).unwrap() as i64 - 4,
                },
                target: rng.below(3).unwrap(),
                seen: false,
            };
            let (a, b) = (agent.q_values(&c, &d), back.q_values(&c, &d));
            assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits));
        }
    }
    // Reserved metadata keys are refused on save.
    let w = Weights::init(Architecture::default(), &mut Rng::new(0));
    let bad: BTreeMap<String, String> = [("architecture".to_string(), "7".to_string())]
        .into_iter()
        .collect();
    assert!(file::to_bytes(&w, &bad).is_err());
}

#[test]
fn features_are_normalized_by_the_limits_and_the_largest_gap() {
    let c = course(7, 30);
    let d = Decision {
        step: 0,
        state: State::REST,
        target: 0,
        seen: false,
    };
    let x = features(&c, &d);
    assert_eq!(x[0], 0.0);
    assert_eq!(x[1], 0.0);
    let gap = c.points[1] - c.points[0];
    assert!((f64::from(x[2]) - gap / c.max_gap).abs() < 1e-6);
    assert!(x[2] > 0.0 && x[2] <= 1.0);
    let lat = c.lattice;
    let s = State {
        q: 0,
        n: lat.max_n,
        m: lat.max_m,
    };
    let x = features(&c, &Decision { state: s, ..d });
    assert!(
        (x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 1e-3,
        "{x:?}"
    );
}

/// Held-out processes of the committed weights' subset (high density, 15
/// points): pair 0 trains on paths 0 and 1, these are test paths.
const HELD_OUT: [(usize, usize); 5] = [(7, 1), (7, 29), (7, 58), (9, 16), (9, 44)];

fn committed() -> Agent {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("weights/ddqn_high_arch2.safetensors");
    let agent = Agent::load(&path).unwrap();
    assert_eq!(agent.architecture().number(), 2);
    assert_eq!(
        agent.info().get("density").map(String::as_str),
        Some("high")
    );
    agent
}

/// The committed weights behind the shield (RPRO's viability check and the
/// progress rule) pass every point of held-out paths within the precision,
/// stop on the last one, and never reach the step cap.
#[test]
fn committed_weights_behind_the_shield_pass_every_point_of_held_out_paths() {
    let agent = committed();
    let (mut overrides, mut decisions) = (0, 0);
    for (p, limits) in HELD_OUT {
        let c = course(p, limits);
        let rpro = env::record(&c, RproSettings::default(), 1_000_000).unwrap();
        let mut shielded = Shielded::new(agent.clone(), &c, RproSettings::default()).unwrap();
        let r = run(&c, &mut shielded, metrics::step_cap(rpro.steps()))
            .unwrap_or_else(|e| panic!("path {p}, limits #{limits}: {e}"));
        assert_eq!(r.passes.len(), c.targets());
        assert!(r.max_error() <= database::PRECISION);
        assert_eq!(shielded.decisions(), r.steps());
        assert!(
            shielded.overrides() < r.steps(),
            "path {p}, limits #{limits}: every decision overridden"
        );
        overrides += shielded.overrides();
        decisions += shielded.decisions();
    }
    eprintln!("shielded: {overrides} overrides in {decisions} decisions");
}

/// The committed weights, raw, in the paper-style closed loop: RPRO itself
/// completes there both ways (the loop is sound), its paper-style steps are
/// its pass of the last point as [`run`] records it (like for like with
/// `metrics::baseline`), and the agent passes a measured share of the
/// points within the precision and completes a measured number of
/// processes paper-style (lower bounds below the measured values, module
/// `ddqn::metrics`).
#[test]
fn committed_weights_raw_in_closed_loop() {
    let agent = committed();
    let (mut passed, mut points, mut completed, mut paper) = (0, 0, 0, 0);
    for (p, limits) in HELD_OUT {
        let c = course(p, limits);
        let mut rpro = kerf_stepping::Rpro::new(&c, RproSettings::default()).unwrap();
        let reference = ddqn::closed_loop(&mut rpro, &c, 1_000_000).unwrap();
        assert!(reference.completed && reference.substitutions == 0);
        assert!(reference.errors.iter().all(|e| *e <= database::PRECISION));
        let mut rpro = kerf_stepping::Rpro::new(&c, RproSettings::default()).unwrap();
        let rpro_run = run(&c, &mut rpro, 1_000_000).unwrap();
        assert_eq!(reference.steps, rpro_run.steps());
        let last_pass = rpro_run.passes.last().unwrap().step;
        assert_eq!(reference.paper_steps, Some(last_pass));
        assert_eq!(
            metrics::Outcome::from(&rpro_run).paper_steps,
            last_pass,
            "baseline and closed loop count RPRO's steps alike"
        );
        assert!(last_pass <= reference.steps);
        let r =
            ddqn::closed_loop(&mut agent.clone(), &c, metrics::step_cap(rpro_run.steps())).unwrap();
        assert_eq!(r.errors.len(), c.targets());
        assert!(r.steps <= metrics::step_cap(rpro_run.steps()));
        // Paper-style completion is implied by completion at rest.
        assert!(!r.completed || r.paper_steps.is_some());
        if let Some(k) = r.paper_steps {
            assert_eq!(r.passed(), c.targets());
            assert!(k <= r.steps);
        }
        passed += r.passed();
        points += r.within.len();
        completed += usize::from(r.completed);
        paper += usize::from(r.paper_steps.is_some());
        eprintln!(
            "path {p} limits #{limits}: steps {} (RPRO {}), paper-style {:?} (RPRO {last_pass}), \
             completed at rest {}, capped {}, passed {}/{}, mean error {:.1} µm, substitutions {}",
            r.steps,
            rpro_run.steps(),
            r.paper_steps,
            r.completed,
            r.capped,
            r.passed(),
            c.targets(),
            r.mean_error() * 1e6,
            r.substitutions
        );
    }
    eprintln!(
        "raw: paper-style {paper}/{n}, at rest {completed}/{n}, passed {passed}/{points}",
        n = HELD_OUT.len()
    );
    assert!(
        passed * 100 >= points * RAW_PASSED_PERCENT,
        "passed {passed} of {points} points"
    );
    assert!(paper >= RAW_PAPER_COMPLETED, "paper-style {paper}");
}

/// Lower bound (per cent) of the share of points the committed raw agent
/// passes within the precision on [`HELD_OUT`] (measured: 52 of 70, 74 %).
const RAW_PASSED_PERCENT: usize = 60;

/// Lower bound of the committed raw agent's paper-style completions on
/// [`HELD_OUT`] (measured: 1 of 5, path 7 limits #1).
const RAW_PAPER_COMPLETED: usize = 1;

/// An agent whose greedy action is always `action`.
fn constant(action: Action) -> Agent {
    let arch = Architecture::new(2).unwrap();
    let mut layers = Weights::init(arch, &mut Rng::new(4)).layers().to_vec();
    let out = layers.len() - 1;
    layers[out].weight.iter_mut().for_each(|x| *x = 0.0);
    layers[out].bias = vec![0.0; 3];
    layers[out].bias[action.index()] = 1.0;
    Agent::new(Weights::from_layers(arch, layers).unwrap(), BTreeMap::new()).unwrap()
}

/// Paper-style completion counts to the pass of the last point and needs
/// no rest; completion at rest does; a run that misses a point completes
/// neither way.
#[test]
fn paper_style_completion_needs_no_stop_on_the_last_point() {
    // One point 50 mm ahead with a 0.1 mm window, the slowest Table 1
    // limits (2.5 m/min: 83 µm per 2 ms period): constant "accelerate"
    // (held at the velocity limit by limit substitutions) passes it within
    // the window and never stops.
    let lat = Lattice::new(database::limit_grid()[0], database::PERIOD).unwrap();
    let c = Course::new(lat, vec![0.0, 0.05], 1e-4).unwrap();
    let cap = 2_000;
    let r = ddqn::closed_loop(&mut constant(Action::Accelerate), &c, cap).unwrap();
    assert!(!r.completed && r.capped && r.steps == cap, "{r:?}");
    assert!(r.substitutions > 0);
    let k = r.paper_steps.expect("the point is passed within 0.1 mm");
    assert_eq!(k, r.samples[0]);
    assert!(r.within[0] && k > 0 && k < cap);
    // RPRO completes both ways, its last pass before its stop.
    let mut rpro = kerf_stepping::Rpro::new(&c, RproSettings::default()).unwrap();
    let reference = ddqn::closed_loop(&mut rpro, &c, cap).unwrap();
    assert!(reference.completed);
    assert!(reference.paper_steps.is_some_and(|p| p <= reference.steps));
    // On dense points constant "accelerate" steps over points: neither.
    let dense = course(7, 29);
    let r = ddqn::closed_loop(&mut constant(Action::Accelerate), &dense, cap).unwrap();
    assert!(r.passed() < dense.targets());
    assert_eq!(r.paper_steps, None);
    assert!(!r.completed);
}

/// An episode replays RPRO's recorded run from any step: the features are
/// the recorded ones from there, the steps count from the start, and the
/// replay ends (terminal) at the run's end.
#[test]
fn episodes_replay_from_any_recorded_step() {
    let c = course(7, 29);
    let rec = env::record(&c, RproSettings::default(), 1_000_000).unwrap();
    let n = rec.steps();
    let start = n / 2;
    let mut e = env::Env::starting_at(&rec, start);
    assert_eq!((e.start(), e.position(), e.steps()), (start, start, 0));
    assert_eq!(e.features(), rec.features[start]);
    let mut taken = 0;
    while let Some(o) = e.step(Action::Keep) {
        taken += 1;
        assert_eq!(o.rpro, rec.actions[start + taken - 1]);
        assert_eq!(o.next, rec.features[start + taken]);
        assert_eq!(o.end == env::StepEnd::Done, start + taken == n);
    }
    assert_eq!(taken, n - start);
    assert_eq!(e.steps(), n - start);
    assert!(e.done());
    // A start past the end is clamped to the end: nothing to replay.
    let mut late = env::Env::starting_at(&rec, n + 10);
    assert!(late.done() && late.step(Action::Keep).is_none());
    assert_eq!(env::Env::new(&rec).start(), 0);
}

/// The training reading of module `ddqn::env`: after a short training on
/// replays of RPRO's runs the agent agrees with RPRO's decisions on a
/// held-out RPRO run more often than the constant "accelerate" policy
/// (the policy the episode-ending reading learned).
#[test]
fn short_training_beats_constant_accelerate_on_held_out_rpro_runs() {
    let subset = database::subset(15, Density::High);
    let (train_set, _) = database::split(&subset, 0);
    let picked: Vec<_> = train_set.iter().step_by(6).copied().collect();
    let courses = ddqn::courses(&picked).unwrap();
    let settings = DdqnSettings::default().max_episodes(SHORT_EPISODES).seed(3);
    let trained = ddqn::train(&settings, &courses).unwrap();
    // Episodes start at a uniform step of the recorded run (module
    // `ddqn::env`) and replay it to its end or for MaxStepsPerEpisode steps.
    let lengths: Vec<usize> = courses
        .iter()
        .map(|c| {
            env::record(c, RproSettings::default(), 1_000_000)
                .unwrap()
                .steps()
        })
        .collect();
    let mut late_starts = 0;
    for h in &trained.history {
        let n = lengths[h.course];
        assert!(h.start < n, "{h:?}");
        match h.end {
            ddqn::train::EpisodeEnd::Completed => assert_eq!(h.start + h.steps, n, "{h:?}"),
            ddqn::train::EpisodeEnd::Truncated => assert_eq!(h.steps, 300, "{h:?}"),
        }
        late_starts += usize::from(2 * h.start >= n);
    }
    // Uniform starts: about half the episodes begin in a run's second half.
    assert!(
        (SHORT_EPISODES / 4..=3 * SHORT_EPISODES / 4).contains(&late_starts),
        "{late_starts} of {SHORT_EPISODES} episodes start in the second half"
    );
    let (mut agent_share, mut accelerate_share) = (0.0, 0.0);
    for (p, limits) in HELD_OUT {
        let c = course(p, limits);
        let rec = env::record(&c, RproSettings::default(), 1_000_000).unwrap();
        agent_share += metrics::agreement(&trained.agent, &c, &rec).unwrap();
        accelerate_share += rec
            .actions
            .iter()
            .filter(|a| **a == Action::Accelerate)
            .count() as f64
            / rec.steps() as f64;
    }
    let n = HELD_OUT.len() as f64;
    eprintln!(
        "agreement with RPRO: agent {:.3}, constant accelerate {:.3}",
        agent_share / n,
        accelerate_share / n
    );
    assert!(agent_share > accelerate_share + 0.05 * n);
}

/// Episodes of the short training run.
const SHORT_EPISODES: usize = 40;

/// The shield's progress rule: an agent that always decelerates (a
/// network whose "decelerate" output dominates) never rests before a
/// point; the shielded run finishes without the step cap.
#[test]
fn the_shield_does_not_let_a_decelerating_agent_stall() {
    let w = Weights::init(Architecture::new(2).unwrap(), &mut Rng::new(4));
    let mut layers = w.layers().to_vec();
    let out = layers.len() - 1;
    layers[out].weight.iter_mut().for_each(|x| *x = 0.0);
    layers[out].bias = vec![0.0, 0.0, 1.0];
    let agent = Agent::new(
        Weights::from_layers(w.architecture(), layers).unwrap(),
        BTreeMap::new(),
    )
    .unwrap();
    let c = course(7, 29);
    let rec = env::record(&c, RproSettings::default(), 1_000_000).unwrap();
    let mut s = Shielded::new(agent, &c, RproSettings::default()).unwrap();
    let r = run(&c, &mut s, metrics::step_cap(rec.steps())).unwrap();
    assert_eq!(r.passes.len(), c.targets());
    assert!(s.overrides() > 0);
}

#[test]
fn training_is_deterministic_for_a_seed() {
    let subset = database::subset(15, Density::High);
    let (train_set, _) = database::split(&subset, 0);
    let picked: Vec<_> = train_set.iter().step_by(30).copied().collect();
    let courses = ddqn::courses(&picked).unwrap();
    let settings = DdqnSettings::default().max_episodes(20).seed(11);
    let a = ddqn::train(&settings, &courses).unwrap();
    let b = ddqn::train(&settings, &courses).unwrap();
    assert!(a.learning_steps > 0, "no gradient step in 20 episodes");
    assert_eq!(a.agent.weights(), b.agent.weights());
    assert_eq!(a.history, b.history);
    let c = ddqn::train(&settings.seed(12), &courses).unwrap();
    assert_ne!(a.agent.weights(), c.agent.weights());
    // Training moved the weights away from their initialization.
    let init = Weights::init(settings.architecture, &mut Rng::new(11));
    assert_ne!(a.agent.weights(), &init);
    assert_eq!(a.agent.info().get("seed").map(String::as_str), Some("11"));

    for bad in [
        settings.mini_batch_size(0),
        settings.experience_buffer_length(10),
        settings.discount(1.5),
        settings.learning_rate(0.0),
        settings.target_smooth_factor(f64::NAN),
    ] {
        assert!(matches!(
            ddqn::train(&bad, &courses),
            Err(StepError::InvalidParameter { .. })
        ));
    }
    assert!(ddqn::train(&settings, &[]).is_err());
}

#[test]
fn pearson_and_median_match_hand_values() {
    use ddqn::metrics::{median, pearson};
    assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
    assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
    assert_eq!(median(&[]), None);
    let r = pearson(&[1.0, 2.0, 3.0, 4.0], &[2.0, 4.0, 6.0, 8.5]).unwrap();
    assert!(r > 0.99 && r < 1.0);
    assert!((pearson(&[1.0, 2.0, 3.0], &[3.0, 2.0, 1.0]).unwrap() + 1.0).abs() < 1e-12);
    assert_eq!(pearson(&[1.0, 1.0], &[1.0, 2.0]), None);
}
