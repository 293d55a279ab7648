//! The training environment: one stored RPRO run of the database, replayed
//! while the agent chooses actions and is rewarded against RPRO's recorded
//! decisions (seed 002 section 2.C and eq. 4).
//!
//! # kerf's reading (the seed leaves the episode open)
//! Section 2.C: the database is "stored simulations of machining processes
//! … prepared using the RPRO algorithm", and eq. 4 rewards r = 0 when the
//! agent's action equals RPRO's decision, r = −0.1 otherwise. kerf reads the
//! database as the recorded RPRO runs and an episode as the replay of one:
//! * **Reset**: a recorded state of RPRO's run of the process, drawn
//!   uniformly over the run's periods by the trainer ([`Env::starting_at`];
//!   module `ddqn::train`). *kerf's choice* — the paper does not say where
//!   an episode starts; see "Where an episode starts" below.
//! * **Step**: the agent sees the features of RPRO's recorded state and
//!   chooses an action (ε-greedy, module `ddqn::train`); the reward is eq. 4
//!   against RPRO's recorded decision there; the next state is RPRO's next
//!   recorded state, *whatever the agent chose*.
//! * **End**: the end of the recorded run (terminal: RPRO rests on the last
//!   point), or MaxStepsPerEpisode periods (Table 3: 300) — a truncation,
//!   not a terminal state: the target still bootstraps from the last state,
//!   as MATLAB's `IsDone` stays false at the step limit.
//!
//! # Why not the agent's own states
//! A first reading stepped the axis with the agent's action, labelled every
//! state with RPRO's decision there, and ended the episode as soon as the
//! agent left RPRO's viable set (where RPRO has no decision to imitate).
//! From a random initial network the agent leaves that set within a few
//! periods: measured, episodes lasted 15–20 steps, the agent only ever saw
//! the acceleration phase, learned "accelerate", and completed 0 of the 480
//! test processes. Replaying RPRO's runs shows the agent every phase of a
//! process (acceleration, cruising, braking before a close point, the stop
//! on the last one) in every episode, which is what imitating "stored
//! simulations" needs. The cost is the usual one of imitating on the
//! expert's states: the agent never sees its own mistakes' states, which
//! the closed-loop evaluation ([`super::metrics`]) measures.
//!
//! # Where an episode starts (kerf's choice)
//! The first version reset to RPRO's first recorded state (at rest on the
//! start point). With MaxStepsPerEpisode = 300 (Table 3) an episode then
//! only ever covers periods 0–299 of a run: a medium-density run (about 626
//! periods on the 15-point subset) was never seen past its first half, and
//! even on high density (about 110 periods) the stop on the last point was
//! one short stretch of each episode. Measured with those episodes, the
//! committed agent passed points but never braked to stop on the last one
//! (0 of 480 test processes completed at rest). The seed names the cause
//! itself (section 3, after Table 6: limiting episodes to 300 steps meant
//! the agent "did not have the opportunity to experience the end of the
//! machining process during learning"). kerf therefore starts each episode
//! at a step drawn uniformly from 0..steps of the recorded run (from the
//! trainer's seeded [`kerf_rng::Rng`]) and still ends it after at most
//! MaxStepsPerEpisode periods, so every phase — the start, the middle, the
//! braking, the stop — is trained, whatever the run's length.
//!
//! RPRO's runs are deterministic, so a [`Recording`] is computed once per
//! process ([`record`]) and replayed by every episode on it.

use crate::{
    course::Course,
    error::StepError,
    lattice::Action,
    rpro::{Rpro, RproSettings},
    run::{run, Controller, Decision},
};

use super::features::features;

/// Reward of an action that differs from RPRO's (seed 002 eq. 4).
pub const MISMATCH_REWARD: f32 = -0.1;

/// One stored RPRO run: at each period the decision RPRO saw, its
/// features and RPRO's action.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// What RPRO saw at each period.
    pub decisions: Vec<Decision>,
    /// RPRO's action at each period.
    pub actions: Vec<Action>,
    /// The agent's input at each period ([`features`]), plus one for the
    /// final state (at rest on the last point): `actions.len() + 1` rows.
    pub features: Vec<[f32; 3]>,
}

