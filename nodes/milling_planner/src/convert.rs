//! Messages ⇄ planner types: `kerf_msgs/msg/MillRequest` → [`kerf_millplan::MillRequest`]
//! (with the `has_*` flags of the `.msg` file), [`MillPlanOutput`] and [`MillPlanError`] →
//! `kerf_msgs/msg/MillPlan`.
//!
//! A plan is published AS THE ROBOT RUNS IT ([`kerf_millplan::Executed`]): the trajectory is
//! the planner's executed one (from rest to rest, time-scaled so that its quintic Hermite
//! interpolation stays within every joint's velocity and acceleration limit), and the
//! segments and totals of the `MillPlan` are those of the plan at the feeds that trajectory
//! runs (|μ|max and reward re-evaluated where the joints' limits lowered a feed). The message
//! text gives the totals at the planned feeds next to them ([`success_message`]).
//!
//! Nothing here checks the values themselves: [`kerf_millplan::MillRequest::validate_with`]
//! (called by the planner) does that and names the field. The conversion only maps the
//! message's groups onto the request's optional sections and refuses what the message
//! contract forbids and the request form cannot express (a `policy_file` for `dp` or
//! `naive`).

use kerf_millplan::{
    planner::status,
    request::{
        RequestInitial, RequestLimits, RequestProcess, RequestStepBounds, RequestTolerances,
    },
    MillPlanError, MillPlanOutput, MillRequest, PlannerKind,
};
use kerf_msgs::numbers::{check_value, Number, NumberError, NumberFields, NumberRules};
use kerf_msgs::{msg, trajectory_msgs::JointTrajectory};

/// Status of a request refused because the queue is full (`MillPlan::QUEUE_FULL`; the
/// planner library has no such status, it belongs to the node).
pub const QUEUE_FULL: u8 = msg::MillPlan::QUEUE_FULL;

/// A count for a `uint32` field, saturating at `u32::MAX` (never reached by a plan that fits
/// in memory).
fn to_u32(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
}

/// The planner name of a request's `planner` field as the message means it: empty = `best`.
pub fn planner_name(field: &str) -> &str {
    if field.is_empty() {
        msg::MillRequest::PLANNER_BEST
    } else {
        field
    }
}

/// A number outside its declared rule ([`kerf_msgs::numbers`]) as the planner's error:
/// INVALID_REQUEST naming the message's field, e.g. `invalid spindle_max_rpm: 1e308 must be in
/// (0, 100000] rpm ...`.
pub fn number_error(e: NumberError) -> MillPlanError {
    MillPlanError::InvalidConfig {
        name: e.field,
        reason: format!("{} {}", e.value, e.rule),
    }
}

/// Checks every numeric field of a `MillRequest` message against its declared rule
/// ([`kerf_msgs::numbers::mill`]).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] naming the first field outside its rule.
pub fn check_numbers(m: &msg::MillRequest) -> Result<(), MillPlanError> {
    m.check_numbers().map_err(number_error)
}

/// Checks every number of a YAML request ([`MillRequest`]) against the rule of its
/// `MillRequest` message field, named as in the message (`limits.spindle_rpm[1]` is
/// `spindle_max_rpm`, `initial.g` is `initial_g`, …).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] naming the first field outside its rule.
pub fn check_text_numbers(r: &MillRequest) -> Result<(), MillPlanError> {
    let rules = <msg::MillRequest as NumberRules>::SECTIONS;
    let float = |path: &str, v: f64| check_value(rules, path, Number::Float(v));
    let opt = |path: &str, v: Option<f64>| v.map_or(Ok(()), |v| float(path, v));
    let count = |path: &str, v: usize| {
        let value = i128::try_from(v).unwrap_or(i128::MAX);
        let max = i128::from(u32::MAX);
        check_value(rules, path, Number::Int { value, min: 0, max })
    };
    let pair = |names: [&str; 2], v: Option<[f64; 2]>| -> Result<(), NumberError> {
        if let Some([lo, hi]) = v {
            float(names[0], lo)?;
            float(names[1], hi)?;
        }
        Ok(())
    };
    let run = || -> Result<(), NumberError> {
        for (i, p) in r.points.iter().enumerate() {
            for (c, v) in ["x", "y", "z"].iter().zip(p) {
                float(&format!("points[{i}].{c}"), *v)?;
            }
        }
        if let Some(n) = r.segments {
            count("segments", n)?;
        }
        if let Some(p) = &r.process {
            count("teeth", p.teeth)?;
            float("tool_radius", p.tool_radius)?;
            float("axial_depth", p.axial_depth)?;
            float("kt", p.kt)?;
            float("kn", p.kn)?;
            float("entry_angle", p.entry_angle)?;
            float("exit_angle", p.exit_angle)?;
        }
        if let Some(l) = &r.limits {
            pair(["spindle_min_rpm", "spindle_max_rpm"], l.spindle_rpm)?;
            pair(["feed_min", "feed_max"], l.feed)?;
            pair(["g_min", "g_max"], l.redundancy_angle)?;
            if let Some(s) = &l.step_bounds {
                opt("max_spindle_step_rpm", s.spindle_rpm)?;
                opt("max_feed_step", s.feed)?;
                opt("max_g_step", s.redundancy_angle)?;
            }
        }
        if let Some(i) = &r.initial {
            opt("initial_spindle_rpm", i.spindle_rpm)?;
            opt("initial_feed", i.feed)?;
            opt("initial_g", i.g)?;
        }
        opt("time_budget", r.time_budget)?;
        if let Some(t) = &r.tolerances {
            opt("path_tolerance", t.path_tolerance)?;
            opt("min_condition_indicator", t.min_condition_indicator)?;
        }
        Ok(())
    };
    run().map_err(number_error)
}

