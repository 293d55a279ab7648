//! The time-optimal variable feed along the smoothed joint path (issue 16, item 1): third-order
//! time-optimal path parameterization (TOPP3) under every joint's velocity, acceleration and
//! jerk limit and the process limits (feedrate, path acceleration, path jerk).
//!
//! Seed 001 moves at the constant feedrate `ṡ = f` (eq. 13) and names a variable feedrate as
//! future work (section 4). kerf keeps the paper's geometry (the B-spline joint path of eq. 61-62
//! in the normalized arc length `u = s/σ`) and replaces its time law by the fastest one the
//! machine can follow.
//!
//! # Formulation
//! With `a = ṡ²`, `b = s̈` and `c = s⃛/ṡ` on a station grid `0 = s_0 < … < s_n = σ`, the chain
//! rule of seed 001 eq. 6-7 in arc length (`q' = dq/ds = q_u/σ`, `q'' = q_uu/σ²`,
//! `q''' = q_uuu/σ³`) gives for every joint
//!
//! ```text
//! q̇ = q' ṡ,   q̈ = q'' a + q' b,   q⃛ = ṡ (q''' a + 3 q'' b + q' c)
//! ```
//!
//! and the process limits are those of a virtual seventh axis `q₇ = s` (`q' = 1`,
//! `q'' = q''' = 0`): `ṡ ≤ f`, `|s̈| ≤ A`, `|s⃛| ≤ J` (Table 1: the requested feedrate and the
//! feed ramps' path acceleration and jerk, now upper limits, not fixed ramps). The velocity
//! and acceleration rows are linear in `(a, b)`; the jerk rows are linearized around a
//! reference `a` from the second-order problem, on the safe side (`1/√a` by its tangent).
//! The problem is the TOPP3-SOCP of Wang et al., *Int. J. Mach. Tools Manuf.* 215:104355
//! (2026), solved by the `copp` crate on Clarabel: rest to rest, `a = b = 0` at both ends,
//! one constant-jerk (`s⃛` constant) interval at each end, `c` constant on every other interval
//! (so `b` is linear and `a` quadratic in `s` there, `a_{k+1} = a_k + (b_k + b_{k+1}) Δs`).
//!
//! The constraints hold at the stations. Between them the joint path's derivatives move; the
//! solver gets the joint limits scaled by a margin, and the planner checks the law the executor
//! will run at every controller sample (eq. 7, [`crate::metrics::limit_violations`]) and
//! solves again with a smaller margin if a sample breaks a limit.

use copp::diag::CoppError;
use copp::robot::Robot;
use copp::solver::topp2_ra::{topp2_ra, ReachSet2OptionsBuilder, Topp2ProblemBuilder};
use copp::solver::topp3_socp::{
    s_to_t_topp3, t_to_s_topp3, topp3_socp, ClarabelOptionsBuilder, Topp3ProblemBuilder,
    Topp3Profile,
};
use copp::InterpolationMode;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::error::ConstraintFamily;
use crate::machine::{AxisLimits, JOINT_NAMES};
use crate::timelaw::chain_rule;
use crate::PlanError;

/// Which time law a plan runs (`options.feed_law` of the request).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedMode {
    /// The fastest law under every joint's and the process's limits (this module; issue 16).
    #[default]
    TimeOptimal,
    /// Seed 001's constant feedrate (eq. 13) with kerf's jerk-limited S-curve ramps at the
    /// request's path acceleration and jerk ([`crate::timelaw::TimeLaw`]).
    Constant,
}

impl FeedMode {
    /// The name used in requests and answers.
    pub fn as_str(self) -> &'static str {
        match self {
            FeedMode::TimeOptimal => "time_optimal",
            FeedMode::Constant => "constant",
        }
    }
}

/// Most sequential convex passes: the first linearizes the jerk rows around the second-order
/// (TOPP2-RA) profile, each further one around the previous solution (the linearization is on
/// the safe side, so each pass is feasible). Measured: case 1 at twice its feed 1.404 s after
/// one pass, 1.386 s after two; saddle r/R 0.4 1.611 s after two, 1.546 s after four.
pub const SCP_PASSES: usize = 4;

/// A further pass runs while the last one shortened the cycle by at least this fraction.
pub const SCP_GAIN: f64 = 0.005;

