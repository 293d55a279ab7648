//! Messages ⇄ planner types: `kerf_msgs/msg/CutRequest` → [`kerf_mjto::CutRequest`] (with the
//! "0 = default" rules of the `.msg` file), [`kerf_mjto::CutPlan`] and [`PlanError`] →
//! `kerf_msgs/msg/CutPlan`.
//!
//! Nothing here validates the path itself: [`kerf_mjto::CutRequest::validate`] does that (and
//! names the field); the conversion only applies the defaults and refuses what cannot be
//! expressed in the planner form (a zero quaternion, an index that does not fit `usize`).

use kerf_mjto::optimal_feed::FeedMode;
use kerf_mjto::{
    error::{status, CollisionReport},
    machine::JOINT_NAMES,
    plan::{Metrics, RtoRecord},
    request::{CutOptions, OrientationCorridor, PoseSpec, RtoConstraint},
    CutRequest, PlanError,
};
use kerf_msgs::numbers::{NumberError, NumberFields};
use kerf_msgs::{msg, trajectory_msgs::JointTrajectory};

/// Path acceleration limit of the feed ramps used when the message says 0 (m/s²); seed 001
/// Table 1, both cases. Equal to the default of the YAML request form (tested).
pub const DEFAULT_FEED_ACCELERATION: f64 = 8.0;

/// Path jerk limit of the feed ramps used when the message says 0 (m/s³); seed 001 Table 1.
pub const DEFAULT_FEED_JERK: f64 = 80.0;

/// `value`, or `default` when `value` is exactly 0 (the "0 = default" rule of the `.msg`).
fn or_default(value: f64, default: f64) -> f64 {
    if value == 0.0 {
        default
    } else {
        value
    }
}

/// `value` as `usize`, or `default` when 0.
fn count_or_default(value: u32, default: usize) -> usize {
    if value == 0 {
        default
    } else {
        // u32 always fits usize on the 32- and 64-bit targets kerf supports.
        usize::try_from(value).unwrap_or(usize::MAX)
    }
}

/// A count or index for a `uint32` field, saturating at `u32::MAX` (never reached by a plan
/// that fits in memory).
fn to_u32(v: usize) -> u32 {
    u32::try_from(v).unwrap_or(u32::MAX)
}

/// A number outside its declared rule ([`kerf_msgs::numbers`]) as the planner's error:
/// INVALID_REQUEST naming the message's field, e.g. `invalid request: points[1].y: NaN must be
/// finite`.
pub fn number_error(e: NumberError) -> PlanError {
    PlanError::invalid(e.field, format!("{} {}", e.value, e.rule))
}

/// Checks every numeric field of a `CutRequest` message against its declared rule
/// ([`kerf_msgs::numbers::cut`]).
///
/// # Errors
/// [`PlanError::InvalidRequest`] naming the first field outside its rule.
pub fn check_numbers(m: &msg::CutRequest) -> Result<(), PlanError> {
    m.check_numbers().map_err(number_error)
}

