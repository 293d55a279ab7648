//! The executor's own validation is the judge of "executable": the
//! executed trajectories of the milling planner's plans (naive, ddpg and
//! dp through [`MillPlanner::plan`], and a DP plan of narrow ranges through
//! [`kerf_millplan::execute`]) pass `kerf_executor::validate` from rest at
//! their first point, with the cell robot's limits, as the trajectory
//! executor node would receive them.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;
use support::reduced_dp_spec;

use std::sync::OnceLock;

use kerf_executor::{ExecutorConfig, JointLimits, JointSample};
use kerf_mill::MillCell;
use kerf_millplan::request::RequestLimits;
use kerf_millplan::{dp, execute, JointTrajectory, MillPlanner, MillRequest, Plan, RewardWeights};

fn planner() -> &'static MillPlanner {
    static P: OnceLock<MillPlanner> = OnceLock::new();
    P.get_or_init(|| MillPlanner::with_default_cell().expect("planner"))
}

/// The cell robot's joints as the executor's robot model (model order).
fn executor_limits(cell: &MillCell) -> Vec<JointLimits> {
    cell.robot()
        .executor_limits()
        .expect("the cell's robot has acceleration limits")
}

/// `kerf_executor::validate` of `t` from rest at its first point, start
/// time `None`, now 0, the executor's default configuration.
fn assert_executable(cell: &MillCell, t: &JointTrajectory, what: &str) {
    let limits = executor_limits(cell);
    assert_eq!(t.request.start_time, None, "{what}");
    let first = &t.points()[0].positions;
    // The start state in model order (the trajectory's names may be in any).
    let start: Vec<f64> = limits
        .iter()
        .map(|l| {
            let k = t
                .joint_names()
                .iter()
                .position(|n| n == &l.name)
                .expect("every robot joint in the trajectory");
            first[k]
        })
        .collect();
    let validated = kerf_executor::validate(
        &limits,
        &ExecutorConfig::default(),
        &t.request,
        &JointSample::at_rest(start),
        0.0,
    );
    assert!(validated.is_ok(), "{what}: {:?}", validated.err());
}

#[test]
fn planner_outputs_pass_the_executors_validation() {
    let cell = planner().cell().clone();
    for (kind, limits) in [
        ("naive", None),
        ("ddpg", None),
        // The DP on narrow ranges (seconds, not the full grid's).
        (
            "dp",
            Some(RequestLimits {
                spindle_rpm: Some([2000.0, 2200.0]),
                feed: Some([0.03, 0.05]),
                redundancy_angle: Some([-1.0, 1.0]),
                step_bounds: None,
            }),
        ),
    ] {
        let request = MillRequest {
            planner: kind.to_string(),
            allow_chatter: true,
            limits,
            ..MillRequest::default()
        };
        let out = planner().plan(&request).expect(kind);
        let t = &out.executed.scaling.trajectory;
        assert!(
            t.points().len() > out.plan.segments.len() + 2,
            "{kind}: dense samples"
        );
        assert_executable(&cell, t, kind);
    }
}

#[test]
fn an_executed_dp_plan_passes_the_executors_validation() {
    let cell = MillCell::default_cell().expect("cell");
    let cache = planner().cache().expect("the default cell's cache");
    let weights = RewardWeights::default();
    let spec = reduced_dp_spec(&cell);
    let r = dp::solve(&cell, cache, &spec).expect("dp");
    let plan = Plan::evaluate(&cell, &weights, &r.states, "dp").expect("plan");
    let executed = execute(&cell, &plan, &weights, 2).expect("executed");
    // The DP's g steps are slowed to the joint limits.
    assert!(executed.scaling.slowed_segments() > 0);
    assert_executable(&cell, &executed.scaling.trajectory, "dp (narrow ranges)");
    // The check is not vacuous: the same trajectory run twice as fast
    // (times halved, velocities doubled, accelerations x4) is refused.
    let mut fast = executed.scaling.trajectory.request.clone();
    for p in &mut fast.points {
        p.time_from_start *= 0.5;
        p.velocities.iter_mut().for_each(|v| *v *= 2.0);
        p.accelerations.iter_mut().for_each(|a| *a *= 4.0);
    }
    let first = fast.points[0].positions.clone();
    let refused = kerf_executor::validate(
        &executor_limits(&cell),
        &ExecutorConfig::default(),
        &fast,
        &JointSample::at_rest(first),
        0.0,
    );
    assert!(refused.is_err());
}