/// Converts a `MillRequest` message to the planner's request.
///
/// * `points` → `points`; `segments` 0 → the cell's (`None`).
/// * `has_process` → `process` (every field of the group), else `None` (the cell's).
/// * `has_limits` → `limits` with every range and step bound given, else `None`.
/// * `has_initial_state` → `initial` with the three values, else `None` (seed 004's IVP).
/// * `planner` "" → `best`; `policy_file` "" → `None` (the node's default policy).
/// * `allow_chatter` → `allow_chatter`; `entry` "" → `None` (run_in).
/// * `has_tolerances` → `tolerances` with both values (a `min_condition_indicator` of 0 is no
///   minimum), else `None` (the node's).
///
/// Every value is passed on unchanged for the planner's validation (NaN, min > max, …).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] naming `policy_file` when one is given for `dp`, `naive`,
/// `greedy` or `greedy_best_g`, which use no policy (`MillRequest.msg`).
pub fn request_from_msg(m: &msg::MillRequest) -> Result<MillRequest, MillPlanError> {
    let planner = planner_name(&m.planner).to_string();
    let policy_file = if m.policy_file.is_empty() {
        None
    } else {
        Some(m.policy_file.clone())
    };
    if let (
        Ok(
            kind @ (PlannerKind::Dp
            | PlannerKind::Naive
            | PlannerKind::Greedy
            | PlannerKind::GreedyBestG),
        ),
        Some(p),
    ) = (PlannerKind::parse(&planner), &policy_file)
    {
        return Err(MillPlanError::InvalidConfig {
            name: "policy_file".to_string(),
            reason: format!(
                "{p:?} was given for planner {}, which uses no policy; leave policy_file empty",
                kind.name()
            ),
        });
    }
    let process = m.has_process.then(|| RequestProcess {
        // u32 always fits usize on the targets kerf supports.
        teeth: usize::try_from(m.teeth).unwrap_or(usize::MAX),
        tool_radius: m.tool_radius,
        axial_depth: m.axial_depth,
        kt: m.kt,
        kn: m.kn,
        entry_angle: m.entry_angle,
        exit_angle: m.exit_angle,
    });
    let limits = m.has_limits.then_some(RequestLimits {
        spindle_rpm: Some([m.spindle_min_rpm, m.spindle_max_rpm]),
        feed: Some([m.feed_min, m.feed_max]),
        redundancy_angle: Some([m.g_min, m.g_max]),
        step_bounds: Some(RequestStepBounds {
            spindle_rpm: Some(m.max_spindle_step_rpm),
            feed: Some(m.max_feed_step),
            redundancy_angle: Some(m.max_g_step),
        }),
    });
    let initial = m.has_initial_state.then_some(RequestInitial {
        spindle_rpm: Some(m.initial_spindle_rpm),
        feed: Some(m.initial_feed),
        g: Some(m.initial_g),
    });
    Ok(MillRequest {
        start: kerf_approach::StartSpec::from_fields(&m.start, &m.start_positions).map_err(
            |reason| MillPlanError::InvalidConfig {
                name: "start".into(),
                reason,
            },
        )?,
        request_id: m.request_id.clone(),
        points: m.points.iter().map(|p| [p.x, p.y, p.z]).collect(),
        segments: (m.segments != 0).then(|| usize::try_from(m.segments).unwrap_or(usize::MAX)),
        process,
        limits,
        initial,
        planner,
        allow_chatter: m.allow_chatter,
        entry: (!m.entry.is_empty()).then(|| m.entry.clone()),
        policy_file,
        time_budget: (m.time_budget != 0.0).then_some(m.time_budget),
        tolerances: m.has_tolerances.then_some(RequestTolerances {
            path_tolerance: Some(m.path_tolerance),
            min_condition_indicator: Some(m.min_condition_indicator),
        }),
    })
}

