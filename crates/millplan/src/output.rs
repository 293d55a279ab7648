//! The planner's answer to a request ([`MillPlanOutput`]) and the wall
//! time of its steps ([`PlanningPhases`]).

use std::path::PathBuf;

use kerf_mill::BranchJump;

use crate::chatter_judge::JudgedSample;
use crate::executed::Executed;
use crate::plan::{IndicatorProvenance, Plan};
use crate::request::PlannerKind;
use crate::trajectory::JointTrajectory;

/// The answer to a request.
#[derive(Debug, Clone, PartialEq)]
pub struct MillPlanOutput {
    /// The request's id.
    pub request_id: String,
    /// The planner that answered.
    pub planner: PlannerKind,
    /// The policy file used (`ddpg`, `fixed_g`).
    pub policy_file: Option<PathBuf>,
    /// Per-segment Ω, f, g, |μ|max, K, 1/K, joints, time, reward (direct
    /// evaluation) and the totals.
    pub plan: Plan,
    /// The joint trajectory as planned: timed by the planned feeds, not
    /// from rest ([`crate::planned`]).
    pub trajectory: JointTrajectory,
    /// What the robot runs: [`JointTrajectory`] from rest to rest,
    /// time-scaled to the joint velocity and acceleration limits, and the
    /// plan at the feeds that result ([`Executed`]).
    pub executed: Executed,
    /// Joint steps above the branch-jump threshold between trajectory
    /// points (index = the later point).
    pub branch_jumps: Vec<BranchJump>,
    /// Whether the default cell's indicator cache applied to the request.
    pub cache_used: bool,
    /// Wall-clock planning time \[s\].
    pub planning_seconds: f64,
    /// Wall-clock time of each step of [`crate::MillPlanner::plan`] \[s\].
    pub phases: PlanningPhases,
    /// Where the plan's |μ|max values come from: all direct (the default),
    /// or partly the indicator cache with its stated error bound
    /// ([`crate::MillPlanner::with_indicator_source`]); its `note` belongs in the
    /// answer's message.
    pub indicator: IndicatorProvenance,
    /// How every planner of [`PlannerKind::BEST_CANDIDATES`] that ran did when the request
    /// asked for [`PlannerKind::Best`] (in that order; `greedy_best_g` only where `greedy` has
    /// no chatter-free plan; empty for another planner).
    pub candidates: Vec<Candidate>,
}

impl MillPlanOutput {
    /// The executed trajectory and its chatter judge in one sentence
    /// ([`crate::chatter_judge`]): the duration with its run-in and run-out, the samples in
    /// the material, the evaluations, the worst sample and the lowest feed in the material.
    pub fn judge_text(&self) -> String {
        let (v, sc) = (&self.executed.chatter, &self.executed.scaling);
        let sample = |s: &JudgedSample| {
            format!(
                "segment {} (s = {:.4} m, t = {:.3} s: {:.0} rpm, {:.2} mm/s, g = {:.4} rad)",
                s.segment,
                s.arc_length,
                s.time,
                s.rpm,
                s.feed * 1e3,
                s.g
            )
        };
        format!(
            "trajectory {:.3} s from rest to rest (run-in {:.1} mm, run-out {:.1} mm); chatter \
             judged at {} control periods in the material ({} evaluations, {} segment values \
             reused, {:.3} s): worst |mu|max {:.4} at {}; lowest feed in the material {}",
            sc.duration(),
            sc.run_in * 1e3,
            sc.run_out * 1e3,
            v.samples,
            v.evaluations,
            v.reused,
            v.seconds,
            v.max_spectral_radius,
            v.worst.as_ref().map_or("-".to_string(), sample),
            v.lowest_feed.as_ref().map_or("-".to_string(), sample)
        )
    }

    /// [`MillPlanOutput::candidates`] in one sentence: the planner chosen, and each
    /// candidate's executed duration (and its ratio to the chosen one), |μ|max and 1/K, or its
    /// status; empty without candidates.
    pub fn candidates_text(&self) -> String {
        if self.candidates.is_empty() {
            return String::new();
        }
        let chosen = self.executed.scaling.duration();
        let list: Vec<String> = self
            .candidates
            .iter()
            .map(|c| {
                let name = c.planner.name();
                match c.status {
                    crate::status::SUCCESS | crate::status::CHATTER => format!(
                        "{name} {:.3} s ({:.3}x){}, |mu|max {:.4}, 1/K {:.3}",
                        c.duration,
                        c.duration / chosen,
                        if c.chatter_free { "" } else { " CHATTERS" },
                        c.max_spectral_radius,
                        c.min_condition_indicator
                    ),
                    status => format!(
                        "{name} {}",
                        crate::status::status_name(status).unwrap_or("?")
                    ),
                }
            })
            .collect();
        let skipped = if self
            .candidates
            .iter()
            .any(|c| c.planner == PlannerKind::GreedyBestG)
        {
            ""
        } else {
            "; greedy_best_g not run (greedy is chatter-free)"
        };
        format!(
            "best of {} candidates: {} (the fastest chatter-free plan as executed with 1/K at or \
             above its minimum); {}{skipped}",
            self.candidates.len(),
            self.planner.name(),
            list.join("; ")
        )
    }
}

/// One planner's outcome in [`PlannerKind::Best`]'s choice.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The planner.
    pub planner: PlannerKind,
    /// Its status had it been asked alone ([`crate::status`]): SUCCESS, or CHATTER for a plan
    /// that chatters as executed, or its error's status.
    pub status: u8,
    /// The error's message, empty for a plan.
    pub message: String,
    /// The executed trajectory's duration from rest to rest \[s\] (0 without a plan).
    pub duration: f64,
    /// Chatter-free at every executed sample in the material.
    pub chatter_free: bool,
    /// The largest executed |μ|max.
    pub max_spectral_radius: f64,
    /// The smallest 1/K along the trajectory.
    pub min_condition_indicator: f64,
}

impl Candidate {
    /// The candidate of a plan.
    pub fn planned(out: &MillPlanOutput) -> Self {
        let free = !out.executed.chatters();
        Self {
            planner: out.planner,
            status: if free {
                crate::status::SUCCESS
            } else {
                crate::status::CHATTER
            },
            message: String::new(),
            duration: out.executed.scaling.duration(),
            chatter_free: free,
            max_spectral_radius: out.executed.plan.max_spectral_radius,
            min_condition_indicator: out.executed.scaling.min_condition_indicator.0,
        }
    }

    /// The candidate of a planner that failed.
    pub fn failed(planner: PlannerKind, error: &crate::MillPlanError) -> Self {
        Self {
            planner,
            status: crate::status::status_of(error),
            message: error.to_string(),
            duration: 0.0,
            chatter_free: false,
            max_spectral_radius: 0.0,
            min_condition_indicator: 0.0,
        }
    }
}

/// Wall-clock seconds of the steps of [`crate::MillPlanner::plan`] (module
/// documentation); their sum is at most
/// [`MillPlanOutput::planning_seconds`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanningPhases {
    /// Steps 1–3: request validation, the request's cell, reachability.
    pub setup: f64,
    /// Step 4: the planner (policy rollout, DP or naive), including the
    /// policy's loading when not already loaded.
    pub planner: f64,
    /// Step 5: [`Plan::evaluate`] (direct |μ|max of every segment).
    pub evaluation: f64,
    /// Step 6: the joint trajectory.
    pub trajectory: f64,
}
