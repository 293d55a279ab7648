//! Request files as request messages, as a client that read them would send them.

use kerf_mjto::CutRequest;
use kerf_msgs::{
    geometry_msgs::{Point, Pose, Quaternion, Vector3},
    msg,
};

/// The message form of a planner request (the inverse of the node's conversion for every
/// field the message has; the weights are the defaults in every case file).
pub fn cut_msg(r: &CutRequest) -> msg::CutRequest {
    let o = &r.options;
    let [px, py, pz] = r.workpiece_pose.position;
    let [qx, qy, qz, qw] = r.workpiece_pose.orientation;
    msg::CutRequest {
        request_id: r.request_id.clone(),
        points: r
            .points
            .iter()
            .map(|p| Point {
                x: p[0],
                y: p[1],
                z: p[2],
            })
            .collect(),
        axes: r
            .axes
            .iter()
            .map(|a| Vector3 {
                x: a[0],
                y: a[1],
                z: a[2],
            })
            .collect(),
        feedrate: r.feedrate,
        feed_acceleration: r.feed_acceleration,
        feed_jerk: r.feed_jerk,
        sample_period: r.sample_period,
        max_lead_angle: r.max_lead_angle,
        max_tilt_angle: r.max_tilt_angle,
        mesh: r.mesh.clone(),
        workpiece_pose: Pose {
            position: Point {
                x: px,
                y: py,
                z: pz,
            },
            orientation: Quaternion {
                x: qx,
                y: qy,
                z: qz,
                w: qw,
            },
        },
        control_points: o.control_points as u32,
        max_iterations: o.max_iterations as u32,
        gfd_q4_steps: o.gfd.q4_steps as u32,
        gfd_q5_steps: o.gfd.q5_steps as u32,
        gfd_q6_steps: o.gfd.q6_steps as u32,
        gfd_q4_half_range: o.gfd.q4_half_range,
        gfd_q5_half_range: o.gfd.q5_half_range,
        rto_indices: o.rto_indices.iter().map(|&i| i as u32).collect(),
        rto_spacing: o.rto_spacing,
        rto_angle: o.rto_angle,
        has_reference_standoff: true,
        reference_standoff: o.reference_standoff,
        clearance: o.clearance,
        cl_tolerance: o.cl_tolerance,
        feed_law: o.feed_law.as_str().into(),
        rto_constraint: o.rto_constraint.as_str().into(),
        orientation_corridor: o.orientation_corridor.as_str().into(),
        time_budget: r.time_budget,
        start: r.start.to_fields().0,
        start_positions: r.start.to_fields().1,
    }
}