/// Checks that a trajectory is publishable: six joint names, one position, velocity and
/// acceleration per joint and point, finite values, times from 0 strictly increasing, and at
/// rest (every velocity and acceleration zero) at the first and the last point (an executor
/// cannot step the velocity at the start, and kerf's refuses a trajectory that does not end
/// at rest).
///
/// # Errors
/// A sentence naming the first defect (a planner bug: the node answers INTERNAL_ERROR rather
/// than publish it).
pub fn check_trajectory(t: &kerf_millplan::JointTrajectory) -> Result<(), String> {
    let t = &t.request;
    if t.joint_names.len() != 6 {
        return Err(format!(
            "{} joint names {:?}, expected 6",
            t.joint_names.len(),
            t.joint_names
        ));
    }
    if t.points.len() < 2 {
        return Err(format!(
            "{} trajectory point(s); at least 2 are needed",
            t.points.len()
        ));
    }
    if t.points.first().map(|p| p.time_from_start) != Some(0.0) {
        return Err("the first point is not at time 0".to_string());
    }
    for (k, w) in t.points.windows(2).enumerate() {
        let (a, b) = (w[0].time_from_start, w[1].time_from_start);
        if !(b.is_finite() && b > a) {
            return Err(format!(
                "times do not increase at point {}: {a} then {b} s",
                k + 1
            ));
        }
    }
    for (k, p) in t.points.iter().enumerate() {
        for (what, values) in [
            ("position", &p.positions),
            ("velocity", &p.velocities),
            ("acceleration", &p.accelerations),
        ] {
            if values.len() != t.joint_names.len() {
                return Err(format!(
                    "{} {what} value(s) at point {k} (t = {} s) for {} joints",
                    values.len(),
                    p.time_from_start,
                    t.joint_names.len()
                ));
            }
            if let Some(j) = values.iter().position(|v| !v.is_finite()) {
                return Err(format!(
                    "{what} of {} at point {k} (t = {} s) is {}",
                    t.joint_names.get(j).map(String::as_str).unwrap_or("?"),
                    p.time_from_start,
                    values[j]
                ));
            }
        }
    }
    let last = t.points.len() - 1;
    for (k, end) in [(0, "first"), (last, "last")] {
        let p = &t.points[k];
        for (what, values, unit) in [
            ("velocity", &p.velocities, "rad/s"),
            ("acceleration", &p.accelerations, "rad/s^2"),
        ] {
            if let Some(j) = values.iter().position(|v| *v != 0.0) {
                return Err(format!(
                    "the {end} point (t = {} s) is not at rest: {what} of {} is {} {unit}",
                    p.time_from_start,
                    t.joint_names.get(j).map(String::as_str).unwrap_or("?"),
                    values[j]
                ));
            }
        }
    }
    Ok(())
}

/// The trajectory the robot runs as a `trajectory_msgs/JointTrajectory`: the planner's
/// executed trajectory ([`kerf_millplan::Executed`]: `out.executed.scaling.trajectory`, from
/// rest to rest and time-scaled to the joints' velocity and acceleration limits) as it is —
/// its executor form ([`kerf_millplan::JointTrajectory::request`], a
/// `kerf_executor::TrajectoryRequest`) converted by [`kerf_ros::planner::trajectory_msg`]: the planner's joint names (`joint_1` …
/// `joint_6`), one point per trajectory point with its positions, velocities, accelerations
/// and time (the executor interpolates quintic Hermite segments; the harness's framing needs
/// the accelerations, issue 27).
/// `header.stamp` is zero (the planner's `start_time` is `None`: the executor starts it on
/// receipt).
///
/// # Errors
/// As [`check_trajectory`], or a time that does not fit a `Duration`.
pub fn trajectory_msg(t: &kerf_millplan::JointTrajectory) -> Result<JointTrajectory, String> {
    check_trajectory(t)?;
    kerf_ros::planner::trajectory_msg(&t.request)
}