/// Joints of the machine.
const JOINTS: usize = 6;

/// A constraint is reported as limiting the feed at a station when it is used to at least this
/// fraction.
pub const ACTIVE_FRACTION: f64 = 0.98;

/// The time-optimal problem on one joint path.
#[derive(Debug, Clone, Copy)]
pub struct FeedProblem<'a> {
    /// Stations `s_k` (m), strictly increasing from 0 to σ.
    pub stations: &'a [f64],
    /// Per station: `[q, q', q'', q''']` (derivatives in arc length), each per joint q1..q6.
    pub derivatives: &'a [[[f64; JOINTS]; 4]],
    /// Joint limits (Table 2).
    pub joints: &'a [AxisLimits; JOINTS],
    /// Largest feedrate f (m/s): the requested cruise maximum.
    pub feed: f64,
    /// Largest path acceleration (m/s²).
    pub acc: f64,
    /// Largest path jerk (m/s³).
    pub jerk: f64,
    /// Fraction of each joint's velocity, acceleration and jerk limit given to the solver, in
    /// (0, 1].
    pub margin: f64,
    /// Fraction of the process limits (feedrate, path acceleration, path jerk) given to the
    /// solver, in (0, 1].
    pub process_margin: f64,
    /// Per station `[g, g', g'']` with `g = |dC/ds|`, the tool tip's speed per unit ṡ
    /// ([`crate::tip`]); the process limits apply to the tip, the virtual axis q₇ with
    /// `q₇' = g`. Empty: `g = 1` (the tip moves at ṡ).
    pub tip: &'a [[f64; 3]],
}

/// What limits the feed over a stretch of the path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeedLimit {
    /// Start of the stretch (m of path).
    pub s_start: f64,
    /// End of the stretch (m of path).
    pub s_end: f64,
    /// The limit: "feedrate", "path acceleration", "path jerk" or "<joint> velocity|acceleration|jerk".
    pub limited_by: String,
}

/// A solved time-optimal feed law.
#[derive(Debug, Clone, PartialEq)]
pub struct OptimalFeed {
    s: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    t: Vec<f64>,
    stationary: (usize, usize),
}

fn copp_error(stage: &str, e: CoppError) -> PlanError {
    PlanError::Solver {
        problem: "time-optimal feed (TOPP3)".into(),
        detail: format!("{stage}: {e}"),
    }
}

/// The steady-state feed a station allows: the largest constant `ṡ` at which every joint is
/// inside its velocity, acceleration and jerk limit there (`q̇ = q' ṡ`, `q̈ = q'' ṡ²`,
/// `q⃛ = q''' ṡ³`, seed 001 eq. 7 with `s̈ = s⃛ = 0`), with the joint and limit that set it.
///
/// # Returns
/// `(feed, joint index, family)`; `f64::INFINITY` and `None` when no joint moves.
pub fn steady_feed(
    derivatives: &[[f64; JOINTS]; 4],
    joints: &[AxisLimits; JOINTS],
) -> (f64, Option<(usize, ConstraintFamily)>) {
    let mut best = (f64::INFINITY, None);
    for (j, l) in joints.iter().enumerate() {
        let candidates = [
            (l.vel / derivatives[1][j].abs(), ConstraintFamily::Velocity),
            (
                (l.acc / derivatives[2][j].abs()).sqrt(),
                ConstraintFamily::Acceleration,
            ),
            (
                (l.jerk / derivatives[3][j].abs()).cbrt(),
                ConstraintFamily::Jerk,
            ),
        ];
        for (v, family) in candidates {
            if v < best.0 {
                best = (v, Some((j, family)));
            }
        }
    }
    best
}

/// Name of a constraint family as a limit ("velocity", …).
pub fn family_word(family: ConstraintFamily) -> &'static str {
    match family {
        ConstraintFamily::Velocity => "velocity",
        ConstraintFamily::Acceleration => "acceleration",
        ConstraintFamily::Jerk => "jerk",
        ConstraintFamily::Position => "position",
        ConstraintFamily::Rto => "RTO",
        ConstraintFamily::Boundary => "boundary",
        ConstraintFamily::Stroke => "stroke",
        ConstraintFamily::Allowance => "lead/tilt allowance",
    }
}

