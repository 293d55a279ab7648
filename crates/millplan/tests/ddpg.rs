//! DDPG (kerf_millplan::ddpg) on a toy environment with a known optimum:
//! it learns, it is deterministic for a seed, it refuses bad settings, and
//! it propagates environment errors.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_millplan::ddpg::{train, DdpgSettings, EpisodeReport};
use kerf_millplan::policy::Policy;
use kerf_millplan::{Environment, MillPlanError, Transition};

/// 1-D regulation: state x ∈ [−1, 1], action a ∈ [−1, 1] moves x by 0.1·a
/// (clipped to [−1, 1]), reward −x² after the move, 20 steps, no terminal
/// state. Episodes start alternately at x₀ = +0.8 and −0.8 (deterministic),
/// so a good policy must depend on the state.
///
/// Optimum from ±0.8 (move by 0.1 toward 0 for 8 steps, then stay):
/// −Σ_{k=1..7} (0.1k)² = −1.40. Zero action: −20 · 0.64 = −12.8.
struct Toy {
    x: f64,
    t: usize,
    episode: usize,
    start: Option<f64>,
}

const TOY_STEPS: usize = 20;

impl Toy {
    fn new() -> Self {
        Self {
            x: 0.0,
            t: 0,
            episode: 0,
            start: None,
        }
    }
    /// A toy environment that always starts at `x0`.
    fn starting_at(x0: f64) -> Self {
        Self {
            start: Some(x0),
            ..Self::new()
        }
    }
}

impl Environment for Toy {
    fn observation_dim(&self) -> usize {
        1
    }
    fn action_dim(&self) -> usize {
        1
    }
    fn max_steps(&self) -> usize {
        TOY_STEPS
    }
    fn reset(&mut self) -> Result<Vec<f32>, MillPlanError> {
        self.x = self.start.unwrap_or(if self.episode.is_multiple_of(2) {
            0.8
        } else {
            -0.8
        });
        self.episode += 1;
        self.t = 0;
        Ok(vec![self.x as f32])
    }
    fn step(&mut self, action: &[f32]) -> Result<Transition, MillPlanError> {
        let a = match action {
            [a] if a.is_finite() && (-1.0..=1.0).contains(a) => f64::from(*a),
            _ => {
                return Err(MillPlanError::InvalidConfig {
                    name: "toy action".to_string(),
                    reason: format!("{action:?}"),
                })
            }
        };
        self.x = (self.x + 0.1 * a).clamp(-1.0, 1.0);
        self.t += 1;
        Ok(Transition {
            observation: vec![self.x as f32],
            reward: -self.x * self.x,
            done: false,
        })
    }
}

/// Greedy return of the trained actor from x₀ (through the policy's plain
/// forward pass).
fn greedy_return(policy: &Policy, x0: f64) -> f64 {
    let mut env = Toy::starting_at(x0);
    policy.rollout(&mut env).expect("rollout").total_reward
}

/// Table 2 settings (learning rates, γ, τ, buffer, batch 64, noise) with a
/// reduced budget: 2×64 hidden units, `episodes` toy episodes.
fn small_settings(seed: u64, episodes: usize) -> DdpgSettings {
    DdpgSettings::default()
        .with_episodes(episodes)
        .with_steps_per_episode(TOY_STEPS)
        .with_hidden_sizes(vec![64, 64])
        .with_seed(seed)
}

