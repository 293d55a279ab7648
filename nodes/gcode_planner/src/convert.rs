//! Messages to requests and plans to messages.

use kerf_gcodeplan::{GcodePlan, GcodePlanError, GcodeRequest, LimitOverrides, RunKind};
use kerf_msgs::msg;
use kerf_msgs::numbers::{check_value, Number, NumberError, NumberFields, NumberRules};

/// The status of a planner error.
///
/// | error | status |
/// |---|---|
/// | reader error, a path that cannot be smoothed, an empty program | PROGRAM_ERROR |
/// | a point out of reach | UNREACHABLE |
/// | a bad setting or field, too many points, too many lines, an arc needing too many chords | INVALID_REQUEST |
/// | the time budget ran out | TIMEOUT |
/// | the memory budget ran out | RESOURCE_LIMIT |
/// | cancelled, not executable | INTERNAL_ERROR |
pub fn status_of(e: &GcodePlanError) -> u8 {
    match e {
        // The line limit is the planner's, like its most points: the request asks too much.
        GcodePlanError::Program(kerf_gcodeplan::GcodeError::TooManyLines { .. }) => {
            msg::GcodePlan::INVALID_REQUEST
        }
        GcodePlanError::Program(_) | GcodePlanError::Path { .. } | GcodePlanError::Empty { .. } => {
            msg::GcodePlan::PROGRAM_ERROR
        }
        GcodePlanError::Unreachable { .. } => msg::GcodePlan::UNREACHABLE,
        GcodePlanError::InvalidSetting { .. }
        | GcodePlanError::InvalidRequest { .. }
        | GcodePlanError::TooManyPoints { .. }
        | GcodePlanError::Arc { .. } => msg::GcodePlan::INVALID_REQUEST,
        GcodePlanError::Interrupted(kerf_budget::Interrupt::TimedOut { .. }) => {
            msg::GcodePlan::TIMEOUT
        }
        GcodePlanError::Interrupted(kerf_budget::Interrupt::OverMemory { .. }) => {
            msg::GcodePlan::RESOURCE_LIMIT
        }
        GcodePlanError::Interrupted(_) | GcodePlanError::NotExecutable { .. } => {
            msg::GcodePlan::INTERNAL_ERROR
        }
    }
}

/// The program line an error names (0 when none): every error of a program line (the
/// reader's, the line limit's, an arc's, a motion's) carries it ([`GcodePlanError::line`]).
pub fn error_line(e: &GcodePlanError) -> u32 {
    u32::try_from(e.line()).unwrap_or(u32::MAX)
}

/// A number outside its declared rule ([`kerf_msgs::numbers`]) as the planner's error:
/// INVALID_REQUEST naming the message's field, e.g. `max_feed: 5e-324 must not be denormal`.
pub fn number_error(e: NumberError) -> GcodePlanError {
    GcodePlanError::InvalidRequest {
        field: e.field,
        reason: format!("{} {}", e.value, e.rule),
    }
}

/// Checks every numeric field of a `GcodeRequest` message against its declared rule
/// ([`kerf_msgs::numbers::gcode`]).
///
/// # Errors
/// [`GcodePlanError::InvalidRequest`] naming the first field outside its rule.
pub fn check_numbers(m: &msg::GcodeRequest) -> Result<(), GcodePlanError> {
    m.check_numbers().map_err(number_error)
}