/// Converts a `CutRequest` message to the planner's request, applying the defaults of the
/// `.msg` file: 0 means the [`CutOptions`] default for `control_points`, `max_iterations`, the
/// GFD grid, `rto_spacing` and `rto_angle`; 0 means [`DEFAULT_FEED_ACCELERATION`] /
/// [`DEFAULT_FEED_JERK`] for the feed ramps; `has_reference_standoff == false` means the default
/// standoff; an empty `rto_constraint` means the default ([`RtoConstraint::Box`]), an empty
/// `orientation_corridor` the default ([`OrientationCorridor::Allowance`]). Every other
/// value is passed on unchanged for [`CutRequest::validate`] to check.
///
/// # Errors
/// [`PlanError::InvalidRequest`] for an all-zero `workpiece_pose.orientation` (the identity is
/// w = 1), for an `rto_constraint` other than `""`, `"equality"` and `"box"` and for an
/// `orientation_corridor` other than `""`, `"allowance"` and `"none"`.
pub fn request_from_msg(m: &msg::CutRequest) -> Result<CutRequest, PlanError> {
    let q = &m.workpiece_pose.orientation;
    if q.x == 0.0 && q.y == 0.0 && q.z == 0.0 && q.w == 0.0 {
        return Err(PlanError::invalid(
            "workpiece_pose.orientation",
            "the zero quaternion is not a rotation; send w = 1 (x = y = z = 0) for the identity",
        ));
    }
    let d = CutOptions::default();
    let options = CutOptions {
        control_points: count_or_default(m.control_points, d.control_points),
        max_iterations: count_or_default(m.max_iterations, d.max_iterations),
        gfd: kerf_mjto::request::GfdGrid {
            q4_steps: count_or_default(m.gfd_q4_steps, d.gfd.q4_steps),
            q5_steps: count_or_default(m.gfd_q5_steps, d.gfd.q5_steps),
            q6_steps: count_or_default(m.gfd_q6_steps, d.gfd.q6_steps),
            q4_half_range: or_default(m.gfd_q4_half_range, d.gfd.q4_half_range),
            q5_half_range: or_default(m.gfd_q5_half_range, d.gfd.q5_half_range),
        },
        weights: d.weights,
        rto_indices: m
            .rto_indices
            .iter()
            .map(|&i| usize::try_from(i).unwrap_or(usize::MAX))
            .collect(),
        rto_spacing: or_default(m.rto_spacing, d.rto_spacing),
        rto_angle: or_default(m.rto_angle, d.rto_angle),
        reference_standoff: if m.has_reference_standoff {
            m.reference_standoff
        } else {
            d.reference_standoff
        },
        clearance: m.clearance,
        cl_tolerance: or_default(m.cl_tolerance, d.cl_tolerance),
        feed_law: match m.feed_law.as_str() {
            "" | "time_optimal" => FeedMode::TimeOptimal,
            "constant" => FeedMode::Constant,
            other => {
                return Err(PlanError::invalid(
                    "feed_law",
                    format!("{other:?} is neither \"time_optimal\" (or empty) nor \"constant\""),
                ))
            }
        },
        rto_constraint: RtoConstraint::parse(&m.rto_constraint)?,
        orientation_corridor: OrientationCorridor::parse(&m.orientation_corridor)?,
    };
    let p = &m.workpiece_pose.position;
    Ok(CutRequest {
        start: kerf_approach::StartSpec::from_fields(&m.start, &m.start_positions)
            .map_err(|reason| PlanError::invalid("start", reason))?,
        request_id: m.request_id.clone(),
        points: m.points.iter().map(|p| [p.x, p.y, p.z]).collect(),
        axes: m.axes.iter().map(|a| [a.x, a.y, a.z]).collect(),
        feedrate: m.feedrate,
        feed_acceleration: or_default(m.feed_acceleration, DEFAULT_FEED_ACCELERATION),
        feed_jerk: or_default(m.feed_jerk, DEFAULT_FEED_JERK),
        sample_period: m.sample_period,
        max_lead_angle: m.max_lead_angle,
        max_tilt_angle: m.max_tilt_angle,
        mesh: m.mesh.clone(),
        workpiece_pose: PoseSpec {
            position: [p.x, p.y, p.z],
            orientation: [q.x, q.y, q.z, q.w],
        },
        options,
        time_budget: m.time_budget,
    })
}

/// The `CutMetrics` message of planner metrics.
pub fn metrics_to_msg(m: &Metrics) -> msg::CutMetrics {
    msg::CutMetrics {
        peak_velocity: m.peak_velocity,
        peak_acceleration: m.peak_acceleration,
        peak_jerk: m.peak_jerk,
        rms_jerk: m.rms_jerk,
        within_limits: m.within_limits,
        limit_violations: m.limit_violations.clone(),
        max_cl_error: m.max_cl_error,
        max_lead_angle: m.max_lead_angle,
        max_tilt_angle: m.max_tilt_angle,
        colliding_samples: to_u32(m.colliding_samples),
    }
}

/// The `CutRto` message of one RTO.
pub fn rto_to_msg(r: &RtoRecord) -> msg::CutRto {
    msg::CutRto {
        u: r.u,
        cl_index: to_u32(r.cl_index),
        q4: r.q4,
        q5: r.q5,
        q6: r.q6,
        inserted_at_iteration: to_u32(r.inserted_at_iteration),
    }
}