/// The `MillSegment` messages of a plan AS EXECUTED (`out.executed.plan`: the feed the robot
/// runs each segment at, |μ|max and reward re-evaluated where that feed differs from the
/// planned one, the segment's time on the published trajectory — the start and stop from rest
/// included in the first and the last), in path order.
pub fn segments_msg(out: &MillPlanOutput) -> Vec<msg::MillSegment> {
    out.executed
        .plan
        .segments
        .iter()
        .map(|s| msg::MillSegment {
            index: to_u32(s.segment),
            spindle_rpm: s.rpm,
            feed: s.feed,
            redundancy_angle: s.g,
            mu_max: s.spectral_radius,
            condition_indicator: s.condition_indicator,
            time: s.time,
            reward: s.reward.total,
            joint_positions: s.joints.to_vec(),
        })
        .collect()
}

/// The chatter part of [`success_message`] for a plan as executed (`executed`) and as
/// planned (`planned`).
fn chatter_text(out: &MillPlanOutput) -> String {
    let v = &out.executed.chatter;
    if !out.executed.chatters() {
        return if out.executed.plan.chatter_free {
            "chatter-free at every executed sample in the material".to_string()
        } else {
            "no executed sample chatters; some cached segment's |mu|max is within the indicator \
             cache's error bound of 1"
                .to_string()
        };
    }
    let at = v.first_chatter.or(v.worst).map_or(String::new(), |s| {
        format!(
            " from segment {} (|mu|max {:.4} at {:.2} mm/s, {:.0} rpm)",
            s.segment,
            s.spectral_radius,
            s.feed * 1e3,
            s.rpm
        )
    });
    format!(
        "CHATTERS as executed{at} in {} segment(s); answered only because the request allows \
         chatter (allow_chatter): kerf does not send this trajectory to the robot",
        v.chattering_segments.len().max(1)
    )
}

/// A one-line summary of a successful plan, for the `message` field and logs: the totals AS
/// EXECUTED (`out.executed`: what the robot runs, the published trajectory and the `MillPlan`
/// totals) next to those at the planned feeds (`out.plan`), how many trajectory intervals the
/// joints' limits slowed, the indicator cache, the planning time and IK branch jumps.
pub fn success_message(out: &MillPlanOutput) -> String {
    let (p, e, scaling) = (&out.plan, &out.executed.plan, &out.executed.scaling);
    let policy = out
        .policy_file
        .as_ref()
        .map(|f| format!(" (policy {})", f.display()))
        .unwrap_or_default();
    let jumps = if out.branch_jumps.is_empty() {
        String::new()
    } else {
        let list: Vec<String> = out
            .branch_jumps
            .iter()
            .map(|j| format!("point {} {} {:.3} rad", j.index, j.joint, j.step))
            .collect();
        format!(
            "; WARNING: {} IK branch jump(s) in the trajectory: {}",
            list.len(),
            list.join(", ")
        )
    };
    let lowest_feed = e
        .segments
        .iter()
        .map(|s| s.feed)
        .fold(f64::INFINITY, f64::min);
    let executed_cache = match out.executed.cached_segments.len() {
        0 => String::new(),
        k => format!(
            "; as executed, |mu|max of {k} of {} segments from the indicator cache",
            e.segments.len()
        ),
    };
    format!(
        "planned {} segments with {}{policy}: machining time {:.3} s as executed from rest to \
         rest ({:.3} s at the planned feeds; {} of {} segments slowed to the joints' \
         velocity/acceleration/jerk limits, lowest feed {:.4} m/s; {} trajectory points, tool tip \
         within {:.4} mm of the path and {:.4} mm of the plane at every {} ms control period, \
         tolerance {:.4} mm), \
         max |mu| {:.4} as executed \
         ({:.4} as planned) ({}), min condition indicator {:.3}, total reward {:.3} as executed \
         ({:.3} as planned); indicator cache {} for planning; {}{executed_cache}; planning took \
         {:.3} s{jumps}; {}{}",
        e.segments.len(),
        out.planner.name(),
        e.total_time,
        p.total_time,
        scaling.slowed_segments(),
        scaling.segment_slowdown.len(),
        lowest_feed,
        scaling.trajectory.points().len(),
        out.executed.scaling.deviation.max_off_path * 1e3,
        out.executed.scaling.deviation.max_off_plane * 1e3,
        out.executed.settings.control_period * 1e3,
        out.executed.settings.path_tolerance * 1e3,
        e.max_spectral_radius,
        p.max_spectral_radius,
        chatter_text(out),
        e.min_condition_indicator,
        e.total_reward,
        p.total_reward,
        if out.cache_used { "used" } else { "not used" },
        out.indicator.note.trim_end_matches('.'),
        out.planning_seconds,
        out.judge_text(),
        if out.candidates.is_empty() {
            String::new()
        } else {
            format!("; {}", out.candidates_text())
        },
    )
}