/// DDPG learns the toy task: the greedy return from both starts is far
/// better than the zero-action return −12.8 and close to the optimum −1.40.
///
/// Margin: −2.5 is 1.1 below the optimum; it accepts a policy that reaches
/// 0 one step late (at most 0.8² = 0.64 more) or dithers around 0; the
/// zero action gives −12.8 and a random policy (a ~ U(−1, 1), x a random
/// walk with step s.d. 0.058) about −12 from ±0.8, so passing needs a
/// state-dependent policy that moves toward 0 at nearly full speed from
/// both sides. Measured (seeds 0–9, these settings): worst −1.80, this
/// seed −1.48/−1.52.
#[test]
fn learns_the_toy_task() {
    let settings = small_settings(1, 60);
    let mut reports: Vec<EpisodeReport> = Vec::new();
    let mut env = Toy::new();
    let start = std::time::Instant::now();
    let agent = train(&mut env, &settings, &mut |r| reports.push(r.clone())).expect("training");
    let elapsed = start.elapsed().as_secs_f64();
    let policy = Policy::from_agent(&agent, "toy 1-D regulation").expect("policy");
    let plus = greedy_return(&policy, 0.8);
    let minus = greedy_return(&policy, -0.8);
    let first = &reports[0];
    let last = reports.last().expect("reports");
    println!(
        "toy: greedy returns {plus:.3} (x0 = +0.8), {minus:.3} (x0 = −0.8); optimum −1.40, \
         zero action −12.8; first/last episode reward {:.3}/{:.3}; {elapsed:.2} s",
        first.total_reward, last.total_reward
    );
    assert!(plus > -2.5, "greedy return from +0.8: {plus}");
    assert!(minus > -2.5, "greedy return from −0.8: {minus}");
    // Not better than the optimum (a check on the environment and returns).
    assert!(plus <= -1.40 + 1e-6 && minus <= -1.40 + 1e-6);

    // The reports: one per episode, numbered, warm-up without losses.
    assert_eq!(reports.len(), 60);
    assert_eq!(agent.history(), reports.as_slice());
    for (k, r) in reports.iter().enumerate() {
        assert_eq!(r.episode, k + 1);
        assert_eq!(r.episodes, 60);
        assert_eq!(r.steps, TOY_STEPS);
        assert!(r.total_reward.is_finite() && r.total_reward <= 0.0);
        assert!(r.elapsed_s >= 0.0 && r.remaining_s >= 0.0);
        assert_eq!(r.noise_std, settings.noise_std_at(k));
    }
    // Batch 64 with 20-step episodes: the first update is at step 64, in
    // episode 4 (1-based); episodes 1–3 have no losses.
    assert!(reports[..3].iter().all(|r| r.mean_critic_loss.is_none()));
    assert!(reports[3..]
        .iter()
        .all(|r| r.mean_critic_loss.is_some_and(f64::is_finite)
            && r.mean_actor_loss.is_some_and(f64::is_finite)));
    assert_eq!(last.remaining_s, 0.0);
}

/// The noise schedule of the module documentation: σ₀ for the first E_d
/// episodes, then σ₀ ρ^(k − E_d) for the 1-based episode k.
#[test]
fn noise_schedule() {
    let s = DdpgSettings::default();
    assert_eq!(s.noise_std_at(0), 0.1);
    assert_eq!(s.noise_std_at(49), 0.1);
    assert!((s.noise_std_at(50) - 0.1 * 0.999).abs() < 1e-15);
    assert!((s.noise_std_at(999) - 0.1 * 0.999f64.powi(950)).abs() < 1e-15);
    assert!((s.noise_std_at(999) - 0.03866).abs() < 1e-4);
}

fn actor_bits(settings: &DdpgSettings) -> Vec<u32> {
    let mut env = Toy::new();
    let agent = train(&mut env, settings, &mut |_| {}).expect("training");
    agent
        .actor()
        .parameters()
        .expect("parameters")
        .into_iter()
        .flat_map(|(w, b)| w.into_iter().chain(b))
        .map(f32::to_bits)
        .collect()
}

/// Same seed → bit-identical actor weights (after the warm-up and 56
/// updates, so every random source is exercised: weights, noise, replay
/// sampling); another seed → different weights.
#[test]
fn deterministic_for_a_seed() {
    let settings = small_settings(7, 6).with_hidden_sizes(vec![32, 32]);
    let a = actor_bits(&settings);
    let b = actor_bits(&settings);
    let c = actor_bits(&settings.clone().with_seed(8));
    // Layers 1→32, 32→32, 32→1: weights and biases.
    assert_eq!(a.len(), 32 + 32 + 32 * 32 + 32 + 32 + 1);
    assert!(a == b, "same seed gave different weights");
    let differing = a.iter().zip(&c).filter(|(x, y)| x != y).count();
    assert!(
        differing > a.len() / 2,
        "other seed differs in only {differing} of {} weights",
        a.len()
    );
}