impl FeedProblem<'_> {
    fn validate(&self) -> Result<(), PlanError> {
        let n = self.stations.len();
        if n < 8 || self.derivatives.len() != n {
            return Err(PlanError::invalid(
                "feed stations",
                format!(
                    "{n} stations and {} derivative rows: need at least 8, one row per station",
                    self.derivatives.len()
                ),
            ));
        }
        if !self.stations.windows(2).all(|w| w[1] > w[0]) || self.stations[0] != 0.0 {
            return Err(PlanError::invalid(
                "feed stations",
                "must start at 0 and increase strictly",
            ));
        }
        for (name, v) in [
            ("feedrate", self.feed),
            ("feed_acceleration", self.acc),
            ("feed_jerk", self.jerk),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlanError::invalid(
                    name,
                    format!("{v} must be finite and > 0"),
                ));
            }
        }
        for m in [self.margin, self.process_margin] {
            if !(m > 0.0 && m <= 1.0) {
                return Err(PlanError::invalid(
                    "feed margin",
                    format!("{m} must be in (0, 1]"),
                ));
            }
        }
        if !self.tip.is_empty() && self.tip.len() != n {
            return Err(PlanError::invalid(
                "feed stations",
                format!("{} tip rows for {n} stations", self.tip.len()),
            ));
        }
        if self
            .derivatives
            .iter()
            .any(|d| d.iter().flatten().any(|x| !x.is_finite()))
            || self.tip.iter().flatten().any(|x| !x.is_finite())
        {
            return Err(PlanError::invalid(
                "feed stations",
                "a joint path derivative is not finite",
            ));
        }
        Ok(())
    }
}