/// Checks every number of a YAML request ([`GcodeRequest`]) against the rule of its
/// `GcodeRequest` message field, named as in the message (`limits.max_feed` is `max_feed`,
/// `origin[1]` is `origin.y`). A value given is used, so its full rule applies: a NaN
/// `redundancy_angle` is refused on either machine.
///
/// # Errors
/// [`GcodePlanError::InvalidRequest`] naming the first field outside its rule.
pub fn check_text_numbers(r: &GcodeRequest) -> Result<(), GcodePlanError> {
    let rules = <msg::GcodeRequest as NumberRules>::SECTIONS;
    let opt = |path: &str, v: Option<f64>| {
        v.map_or(Ok(()), |v| check_value(rules, path, Number::Float(v)))
    };
    let run = || -> Result<(), NumberError> {
        opt("tolerance", r.tolerance)?;
        if let Some(l) = &r.limits {
            opt("max_feed", l.max_feed)?;
            opt("tangential_acceleration", l.tangential_acceleration)?;
            opt("tangential_jerk", l.tangential_jerk)?;
            opt("normal_acceleration", l.normal_acceleration)?;
            opt("normal_jerk", l.normal_jerk)?;
            opt("chord_error", l.chord_error)?;
            opt("contour_error", l.contour_error)?;
        }
        opt("rapid_feed", r.rapid_feed)?;
        if let Some(o) = r.origin {
            for (c, v) in ["x", "y", "z"].iter().zip(o) {
                opt(&format!("origin.{c}"), Some(v))?;
            }
        }
        opt("redundancy_angle", r.redundancy_angle)?;
        opt("standoff_axis", r.standoff_axis)?;
        opt("time_budget", r.time_budget)
    };
    run().map_err(number_error)
}

/// A request message as a [`GcodeRequest`]: empty strings and zeros are "not given" where
/// the message says so; groups are read when their `has_*` flag is set.
///
/// # Errors
/// [`GcodePlanError::InvalidSetting`] for both or neither of `program` and `program_uri`
/// (checked again by the planner, named here for the message's field names).
pub fn request_from_msg(m: &msg::GcodeRequest) -> Result<GcodeRequest, GcodePlanError> {
    let given = |v: f64| if v == 0.0 { None } else { Some(v) };
    let program = (!m.program.is_empty()).then(|| m.program.clone());
    let program_file = (!m.program_uri.is_empty()).then(|| m.program_uri.clone());
    if program.is_some() == program_file.is_some() {
        return Err(GcodePlanError::InvalidRequest {
            field: "program / program_uri".to_string(),
            reason: "exactly one must be non-empty".to_string(),
        });
    }
    Ok(GcodeRequest {
        request_id: m.request_id.clone(),
        machine: m.machine.clone(),
        program,
        program_file,
        tolerance: given(m.tolerance),
        method: (!m.method.is_empty()).then(|| m.method.clone()),
        feed_method: (!m.feed_method.is_empty()).then(|| m.feed_method.clone()),
        limits: m.has_limits.then_some(LimitOverrides {
            max_feed: Some(m.max_feed),
            tangential_acceleration: Some(m.tangential_acceleration),
            tangential_jerk: Some(m.tangential_jerk),
            normal_acceleration: Some(m.normal_acceleration),
            normal_jerk: Some(m.normal_jerk),
            chord_error: Some(m.chord_error),
            contour_error: Some(m.contour_error),
        }),
        rapid_feed: given(m.rapid_feed),
        origin: m
            .has_placement
            .then_some([m.origin.x, m.origin.y, m.origin.z]),
        redundancy_angle: (m.has_placement && m.machine == msg::GcodeRequest::MACHINE_IRB6660)
            .then_some(m.redundancy_angle),
        standoff_axis: (m.has_placement && m.machine != msg::GcodeRequest::MACHINE_IRB6660)
            .then_some(m.standoff_axis),
        time_budget: given(m.time_budget),
        start: kerf_approach::StartSpec::from_fields(&m.start, &m.start_positions).map_err(
            |reason| GcodePlanError::InvalidRequest {
                field: "start".to_string(),
                reason,
            },
        )?,
    })
}

/// The method named in an answer.
pub fn method_name(request: &GcodeRequest) -> String {
    request
        .method
        .clone()
        .filter(|m| !m.is_empty())
        .unwrap_or_else(|| msg::GcodeRequest::METHOD_KERF.to_string())
}