/// The `MillPlan` message of a successful plan (status SUCCESS): the executed trajectory
/// ([`trajectory_msg`]), and the segments and totals of the plan as executed
/// (`out.executed.plan`, consistent with that trajectory: `machining_time` is its time in the
/// material, `trajectory_duration` its duration from rest to rest with the run-in and run-out).
///
/// A plan whose executed trajectory fails [`check_trajectory`] is answered INTERNAL_ERROR
/// with the defect instead, so a planner bug never reaches the executor.
pub fn output_to_msg(out: &MillPlanOutput) -> msg::MillPlan {
    let planner = out.planner.name();
    let trajectory = match trajectory_msg(&out.executed.scaling.trajectory) {
        Ok(t) => t,
        Err(reason) => {
            return failure_msg(
                &out.request_id,
                planner,
                status::INTERNAL_ERROR,
                format!("the planner produced an unusable trajectory: {reason}"),
            )
        }
    };
    let p = &out.executed.plan;
    let v = &out.executed.chatter;
    msg::MillPlan {
        request_id: out.request_id.clone(),
        // A chattering plan reaches here only when the request allows chatter.
        status: if !out.executed.chatters() {
            status::SUCCESS
        } else {
            status::CHATTER
        },
        message: success_message(out),
        planner: planner.to_string(),
        trajectory,
        segments: segments_msg(out),
        machining_time: p.total_time,
        chatter_free: p.chatter_free,
        max_mu: p.max_spectral_radius,
        min_condition_indicator: p.min_condition_indicator,
        total_reward: p.total_reward,
        max_path_deviation: out.executed.scaling.deviation.max_off_path,
        max_plane_deviation: out.executed.scaling.deviation.max_off_plane,
        path_tolerance: out.executed.settings.path_tolerance,
        min_condition_indicator_path: out.executed.scaling.min_condition_indicator.0,
        min_condition_arc_length: out.executed.scaling.min_condition_indicator.1,
        // Set by the planner-node harness when it frames the plan (issue 27).
        stretches: msg::PlanStretches::default(),
        trajectory_duration: out.executed.scaling.duration(),
        run_in: out.executed.scaling.run_in,
        run_out: out.executed.scaling.run_out,
        judged_samples: to_u32(v.samples),
        judge_evaluations: to_u32(v.evaluations),
        candidates: out
            .candidates
            .iter()
            .map(|c| msg::MillCandidate {
                planner: c.planner.name().to_string(),
                status: c.status,
                message: c.message.clone(),
                trajectory_duration: c.duration,
                chatter_free: c.chatter_free,
                max_mu: c.max_spectral_radius,
                min_condition_indicator: c.min_condition_indicator,
            })
            .collect(),
    }
}

/// A `MillPlan` that carries only the request id, planner, status and message (everything
/// else empty or zero).
pub fn failure_msg(
    request_id: &str,
    planner: &str,
    status: u8,
    message: impl Into<String>,
) -> msg::MillPlan {
    msg::MillPlan {
        request_id: request_id.to_string(),
        status,
        message: message.into(),
        planner: planner.to_string(),
        ..msg::MillPlan::default()
    }
}

/// The planner field of an answer to a request whose `planner` text is `field`: the name
/// when it is a planner, else empty.
pub fn answer_planner(field: &str) -> &'static str {
    PlannerKind::parse(planner_name(field))
        .map(|k| k.name())
        .unwrap_or("")
}

/// The `MillPlan` of a planner error: status from [`kerf_millplan::status_of`], message the
/// error's text.
pub fn error_to_msg(request_id: &str, planner: &str, err: &MillPlanError) -> msg::MillPlan {
    failure_msg(
        request_id,
        answer_planner(planner),
        kerf_millplan::status_of(err),
        err.to_string(),
    )
}