/// The `CutCollision` message of one collision report.
pub fn collision_to_msg(c: &CollisionReport) -> msg::CutCollision {
    msg::CutCollision {
        u: c.u,
        time: c.time,
        cl_index: to_u32(c.cl_index),
        links: c.links.clone(),
        reason: c.reason.clone(),
    }
}

/// Checks that a plan's samples are a usable trajectory: six joints named q1..q6, one position,
/// velocity and acceleration per joint and sample, finite values, times from 0 strictly
/// increasing.
///
/// # Errors
/// A sentence naming the first defect (a planner bug: the node answers INTERNAL_ERROR rather
/// than publish it).
pub fn check_samples(plan: &kerf_mjto::CutPlan) -> Result<(), String> {
    let n = plan.times.len();
    if n < 2 {
        return Err(format!("the plan has {n} sample(s); at least 2 are needed"));
    }
    if plan.joint_names != JOINT_NAMES {
        return Err(format!(
            "the plan's joints are {:?}, expected {JOINT_NAMES:?}",
            plan.joint_names
        ));
    }
    for (what, len) in [
        ("positions", plan.positions.len()),
        ("velocities", plan.velocities.len()),
        ("accelerations", plan.accelerations.len()),
    ] {
        if len != n {
            return Err(format!("the plan has {n} sample times but {len} {what}"));
        }
    }
    if plan.times.first().copied() != Some(0.0) {
        return Err(format!(
            "the first sample time is {:?}, expected 0",
            plan.times.first()
        ));
    }
    for (i, w) in plan.times.windows(2).enumerate() {
        if !(w[1].is_finite() && w[1] > w[0]) {
            return Err(format!(
                "sample times do not increase at sample {}: {} then {}",
                i + 1,
                w[0],
                w[1]
            ));
        }
    }
    let arrays = [
        ("position", &plan.positions),
        ("velocity", &plan.velocities),
        ("acceleration", &plan.accelerations),
    ];
    for (what, rows) in arrays {
        for (i, row) in rows.iter().enumerate() {
            if let Some(j) = row.iter().position(|v| !v.is_finite()) {
                return Err(format!(
                    "{what} of joint {} at sample {i} (t = {} s) is {}",
                    JOINT_NAMES[j], plan.times[i], row[j]
                ));
            }
        }
    }
    Ok(())
}

/// The plan's samples as a `JointTrajectory` ([`kerf_mjto::CutPlan::joint_trajectory`]
/// converted by [`kerf_ros::planner::trajectory_msg`]): joints q1..q6, one point per sample
/// with positions, velocities and accelerations, `header.stamp` zero (the executor starts it
/// on receipt).
///
/// # Errors
/// As [`check_samples`], or a sample time that does not fit a `Duration`.
pub fn trajectory_msg(plan: &kerf_mjto::CutPlan) -> Result<JointTrajectory, String> {
    check_samples(plan)?;
    kerf_ros::planner::trajectory_msg(&plan.joint_trajectory())
}

/// A one-line summary of a successful plan, for the `message` field and logs.
pub fn success_message(plan: &kerf_mjto::CutPlan) -> String {
    let duration = plan.times.last().copied().unwrap_or(0.0);
    format!(
        "planned {:.4} m of path in {:.3} s of motion ({} feed; constant feed {:.3} s, peak feed \
         {:.4} m/s): {} samples, {} RTOs, {} iteration(s), planning took {:.3} s",
        plan.path_length,
        duration,
        plan.feed.law.as_str(),
        plan.feed.constant_feed_time,
        plan.feed.peak_feed,
        plan.times.len(),
        plan.rtos.len(),
        plan.iterations,
        plan.times_per_stage.total
    )
}