/// Bad settings are refused before anything runs.
#[test]
fn bad_settings_are_errors() {
    let ok = small_settings(0, 1);
    let cases = [
        ("batch 0", ok.clone().with_batch_size(0)),
        ("batch > buffer", ok.clone().with_buffer_capacity(10)),
        ("episodes 0", ok.clone().with_episodes(0)),
        ("steps 0", ok.clone().with_steps_per_episode(0)),
        (
            "actor lr NaN",
            ok.clone().with_actor_learning_rate(f64::NAN),
        ),
        ("critic lr 0", ok.clone().with_critic_learning_rate(0.0)),
        (
            "critic lr inf",
            ok.clone().with_critic_learning_rate(f64::INFINITY),
        ),
        ("gamma > 1", ok.clone().with_discount(1.5)),
        ("gamma NaN", ok.clone().with_discount(f64::NAN)),
        ("tau 0", ok.clone().with_soft_update_rate(0.0)),
        ("tau > 1", ok.clone().with_soft_update_rate(1.1)),
        ("sigma < 0", ok.clone().with_noise_std(-0.1)),
        ("decay NaN", ok.clone().with_noise_decay_rate(f64::NAN)),
        ("decay 0", ok.clone().with_noise_decay_rate(0.0)),
        ("no hidden layers", ok.clone().with_hidden_sizes(vec![])),
        ("hidden width 0", ok.clone().with_hidden_sizes(vec![64, 0])),
    ];
    for (what, settings) in cases {
        let validated = settings.validate();
        assert!(validated.is_err(), "{what} was accepted");
        let mut env = Toy::new();
        let err = train(&mut env, &settings, &mut |_| {}).expect_err(what);
        assert!(
            matches!(
                err,
                MillPlanError::InvalidParameter { .. } | MillPlanError::InvalidConfig { .. }
            ),
            "{what}: {err}"
        );
        // The environment was never touched.
        assert_eq!(env.episode, 0, "{what}");
    }
    assert!(ok.validate().is_ok());
    assert!(DdpgSettings::default().validate().is_ok());
}

/// Settings survive a JSON round trip, and a partial JSON gets the Table 2
/// defaults for the missing fields.
#[test]
fn settings_serde() {
    let s = small_settings(12345678901234567890, 3);
    let json = serde_json::to_string(&s).expect("serialize");
    let back: DdpgSettings = serde_json::from_str(&json).expect("deserialize");
    assert_eq!(back, s);
    let partial: DdpgSettings =
        serde_json::from_str(r#"{"episodes": 20, "seed": 3}"#).expect("partial");
    assert_eq!(
        partial,
        DdpgSettings::default().with_episodes(20).with_seed(3)
    );
    assert!(serde_json::from_str::<DdpgSettings>(r#"{"episode": 20}"#).is_err());
}

/// An environment that fails at a given step, or returns bad data.
struct Failing {
    fail_at: usize,
    mode: u8,
    t: usize,
}

impl Environment for Failing {
    fn observation_dim(&self) -> usize {
        2
    }
    fn action_dim(&self) -> usize {
        1
    }
    fn max_steps(&self) -> usize {
        10
    }
    fn reset(&mut self) -> Result<Vec<f32>, MillPlanError> {
        Ok(vec![0.0, 0.0])
    }
    fn step(&mut self, _action: &[f32]) -> Result<Transition, MillPlanError> {
        self.t += 1;
        if self.t < self.fail_at {
            return Ok(Transition {
                observation: vec![0.0, 0.0],
                reward: 0.0,
                done: false,
            });
        }
        match self.mode {
            0 => Err(MillPlanError::InvalidParameter {
                name: "segment".to_string(),
                value: self.t as f64,
                reason: "model failed".to_string(),
            }),
            1 => Ok(Transition {
                observation: vec![0.0],
                reward: 0.0,
                done: false,
            }),
            2 => Ok(Transition {
                observation: vec![0.0, f32::NAN],
                reward: 0.0,
                done: false,
            }),
            _ => Ok(Transition {
                observation: vec![0.0, 0.0],
                reward: f64::NAN,
                done: false,
            }),
        }
    }
}

/// Environment errors propagate unchanged; bad observations and rewards
/// are errors, never panics.
#[test]
fn environment_errors_propagate() {
    let settings = small_settings(0, 5)
        .with_batch_size(4)
        .with_hidden_sizes(vec![8]);
    for mode in 0..4u8 {
        let mut env = Failing {
            fail_at: 15,
            mode,
            t: 0,
        };
        let err = train(&mut env, &settings, &mut |_| {}).expect_err("must fail");
        let text = err.to_string();
        match mode {
            0 => assert!(
                matches!(&err, MillPlanError::InvalidParameter { reason, .. } if reason == "model failed"),
                "{text}"
            ),
            1 => assert!(text.contains("1 entries, expected 2"), "{text}"),
            2 => assert!(text.contains("NaN"), "{text}"),
            _ => assert!(text.contains("reward"), "{text}"),
        }
        assert_eq!(env.t, 15, "mode {mode}: stopped at the failing step");
    }
}
