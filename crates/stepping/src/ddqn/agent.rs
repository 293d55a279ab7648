//! The trained agent as a [`Controller`]: the greedy action of the
//! Q-network ([`Agent`], what seed 002 measures), and the same agent behind
//! RPRO's viability check ([`Shielded`], what a deployment runs).

use std::collections::BTreeMap;
use std::path::Path;

use crate::{
    course::Course,
    error::StepError,
    lattice::Action,
    rpro::{Rpro, RproSettings},
    run::{Controller, Decision},
};

use super::{
    features::features,
    file,
    net::{Architecture, Weights},
};

/// A Q-network that acts greedily: a = argmax_a Q(x, a) over
/// [`Action::ALL`] (ties go to the earlier action), x = [`features`].
#[derive(Debug, Clone, PartialEq)]
pub struct Agent {
    weights: Weights,
    info: BTreeMap<String, String>,
}

impl Agent {
    /// An agent with `weights` and the description `info` (stored in the
    /// file's metadata by [`Agent::save`]).
    ///
    /// # Errors
    /// [`StepError::Network`] when the weights are inconsistent
    /// ([`Weights::validate`]).
    pub fn new(weights: Weights, info: BTreeMap<String, String>) -> Result<Self, StepError> {
        weights.validate()?;
        Ok(Self { weights, info })
    }

    /// Reads a network file ([`file`]).
    ///
    /// # Errors
    /// [`StepError::Network`] with the reason (missing file, truncated,
    /// wrong architecture, missing tensor, wrong shape, …).
    pub fn load(path: &Path) -> Result<Self, StepError> {
        let (weights, info) = file::read(path)?;
        Ok(Self { weights, info })
    }

    /// Writes the network file ([`file`]).
    ///
    /// # Errors
    /// [`StepError::Network`] when it cannot be written.
    pub fn save(&self, path: &Path) -> Result<(), StepError> {
        file::write(path, &self.weights, &self.info)
    }

    /// The weights.
    pub fn weights(&self) -> &Weights {
        &self.weights
    }

    /// The architecture.
    pub fn architecture(&self) -> Architecture {
        self.weights.architecture()
    }

    /// The description stored with the network (training settings, …).
    pub fn info(&self) -> &BTreeMap<String, String> {
        &self.info
    }

    /// Q-values at `decision`, in [`Action::ALL`] order.
    pub fn q_values(&self, course: &Course, decision: &Decision) -> [f32; 3] {
        self.weights.q_values(&features(course, decision))
    }

    /// The greedy action at `decision`.
    ///
    /// # Errors
    /// [`StepError::Network`] when a Q-value is not finite.
    pub fn greedy(&self, course: &Course, decision: &Decision) -> Result<Action, StepError> {
        argmax(&self.q_values(course, decision)).ok_or_else(|| StepError::Network {
            reason: format!("non-finite Q-value at step {}", decision.step),
        })
    }
}

/// The index-ordered argmax of `q` as an action; `None` when a value is not
/// finite.
pub(crate) fn argmax(q: &[f32; 3]) -> Option<Action> {
    if q.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut best = 0;
    for (k, v) in q.iter().enumerate().skip(1) {
        if *v > q[best] {
            best = k;
        }
    }
    Some(Action::ALL[best])
}

impl Controller for Agent {
    fn decide(&mut self, course: &Course, decision: &Decision) -> Result<Action, StepError> {
        self.greedy(course, decision)
    }
}

/// The agent behind RPRO's viability check, with a progress rule.
///
/// # Rule
/// At each period let `a` be the agent's greedy action and `r` RPRO's own
/// decision. The agent's `a` is taken when
/// 1. RPRO allows it ([`Rpro::allows`]: the next state is viable), and
/// 2. it does not slow the axis below what progress needs: the next
///    state's settled velocity ([`crate::lattice::State::settled_velocity`])
///    is at least min(`course.crawl`, settled velocity after `r`).
///
/// Otherwise RPRO's `r` is taken (an *override*, [`Shielded::overrides`]).
///
/// Rule 1 alone keeps RPRO's guarantee (module [`crate::rpro`]): every
/// point is passed within the precision and the axis stops on the last one
/// — *if* the run ends. It does not force the run to end: resting before a
/// point is viable, and an agent that decelerates there stalls until the
/// step cap (measured on the first trained agents). Rule 2 forbids that: the
/// axis may settle below the crawl velocity only where RPRO itself does (the
/// approach to the last point, or a point closer than a crawl's stopping
/// distance), so each period either keeps at least the crawl velocity or
/// follows RPRO's own braking, and the run ends.
#[derive(Debug, Clone)]
pub struct Shielded {
    agent: Agent,
    rpro: Rpro,
    decisions: usize,
    overrides: usize,
}

impl Shielded {
    /// The shield of `agent` on `course`.
    ///
    /// # Errors
    /// [`RproSettings::validate`].
    pub fn new(agent: Agent, course: &Course, settings: RproSettings) -> Result<Self, StepError> {
        Ok(Self {
            agent,
            rpro: Rpro::new(course, settings)?,
            decisions: 0,
            overrides: 0,
        })
    }

    /// Decisions taken so far.
    pub fn decisions(&self) -> usize {
        self.decisions
    }

    /// Decisions where RPRO replaced the agent's action.
    pub fn overrides(&self) -> usize {
        self.overrides
    }

    /// The agent.
    pub fn agent(&self) -> &Agent {
        &self.agent
    }
}

impl Controller for Shielded {
    fn decide(&mut self, course: &Course, decision: &Decision) -> Result<Action, StepError> {
        self.decisions += 1;
        let wanted = self.agent.greedy(course, decision)?;
        let own = self.rpro.decide(course, decision)?;
        if wanted == own {
            return Ok(own);
        }
        let settled = |a: Action| decision.state.step(a.sign()).settled_velocity();
        if settled(wanted) >= course.crawl.min(settled(own))
            && self.rpro.allows(course, decision, wanted)
        {
            return Ok(wanted);
        }
        self.overrides += 1;
        Ok(own)
    }
}