/// The `CutPlan` message of a successful plan (status SUCCESS).
///
/// # Errors
/// INTERNAL_ERROR as a message (never `Err`): a plan whose samples fail [`check_samples`] is
/// answered with status INTERNAL_ERROR and the defect, so a planner bug never reaches the
/// executor.
pub fn plan_to_msg(plan: &kerf_mjto::CutPlan) -> msg::CutPlan {
    let trajectory = match trajectory_msg(plan) {
        Ok(t) => t,
        Err(reason) => {
            return failure_msg(
                &plan.request_id,
                status::INTERNAL_ERROR,
                format!("the planner produced an unusable trajectory: {reason}"),
            )
        }
    };
    let t = &plan.times_per_stage;
    msg::CutPlan {
        request_id: plan.request_id.clone(),
        status: status::SUCCESS,
        message: success_message(plan),
        trajectory,
        rtos: plan.rtos.iter().map(rto_to_msg).collect(),
        metrics: metrics_to_msg(&plan.metrics),
        qi_metrics: metrics_to_msg(&plan.qi_metrics),
        collisions: Vec::new(),
        max_feasible_feedrate: 0.0,
        iterations: to_u32(plan.iterations),
        collision_queries: to_u32(plan.collision_queries),
        control_points: to_u32(plan.control_points),
        path_length: plan.path_length,
        feed_law: plan.feed.law.as_str().to_string(),
        cycle_time: plan.feed.cycle_time,
        constant_feed_time: plan.feed.constant_feed_time,
        peak_feed: plan.feed.peak_feed,
        feed_limits: plan
            .feed
            .limits
            .iter()
            .map(|l| msg::CutFeedLimit {
                s_start: l.s_start,
                s_end: l.s_end,
                limited_by: l.limited_by.clone(),
            })
            .collect(),
        time_setup: t.setup,
        time_hessian: t.hessian,
        time_gfd: t.gfd,
        time_selection: t.selection,
        time_rotary_qp: t.rotary_qp,
        time_mpath_qp: t.mpath_qp,
        time_collision: t.collision,
        time_evaluation: t.evaluation,
        time_total: t.total,
        time_feed: t.feed,
        // Filled by the planner-node harness (start, approach, retract).
        stretches: msg::PlanStretches::default(),
    }
}

/// A `CutPlan` message that carries only a status and a message (everything else empty).
pub fn failure_msg(request_id: &str, status: u8, message: impl Into<String>) -> msg::CutPlan {
    msg::CutPlan {
        request_id: request_id.to_string(),
        status,
        message: message.into(),
        ..msg::CutPlan::default()
    }
}