impl OptimalFeed {
    /// Solves the time-optimal problem (module documentation).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] for malformed input (fewer than 8 stations, stations not
    /// increasing, limits not positive); [`PlanError::Solver`] when TOPP2-RA or the TOPP3 SOCP
    /// fails.
    ///
    /// # Performance
    /// One reachability pass (TOPP2-RA, O(n)) and two sparse SOCPs over `2n` unknowns.
    pub fn solve(p: &FeedProblem) -> Result<Self, PlanError> {
        p.validate()?;
        let n = p.stations.len();
        let dim = JOINTS + 1;
        let mut q = [
            DMatrix::<f64>::zeros(dim, n),
            DMatrix::<f64>::zeros(dim, n),
            DMatrix::<f64>::zeros(dim, n),
            DMatrix::<f64>::zeros(dim, n),
        ];
        for (k, (d, &s)) in p.derivatives.iter().zip(p.stations).enumerate() {
            for (order, m) in q.iter_mut().enumerate() {
                for j in 0..JOINTS {
                    m[(j, k)] = d[order][j];
                }
            }
            let g = p.tip.get(k).copied().unwrap_or([1.0, 0.0, 0.0]);
            q[0][(JOINTS, k)] = s;
            q[1][(JOINTS, k)] = g[0];
            q[2][(JOINTS, k)] = g[1];
            q[3][(JOINTS, k)] = g[2];
        }
        let m = p.margin;
        let upper = |f: &dyn Fn(&AxisLimits) -> f64, process: f64| -> Vec<f64> {
            p.joints
                .iter()
                .map(|l| f(l) * m)
                .chain(std::iter::once(process))
                .collect()
        };
        let pm = p.process_margin;
        let vmax = upper(&|l| l.vel, p.feed * pm);
        let amax = upper(&|l| l.acc, p.acc * pm);
        let jmax = upper(&|l| l.jerk, p.jerk * pm);
        let neg = |v: &[f64]| v.iter().map(|x| -x).collect::<Vec<f64>>();
        let (vmin, amin, jmin) = (neg(&vmax), neg(&amax), neg(&jmax));
        let mut robot = Robot::with_capacity(dim, n);
        let dddq = q[3].as_view();
        robot
            .with_s(p.stations)
            .and_then(|r| {
                r.with_q(
                    &q[0].as_view(),
                    &q[1].as_view(),
                    &q[2].as_view(),
                    Some(&dddq),
                    0,
                )
            })
            .and_then(|r| r.with_axial_velocity((vmax.as_slice(), n), (vmin.as_slice(), n), 0))
            .and_then(|r| r.with_axial_acceleration((amax.as_slice(), n), (amin.as_slice(), n), 0))
            .and_then(|r| r.with_axial_jerk((jmax.as_slice(), n), (jmin.as_slice(), n), 0))
            .map_err(|e| copp_error("constraints", e.into()))?;
        let a_ra = {
            let problem = Topp2ProblemBuilder::new(&robot, (0, n - 1), (0.0, 0.0))
                .build()
                .map_err(|e| copp_error("TOPP2 problem", e))?;
            let options = ReachSet2OptionsBuilder::new()
                .build()
                .map_err(|e| copp_error("TOPP2 options", e))?;
            topp2_ra(&problem, &options).map_err(|e| copp_error("TOPP2-RA", e))?
        };
        robot
            .constraints
            .amax_substitute(&a_ra, 0)
            .map_err(|e| copp_error("TOPP2 bound", e.into()))?;
        let options = ClarabelOptionsBuilder::new()
            .allow_almost_solved(true)
            .build()
            .map_err(|e| copp_error("SOCP options", e))?;
        // The last pass's profile and its times t(s).
        let mut solved: Option<(Topp3Profile, Vec<f64>)> = None;
        // Sequential convex passes: each relinearizes the jerk rows around the previous
        // solution (copp's SCP refinement) until the time gains less than SCP_GAIN.
        for _ in 0..SCP_PASSES {
            let reference = solved
                .as_ref()
                .map_or(a_ra.as_slice(), |(p, _)| p.a.as_slice());
            let problem =
                Topp3ProblemBuilder::new(&mut robot, 0, reference, (0.0, 0.0), (0.0, 0.0))
                    .build_with_linearization()
                    .map_err(|e| copp_error("TOPP3 problem", e))?;
            let profile =
                topp3_socp(&problem, &options).map_err(|e| copp_error("TOPP3-SOCP", e))?;
            let (duration, t) = s_to_t_topp3(p.stations, profile.as_parts(), 0.0)
                .map_err(|e| copp_error("t(s)", e))?;
            let before = solved.as_ref().map_or(f64::INFINITY, |(_, t)| {
                t.last().copied().unwrap_or(f64::INFINITY)
            });
            solved = Some((profile, t));
            if (before - duration) / duration < SCP_GAIN {
                break;
            }
        }
        let (profile, t) = solved.ok_or_else(|| PlanError::Solver {
            problem: "time-optimal feed (TOPP3)".into(),
            detail: "no SOCP pass ran".into(),
        })?;
        let (a, b, stationary) = profile.into_parts();
        Ok(Self {
            s: p.stations.to_vec(),
            a,
            b,
            t,
            stationary,
        })
    }