/// A `GcodePlan` that carries only the request id, machine, method, status and message.
pub fn failure_msg(
    request_id: &str,
    machine: &str,
    method: &str,
    status: u8,
    message: impl Into<String>,
) -> msg::GcodePlan {
    msg::GcodePlan {
        request_id: request_id.to_string(),
        status,
        message: message.into(),
        machine: machine.to_string(),
        method: method.to_string(),
        ..msg::GcodePlan::default()
    }
}

/// The `GcodePlan` of a planner error.
pub fn error_to_msg(request: &GcodeRequest, machine: &str, e: &GcodePlanError) -> msg::GcodePlan {
    msg::GcodePlan {
        error_line: error_line(e),
        ..failure_msg(
            &request.request_id,
            machine,
            &method_name(request),
            status_of(e),
            e.to_string(),
        )
    }
}

/// The one-line summary of a plan.
pub fn success_message(plan: &GcodePlan) -> String {
    let cuts = plan.runs.iter().filter(|r| r.kind == RunKind::Cut).count();
    let mut text = format!(
        "{} lines, {} runs ({cuts} cutting), {} points: {:.3} s (under the path limits \
         {:.3} s, T_lb {:.3} s, ratio {:.3}), corners within {:.1} um, executed tip within \
         {:.2} um of the plan (tolerance {:.1} um)",
        plan.lines,
        plan.runs.len(),
        plan.trajectory.points.len(),
        plan.duration,
        plan.path_time,
        plan.lower_bound,
        plan.lower_bound_ratio(),
        plan.max_corner_deviation * 1e6,
        plan.max_interpolation_deviation * 1e6,
        plan.tolerance * 1e6,
    );
    if !plan.warnings.is_empty() {
        text.push_str(&format!("; {} warnings", plan.warnings.len()));
    }
    text
}

/// The `GcodePlan` of a successful plan.
///
/// # Errors
/// A sentence when the trajectory cannot be put in a message (a non-finite value).
pub fn plan_to_msg(request: &GcodeRequest, plan: &GcodePlan) -> Result<msg::GcodePlan, String> {
    let trajectory = kerf_ros::planner::trajectory_msg(&plan.trajectory)?;
    let m = plan.cut_metrics();
    let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    Ok(msg::GcodePlan {
        request_id: request.request_id.clone(),
        status: msg::GcodePlan::SUCCESS,
        message: success_message(plan),
        machine: plan.machine.clone(),
        method: method_name(request),
        trajectory,
        error_line: 0,
        machining_time: plan.duration,
        feed_time: plan.feed_time,
        lower_bound_time: plan.lower_bound,
        lower_bound_ratio: plan.lower_bound_ratio(),
        dwell_time: plan.dwell_time,
        tolerance: plan.tolerance,
        max_corner_deviation: plan.max_corner_deviation,
        max_interpolation_deviation: plan.max_interpolation_deviation,
        max_curvature: m.max_curvature,
        max_turning_angle: m.max_turning_angle,
        rms_acceleration: m.rms_acceleration,
        rms_jerk: m.rms_jerk,
        max_chord_error: m.max_chord_error,
        max_contour_error: m.max_contour_error,
        max_slowdown: plan.runs.iter().map(|r| r.slowdown).fold(1.0, f64::max),
        lines: count(plan.lines),
        runs: count(plan.runs.len()),
        cut_runs: count(plan.runs.iter().filter(|r| r.kind == RunKind::Cut).count()),
        corners: count(plan.runs.iter().map(|r| r.corners).sum()),
        arcs: count(plan.arcs),
        corner_fallbacks: count(plan.corner_fallbacks),
        tool_events: plan
            .events
            .iter()
            .map(|e| msg::GcodeToolEvent {
                time: e.time,
                tool_on: e.on,
                line: count(e.line),
            })
            .collect(),
        warnings: plan.warnings.clone(),
        // Set by the planner-node harness when it frames the plan (issue 27).
        stretches: msg::PlanStretches::default(),
    })
}