/// The `CutPlan` message of a planner error: `status` from [`PlanError::status`], `message`
/// its text, `collisions` filled for [`PlanError::Collision`] (every colliding sample) and
/// [`PlanError::NoFeasibleOrientation`] (one entry at the CL point, `time` −1),
/// `max_feasible_feedrate` for [`PlanError::Infeasible`] when the feedrate is the cause,
/// `iterations` for [`PlanError::Collision`].
pub fn error_to_msg(request_id: &str, err: &PlanError) -> msg::CutPlan {
    let mut m = failure_msg(request_id, err.status(), err.to_string());
    match err {
        PlanError::Collision {
            iterations,
            collisions,
        } => {
            m.iterations = to_u32(*iterations);
            m.collisions = collisions.iter().map(collision_to_msg).collect();
        }
        PlanError::NoFeasibleOrientation { index, u, reason } => {
            m.collisions = vec![msg::CutCollision {
                u: *u,
                time: -1.0,
                cl_index: to_u32(*index),
                links: Vec::new(),
                reason: reason.clone(),
            }];
        }
        PlanError::Infeasible {
            max_feasible_feedrate: Some(f),
            ..
        } => m.max_feasible_feedrate = *f,
        _ => {}
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_mjto::{
        error::LimitViolation,
        plan::{CutPlan, StageTimes},
    };
    use kerf_msgs::builtin_interfaces::Duration;
    use kerf_msgs::geometry_msgs::{Point, Pose, Quaternion, Vector3};

    fn message() -> msg::CutRequest {
        msg::CutRequest {
            request_id: "r1".into(),
            points: vec![
                Point {
                    x: 0.1,
                    y: 0.2,
                    z: 0.3,
                },
                Point {
                    x: 0.2,
                    y: 0.2,
                    z: 0.3,
                },
            ],
            axes: vec![
                Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: 1.0,
                },
                Vector3 {
                    x: 0.0,
                    y: 0.6,
                    z: 0.8,
                },
            ],
            feedrate: 0.25,
            sample_period: 0.004,
            max_lead_angle: 0.1,
            max_tilt_angle: 0.2,
            mesh: "package://kerf/meshes/plate.stl".into(),
            workpiece_pose: Pose {
                position: Point {
                    x: 1.0,
                    y: 2.0,
                    z: 3.0,
                },
                orientation: Quaternion::IDENTITY,
            },
            ..msg::CutRequest::default()
        }
    }

    #[test]
    fn zeros_take_the_documented_defaults() {
        let r = request_from_msg(&message()).unwrap();
        let d = CutOptions::default();
        assert_eq!(r.request_id, "r1");
        assert_eq!(r.points, vec![[0.1, 0.2, 0.3], [0.2, 0.2, 0.3]]);
        assert_eq!(r.axes, vec![[0.0, 0.0, 1.0], [0.0, 0.6, 0.8]]);
        assert_eq!(r.feedrate, 0.25);
        assert_eq!(r.feed_acceleration, 8.0);
        assert_eq!(r.feed_jerk, 80.0);
        assert_eq!(r.sample_period, 0.004);
        assert_eq!((r.max_lead_angle, r.max_tilt_angle), (0.1, 0.2));
        assert_eq!(r.mesh, "package://kerf/meshes/plate.stl");
        assert_eq!(r.workpiece_pose.position, [1.0, 2.0, 3.0]);
        assert_eq!(r.workpiece_pose.orientation, [0.0, 0.0, 0.0, 1.0]);
        // Every option at its CutOptions default, the standoff included.
        assert_eq!(r.options, d);
        assert_eq!(r.options.reference_standoff, -0.07);
        assert_eq!(r.options.max_iterations, 10);
        // The converted request passes the planner's own validation.
        r.validate().unwrap();
    }

    #[test]
    fn feed_defaults_equal_the_yaml_form() {
        let yaml = "points: [[0, 0, 0], [0.1, 0, 0]]\naxes: [[0, 0, 1], [0, 0, 1]]\n\
                    feedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
                    max_tilt_angle: 0.1\nmesh: m.stl\n";
        let r = CutRequest::from_yaml(yaml).unwrap();
        assert_eq!(r.feed_acceleration, DEFAULT_FEED_ACCELERATION);
        assert_eq!(r.feed_jerk, DEFAULT_FEED_JERK);
        assert_eq!(r.options, CutOptions::default());
    }

    #[test]
    fn non_zero_values_pass_unchanged() {
        let mut m = message();
        m.feed_acceleration = 5.0;
        m.feed_jerk = 50.0;
        m.control_points = 7;
        m.max_iterations = 3;
        m.gfd_q4_steps = 11;
        m.gfd_q5_steps = 3;
        m.gfd_q6_steps = 2;
        m.gfd_q4_half_range = 0.5;
        m.gfd_q5_half_range = 0.25;
        m.rto_indices = vec![0, 1];
        m.rto_spacing = 0.05;
        m.rto_angle = 0.2;
        m.has_reference_standoff = true;
        m.reference_standoff = 0.0;
        m.clearance = 0.002;
        m.rto_constraint = "equality".into();
        let r = request_from_msg(&m).unwrap();
        assert_eq!((r.feed_acceleration, r.feed_jerk), (5.0, 50.0));
        let o = &r.options;
        assert_eq!((o.control_points, o.max_iterations), (7, 3));
        assert_eq!((o.gfd.q4_steps, o.gfd.q5_steps, o.gfd.q6_steps), (11, 3, 2));
        assert_eq!((o.gfd.q4_half_range, o.gfd.q5_half_range), (0.5, 0.25));
        assert_eq!(o.rto_indices, vec![0, 1]);
        assert_eq!((o.rto_spacing, o.rto_angle), (0.05, 0.2));
        // q6 = 0 is a valid standoff: the flag, not the value, selects the default.
        assert_eq!(o.reference_standoff, 0.0);
        assert_eq!(o.clearance, 0.002);
        assert_eq!(o.rto_constraint, RtoConstraint::Equality);
        assert_eq!(o.weights, CutOptions::default().weights);
    }

    #[test]
    fn feed_law_names_select_the_law_and_others_are_refused() {
        let mut m = message();
        for (name, law) in [
            ("", FeedMode::TimeOptimal),
            ("time_optimal", FeedMode::TimeOptimal),
            ("constant", FeedMode::Constant),
        ] {
            m.feed_law = name.into();
            assert_eq!(
                request_from_msg(&m).unwrap().options.feed_law,
                law,
                "{name:?}"
            );
        }
        for bad in ["Constant", "variable", " constant"] {
            m.feed_law = bad.into();
            match request_from_msg(&m) {
                Err(e @ PlanError::InvalidRequest { .. }) => {
                    assert_eq!(e.status(), status::INVALID_REQUEST);
                    assert!(e.to_string().contains("feed_law"), "{e}");
                }
                other => panic!("{bad:?}: expected InvalidRequest, got {other:?}"),
            }
        }
    }

    #[test]
    fn orientation_corridor_takes_its_default_and_refuses_other_text() {
        let mut m = message();
        assert_eq!(
            request_from_msg(&m).unwrap().options.orientation_corridor,
            OrientationCorridor::Allowance
        );
        m.orientation_corridor = "none".into();
        assert_eq!(
            request_from_msg(&m).unwrap().options.orientation_corridor,
            OrientationCorridor::None
        );
        m.orientation_corridor = "off".into();
        let e = request_from_msg(&m).unwrap_err();
        assert_eq!(e.status(), status::INVALID_REQUEST);
        assert!(
            e.to_string().contains("options.orientation_corridor"),
            "{e}"
        );
    }

    #[test]
    fn rto_constraint_takes_its_default_and_refuses_other_text() {
        let mut m = message();
        assert_eq!(
            request_from_msg(&m).unwrap().options.rto_constraint,
            RtoConstraint::Box
        );
        m.rto_constraint = "box".into();
        assert_eq!(
            request_from_msg(&m).unwrap().options.rto_constraint,
            RtoConstraint::Box
        );
        m.rto_constraint = "Box ".into();
        let e = request_from_msg(&m).unwrap_err();
        assert_eq!(e.status(), status::INVALID_REQUEST);
        assert!(e.to_string().contains("options.rto_constraint"), "{e}");
    }

    #[test]
    fn bad_values_are_not_repaired() {
        // Negative and NaN values are passed on, and validation names the field.
        let mut m = message();
        m.feed_jerk = -1.0;
        let e = request_from_msg(&m).unwrap().validate().unwrap_err();
        assert_eq!(e.status(), status::INVALID_REQUEST);
        assert!(e.to_string().contains("feed_jerk"), "{e}");
        let mut m = message();
        m.points[1].y = f64::NAN;
        let e = request_from_msg(&m).unwrap().validate().unwrap_err();
        assert!(e.to_string().contains("points[1]"), "{e}");
    }

    #[test]
    fn zero_quaternion_is_refused() {
        let mut m = message();
        m.workpiece_pose.orientation = Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 0.0,
        };
        let e = request_from_msg(&m).unwrap_err();
        assert_eq!(e.status(), status::INVALID_REQUEST);
        let text = e.to_string();
        assert!(text.contains("workpiece_pose.orientation"), "{text}");
        assert!(text.contains("w = 1"), "{text}");
    }

    fn metrics(scale: f64) -> Metrics {
        Metrics {
            peak_velocity: [1.0 * scale; 6],
            peak_acceleration: [2.0 * scale; 6],
            peak_jerk: [3.0 * scale, 4.0, 5.0, 6.0, 7.0, 8.0],
            rms_jerk: [0.5 * scale; 6],
            within_limits: scale < 2.0,
            limit_violations: if scale < 2.0 {
                Vec::new()
            } else {
                vec!["q1 jerk 150 > 120 at t = 0.1 s".into()]
            },
            max_cl_error: 1e-5,
            max_lead_angle: 0.01,
            max_tilt_angle: 0.02,
            colliding_samples: 0,
        }
    }

    fn plan() -> CutPlan {
        let times = vec![0.0, 0.004, 0.008];
        let positions = vec![
            [0.8, 0.7, 1.5, 0.0, 0.0, -0.05],
            [0.801, 0.7, 1.5, 0.01, 0.0, -0.05],
            [0.802, 0.7, 1.5, 0.02, 0.0, -0.05],
        ];
        CutPlan {
            request_id: "r9".into(),
            joint_names: JOINT_NAMES.iter().map(|s| s.to_string()).collect(),
            times,
            path_positions: vec![0.0, 0.001, 0.002],
            positions,
            velocities: vec![[0.25, 0.0, 0.0, 2.5, 0.0, 0.0]; 3],
            accelerations: vec![[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]; 3],
            rtos: vec![
                RtoRecord {
                    u: 0.0,
                    cl_index: 0,
                    q4: 0.0,
                    q5: 0.0,
                    q6: -0.05,
                    inserted_at_iteration: 0,
                },
                RtoRecord {
                    u: 1.0,
                    cl_index: 1,
                    q4: 0.02,
                    q5: 0.0,
                    q6: -0.05,
                    inserted_at_iteration: 2,
                },
            ],
            metrics: metrics(1.0),
            qi_metrics: metrics(2.0),
            iterations: 2,
            collision_queries: 1234,
            control_points: 6,
            path_length: 0.002,
            feed: kerf_mjto::plan::FeedReport {
                law: FeedMode::TimeOptimal,
                cycle_time: 0.008,
                constant_feed_time: 0.007,
                peak_feed: 0.25,
                limits: vec![kerf_mjto::optimal_feed::FeedLimit {
                    s_start: 0.0005,
                    s_end: 0.0015,
                    limited_by: "q4 velocity".into(),
                }],
            },
            times_per_stage: StageTimes {
                setup: 0.1,
                hessian: 0.2,
                gfd: 0.3,
                selection: 0.4,
                rotary_qp: 0.5,
                mpath_qp: 0.6,
                collision: 0.7,
                evaluation: 0.8,
                feed: 0.9,
                total: 3.6,
            },
        }
    }

    #[test]
    fn plan_becomes_a_message() {
        let m = plan_to_msg(&plan());
        assert_eq!(m.status, msg::CutPlan::SUCCESS);
        assert_eq!(m.request_id, "r9");
        assert!(m.message.starts_with("planned 0.0020 m"), "{}", m.message);
        let t = &m.trajectory;
        assert!(t.header.stamp.is_zero());
        assert_eq!(t.joint_names, ["q1", "q2", "q3", "q4", "q5", "q6"]);
        assert_eq!(t.points.len(), 3);
        assert_eq!(t.points[1].positions, [0.801, 0.7, 1.5, 0.01, 0.0, -0.05]);
        assert_eq!(t.points[1].velocities, [0.25, 0.0, 0.0, 2.5, 0.0, 0.0]);
        assert_eq!(t.points[2].accelerations, [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert!(t.points[2].effort.is_empty());
        assert_eq!(t.points[0].time_from_start, Duration::ZERO);
        assert_eq!(t.points[2].time_from_start.as_nanos(), 8_000_000);
        assert_eq!(m.rtos.len(), 2);
        assert_eq!(m.rtos[1].cl_index, 1);
        assert_eq!(m.rtos[1].q4, 0.02);
        assert_eq!(m.rtos[1].inserted_at_iteration, 2);
        assert_eq!(m.metrics.peak_jerk, [3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        assert!(m.metrics.within_limits);
        assert_eq!(m.qi_metrics.peak_velocity, [2.0; 6]);
        assert!(!m.qi_metrics.within_limits);
        assert_eq!(m.qi_metrics.limit_violations.len(), 1);
        assert_eq!(
            (m.iterations, m.collision_queries, m.control_points),
            (2, 1234, 6)
        );
        assert_eq!(m.path_length, 0.002);
        assert_eq!(
            [
                m.time_setup,
                m.time_hessian,
                m.time_gfd,
                m.time_selection,
                m.time_rotary_qp,
                m.time_mpath_qp,
                m.time_collision,
                m.time_evaluation,
                m.time_total,
                m.time_feed
            ],
            [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 3.6, 0.9]
        );
        assert!(m.collisions.is_empty());
        assert_eq!(m.feed_law, "time_optimal");
        assert_eq!(
            (m.cycle_time, m.constant_feed_time, m.peak_feed),
            (0.008, 0.007, 0.25)
        );
        assert_eq!(m.feed_limits.len(), 1);
        assert_eq!(m.feed_limits[0].limited_by, "q4 velocity");
        assert_eq!(m.feed_limits[0].s_end, 0.0015);
    }

    #[test]
    fn unusable_plans_are_internal_errors() {
        let mut p = plan();
        p.velocities[2][4] = f64::NAN;
        let m = plan_to_msg(&p);
        assert_eq!(m.status, msg::CutPlan::INTERNAL_ERROR);
        assert!(
            m.message.contains("velocity of joint q5 at sample 2"),
            "{}",
            m.message
        );
        assert!(m.trajectory.points.is_empty());
        assert_eq!(m.request_id, "r9");

        let mut p = plan();
        p.times[2] = 0.004;
        let m = plan_to_msg(&p);
        assert_eq!(m.status, msg::CutPlan::INTERNAL_ERROR);
        assert!(
            m.message.contains("do not increase at sample 2"),
            "{}",
            m.message
        );

        let mut p = plan();
        p.accelerations.pop();
        assert!(check_samples(&p).unwrap_err().contains("2 accelerations"));
        let mut p = plan();
        p.joint_names.swap(0, 1);
        assert!(check_samples(&p).is_err());
    }

    #[test]
    fn status_constants_match_the_planner() {
        type P = msg::CutPlan;
        assert_eq!(P::SUCCESS, status::SUCCESS);
        assert_eq!(P::INVALID_REQUEST, status::INVALID_REQUEST);
        assert_eq!(P::MESH_ERROR, status::MESH_ERROR);
        assert_eq!(P::UNREACHABLE, status::UNREACHABLE);
        assert_eq!(P::INFEASIBLE, status::INFEASIBLE);
        assert_eq!(P::COLLISION, status::COLLISION);
        assert_eq!(P::LIMIT_VIOLATION, status::LIMIT_VIOLATION);
        assert_eq!(P::INTERNAL_ERROR, status::INTERNAL_ERROR);
    }

    #[test]
    fn errors_become_messages() {
        let collision = PlanError::Collision {
            iterations: 10,
            collisions: vec![CollisionReport {
                u: 0.5,
                time: 1.25,
                cl_index: 40,
                links: vec!["nozzle".into()],
                reason: "nozzle touches the workpiece".into(),
            }],
        };
        let m = error_to_msg("c", &collision);
        assert_eq!(m.status, msg::CutPlan::COLLISION);
        assert_eq!(m.request_id, "c");
        assert_eq!(m.iterations, 10);
        assert_eq!(m.collisions.len(), 1);
        assert_eq!(m.collisions[0].cl_index, 40);
        assert_eq!(m.collisions[0].time, 1.25);
        assert_eq!(m.collisions[0].links, ["nozzle"]);
        assert!(m.message.contains("after 10 iterations"), "{}", m.message);
        assert!(m.trajectory.points.is_empty());

        let none = PlanError::NoFeasibleOrientation {
            index: 7,
            u: 0.25,
            reason: "all 405 candidates collide".into(),
        };
        let m = error_to_msg("n", &none);
        assert_eq!(m.status, msg::CutPlan::COLLISION);
        assert_eq!(m.collisions[0].cl_index, 7);
        assert_eq!(m.collisions[0].time, -1.0);

        let infeasible = PlanError::Infeasible {
            problem: "q4".into(),
            family: kerf_mjto::error::ConstraintFamily::Jerk,
            detail: "primal infeasible".into(),
            max_feasible_feedrate: Some(0.2),
        };
        let m = error_to_msg("i", &infeasible);
        assert_eq!(m.status, msg::CutPlan::INFEASIBLE);
        assert_eq!(m.max_feasible_feedrate, 0.2);
        assert!(m.message.contains("jerk bounds"), "{}", m.message);

        let limits = PlanError::LimitViolation {
            violations: vec![LimitViolation {
                joint: "q4".into(),
                quantity: "jerk",
                value: 250.0,
                limit: 200.0,
                time: 0.5,
            }],
        };
        let m = error_to_msg("l", &limits);
        assert_eq!(m.status, msg::CutPlan::LIMIT_VIOLATION);
        assert!(
            m.message.contains("q4 jerk 250.0000 > 200.0000"),
            "{}",
            m.message
        );
        assert_eq!(m.max_feasible_feedrate, 0.0);
    }
}