    /// Duration T (s).
    pub fn duration(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0)
    }

    /// The largest feed reached (m/s).
    pub fn peak_feed(&self) -> f64 {
        self.a.iter().fold(0.0f64, |m, &a| m.max(a.max(0.0).sqrt()))
    }

    /// `[s, ṡ, s̈, s⃛]` at each of `times` (increasing, within `[0, T]`).
    ///
    /// # Errors
    /// [`PlanError::Solver`] when a time is outside the law or the inverse map fails.
    ///
    /// # Performance
    /// One pass over the stations and the times.
    pub fn eval_many(&self, times: &[f64]) -> Result<Vec<[f64; 4]>, PlanError> {
        let parts = (self.a.as_slice(), self.b.as_slice(), self.stationary);
        let s_t = t_to_s_topp3(
            &self.s,
            parts,
            &self.t,
            InterpolationMode::NonUniformTimeGrid(times),
        )
        .map_err(|e| copp_error("s(t)", e))?;
        let mut out = Vec::with_capacity(times.len());
        let mut k = 0usize;
        let last = self.s.len() - 1;
        let sigma = self.s[last];
        for (&time, &s) in times.iter().zip(&s_t) {
            if !s.is_finite() {
                return Err(copp_error(
                    "s(t)",
                    CoppError::InvalidInput(
                        "s(t)".into(),
                        format!("t = {time} s is outside the law"),
                    ),
                ));
            }
            while k + 1 < last && time > self.t[k + 1] {
                k += 1;
            }
            out.push(self.state(k, time, s.clamp(0.0, sigma)));
        }
        Ok(out)
    }

    /// `[s, ṡ, s̈, s⃛]` in interval `k` at time `time` and position `s`.
    fn state(&self, k: usize, time: f64, s: f64) -> [f64; 4] {
        let n = self.s.len() - 1;
        let (head, tail) = self.stationary;
        // Constant jerk from (or to) rest, copp's stationary blocks: s − s_end = D τ³ with
        // τ = t − t_end, D = a_m^{3/2} / (27 (s_m − s_end)²) from the block's inner node m.
        let rest = |m: usize, end: usize| {
            let (am, sm) = (self.a[m], self.s[m] - self.s[end]);
            let d = am * am.sqrt() / (27.0 * sm * sm);
            let tau = time - self.t[end];
            [s, 3.0 * d * tau * tau, 6.0 * d * tau, 6.0 * d]
        };
        if k < head {
            return rest(head, 0);
        }
        if k >= n - tail {
            return rest(n - tail, n);
        }
        let h = self.s[k + 1] - self.s[k];
        let c = (self.b[k + 1] - self.b[k]) / h;
        let last_ordinary = k + 1 == n - tail;
        // copp's anchor: the last ordinary interval takes its right end, an interval starting
        // at rest its right end too (both give the same a up to rounding).
        let right = self.a[k + 1] != 0.0 && (last_ordinary || self.a[k] == 0.0);
        let a = if right {
            let d = self.s[k + 1] - s;
            self.a[k + 1] - 2.0 * self.b[k + 1] * d + c * d * d
        } else {
            let d = s - self.s[k];
            self.a[k] + 2.0 * self.b[k] * d + c * d * d
        };
        let v = a.max(0.0).sqrt();
        let b = self.b[k] + c * (s - self.s[k]);
        [s, v, b, c * v]
    }

    /// Where the feed is limited and by what: at every station the most used constraint (used
    /// to at least [`ACTIVE_FRACTION`]), merged into stretches.
    pub fn limits(&self, p: &FeedProblem) -> Vec<FeedLimit> {
        let n = self.s.len();
        let mut out: Vec<FeedLimit> = Vec::new();
        for k in 0..n {
            let kk = k.min(n - 2);
            let c = (self.b[kk + 1] - self.b[kk]) / (self.s[kk + 1] - self.s[kk]);
            // The law at the station: [s, ṡ, s̈, s⃛] with s⃛ = c ṡ.
            let v = self.a[k].max(0.0).sqrt();
            let law = [self.s[k], v, self.b[k], c * v];
            // Seed 001 eq. 7 with derivatives in arc length (σ = 1): [·, rate, acc, jerk].
            let motion = |d: [f64; 4]| chain_rule(d, law, 1.0);
            let g = p.tip.get(k).copied().unwrap_or([1.0, 0.0, 0.0]);
            let tip = motion([0.0, g[0], g[1], g[2]]);
            let pm = p.process_margin;
            let mut best = (tip[1] / (pm * p.feed), "feedrate".to_string());
            let mut consider = |x: f64, name: String| {
                if x > best.0 {
                    best = (x, name);
                }
            };
            consider(tip[2].abs() / (pm * p.acc), "path acceleration".into());
            consider(tip[3].abs() / (pm * p.jerk), "path jerk".into());
            // The joints against the limits the solver had (margin included).
            let m = p.margin;
            let d = &p.derivatives[k];
            for (j, l) in p.joints.iter().enumerate() {
                let name = JOINT_NAMES[j];
                let q = motion([d[0][j], d[1][j], d[2][j], d[3][j]]);
                consider(q[1].abs() / (m * l.vel), format!("{name} velocity"));
                consider(q[2].abs() / (m * l.acc), format!("{name} acceleration"));
                consider(q[3].abs() / (m * l.jerk), format!("{name} jerk"));
            }
            if best.0 < ACTIVE_FRACTION {
                continue;
            }
            match out.last_mut() {
                Some(last) if last.limited_by == best.1 && k > 0 && last.s_end == self.s[k - 1] => {
                    last.s_end = self.s[k];
                }
                _ => out.push(FeedLimit {
                    s_start: self.s[k],
                    s_end: self.s[k],
                    limited_by: best.1,
                }),
            }
        }
        out
    }
}