impl Recording {
    /// Periods of the run.
    pub fn steps(&self) -> usize {
        self.actions.len()
    }
}

/// A controller that records what RPRO saw and did.
struct Recorder<'a> {
    rpro: &'a mut Rpro,
    decisions: Vec<Decision>,
    actions: Vec<Action>,
}

impl Controller for Recorder<'_> {
    fn decide(&mut self, course: &Course, decision: &Decision) -> Result<Action, StepError> {
        let a = self.rpro.decide(course, decision)?;
        self.decisions.push(*decision);
        self.actions.push(a);
        Ok(a)
    }
}

/// RPRO's run of `course` with `settings`, recorded.
///
/// # Errors
/// RPRO's errors ([`Rpro::new`], [`run`]: no viable action, step cap
/// `max_steps`).
///
/// # Performance
/// One RPRO run (one decision, a few viability checks, per period).
pub fn record(
    course: &Course,
    settings: RproSettings,
    max_steps: usize,
) -> Result<Recording, StepError> {
    let mut rpro = Rpro::new(course, settings)?;
    let mut rec = Recorder {
        rpro: &mut rpro,
        decisions: Vec::new(),
        actions: Vec::new(),
    };
    let r = run(course, &mut rec, max_steps)?;
    let (decisions, actions) = (rec.decisions, rec.actions);
    let mut feats: Vec<[f32; 3]> = decisions.iter().map(|d| features(course, d)).collect();
    let end = Decision {
        step: r.steps(),
        state: r.states.last().copied().unwrap_or_default(),
        target: course.targets() - 1,
        seen: true,
    };
    feats.push(features(course, &end));
    Ok(Recording {
        decisions,
        actions,
        features: feats,
    })
}

/// How a step ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepEnd {
    /// The episode goes on.
    Continue,
    /// The recorded run is over (RPRO at rest on the last point): terminal.
    Done,
}

/// The outcome of one environment step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// Seed 002 eq. 4.
    pub reward: f32,
    /// RPRO's recorded decision at the state the action was taken in.
    pub rpro: Action,
    /// Features of RPRO's next recorded state.
    pub next: [f32; 3],
    /// How the step ended.
    pub end: StepEnd,
}

/// One stored run being replayed (module documentation).
#[derive(Debug, Clone)]
pub struct Env<'a> {
    recording: &'a Recording,
    start: usize,
    step: usize,
}

impl<'a> Env<'a> {
    /// At the first recorded state of `recording` (at rest on the start).
    pub fn new(recording: &'a Recording) -> Self {
        Self::starting_at(recording, 0)
    }

    /// At recorded state `start` of `recording` (clamped to the run's end;
    /// module documentation, "Where an episode starts").
    pub fn starting_at(recording: &'a Recording, start: usize) -> Self {
        let start = start.min(recording.steps());
        Self {
            recording,
            start,
            step: start,
        }
    }

    /// Features of the current recorded state ([`features`]).
    pub fn features(&self) -> [f32; 3] {
        self.recording.features[self.step.min(self.recording.steps())]
    }

    /// Periods stepped in this episode.
    pub fn steps(&self) -> usize {
        self.step - self.start
    }

    /// The recorded step the episode started at.
    pub fn start(&self) -> usize {
        self.start
    }

    /// The recorded step the episode is at now.
    pub fn position(&self) -> usize {
        self.step
    }

    /// Whether the recorded run is over.
    pub fn done(&self) -> bool {
        self.step >= self.recording.steps()
    }

    /// Rewards `action` against RPRO's recorded decision (eq. 4) and moves
    /// to RPRO's next recorded state.
    ///
    /// # Returns
    /// The outcome; `None` when the recorded run is already over.
    pub fn step(&mut self, action: Action) -> Option<Outcome> {
        let rpro = *self.recording.actions.get(self.step)?;
        self.step += 1;
        Some(Outcome {
            reward: if action == rpro { 0.0 } else { MISMATCH_REWARD },
            rpro,
            next: self.features(),
            end: if self.done() {
                StepEnd::Done
            } else {
                StepEnd::Continue
            },
        })
    }
}
