//! The `--out` document of `kerf plan mill` (JSON or YAML): the request id, every plan —
//! segments and totals as planned and as executed, the time scaling, both trajectories, the
//! branch jumps — and every failure.

use kerf_millplan::{
    plan::Plan, planner::status_name, status_of, JointTrajectory, MillPlanError, MillPlanOutput,
    MillRequest, PlannerKind,
};
use serde_json::{json, Value};

/// The totals of a plan in the `--out` document.
fn totals_json(p: &Plan) -> Value {
    json!({
        "machining_time_s": p.total_time,
        "chatter_free": p.chatter_free,
        "max_spectral_radius": p.max_spectral_radius,
        "min_condition_indicator": p.min_condition_indicator,
        "total_reward": p.total_reward,
    })
}

/// A joint trajectory in the `--out` document.
fn trajectory_json(t: &JointTrajectory) -> Value {
    json!({
        "joint_names": t.joint_names(),
        "points": t.points().iter().zip(&t.arc_length).zip(&t.segment).map(|((p, s), g)| json!({
            "time_from_start_s": p.time_from_start,
            "positions_rad": p.positions,
            "velocities_rad_per_s": p.velocities,
            "accelerations_rad_per_s2": p.accelerations,
            "arc_length_m": s,
            "segment": g,
        })).collect::<Vec<_>>(),
    })
}

/// The `--out` document (module documentation): the request id, every plan and every
/// failure.
pub fn document(
    request: &MillRequest,
    outputs: &[MillPlanOutput],
    failures: &[(PlannerKind, MillPlanError)],
) -> Value {
    let plans: Vec<Value> = outputs
        .iter()
        .map(|o| {
            let p = &o.plan;
            let (x, sc) = (&o.executed.plan, &o.executed.scaling);
            json!({
                "planner": o.planner.name(),
                "policy_file": o.policy_file.as_ref().map(|f| f.display().to_string()),
                "status": 0,
                "status_name": "SUCCESS",
                "planning_seconds": o.planning_seconds,
                "cache_used": o.cache_used,
                "indicator": {
                    "requested": o.indicator.requested.name(),
                    "cached_segments": o.indicator.cached_segments,
                    "error_bound": o.indicator.error_bound,
                    "note": o.indicator.note,
                },
                "totals": totals_json(p),
                "segments": p.segments.iter().map(|g| json!({
                    "segment": g.segment,
                    "spindle_rpm": g.rpm,
                    "feed_m_per_s": g.feed,
                    "g_rad": g.g,
                    "spectral_radius": g.spectral_radius,
                    "condition_number": g.condition_number,
                    "condition_indicator": g.condition_indicator,
                    "joints_rad": g.joints,
                    "time_s": g.time,
                    "reward": {
                        "operational": g.reward.operational,
                        "efficiency": g.reward.efficiency,
                        "stability": g.reward.stability,
                        "total": g.reward.total,
                    },
                })).collect::<Vec<_>>(),
                "executed": {
                    "totals": totals_json(x),
                    "segments": x.segments.iter().map(|g| json!({
                        "segment": g.segment,
                        "feed_m_per_s": g.feed,
                        "spectral_radius": g.spectral_radius,
                        "time_s": g.time,
                        "reward": g.reward.total,
                    })).collect::<Vec<_>>(),
                    "cached_segments": o.executed.cached_segments,
                    "time_scaling": {
                        "segment_slowdown": sc.segment_slowdown,
                        "slowed_segments": sc.slowed_segments(),
                        "rounds": sc.rounds,
                        "uniform": sc.uniform,
                        "ramp_time_s": sc.ramp_time,
                        "duration_s": sc.duration(),
                        "points": sc.trajectory.points().len(),
                        "run_in_m": sc.run_in,
                        "run_out_m": sc.run_out,
                    },
                    "chatter_judge": {
                        "chatter_free": o.executed.chatter.chatter_free,
                        "max_spectral_radius": o.executed.chatter.max_spectral_radius,
                        "samples": o.executed.chatter.samples,
                        "evaluations": o.executed.chatter.evaluations,
                        "chattering_segments": o.executed.chatter.chattering_segments,
                    },
                    "tool_path": {
                        "max_off_path_m": o.executed.scaling.deviation.max_off_path,
                        "p99_off_path_m": o.executed.scaling.deviation.p99_off_path,
                        "max_off_plane_m": o.executed.scaling.deviation.max_off_plane,
                        "samples": o.executed.scaling.deviation.samples,
                    },
                },
                "trajectory": trajectory_json(&sc.trajectory),
                "planned_trajectory": trajectory_json(&o.trajectory),
                "branch_jumps": o.branch_jumps.iter().map(|j| json!({
                    "index": j.index, "joint": j.joint, "step_rad": j.step,
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let failed: Vec<Value> = failures
        .iter()
        .map(|(k, e)| {
            let code = status_of(e);
            json!({
                "planner": k.name(),
                "status": code,
                "status_name": status_name(code).unwrap_or("?"),
                "message": e.to_string(),
            })
        })
        .collect();
    json!({
        "request_id": request.request_id,
        "plans": plans,
        "failures": failed,
    })
}
