//! Checks of a framed plan (issue 27), shared by the planner nodes' tests (the G-code
//! planner's include this file by path): the trajectory starts at the start, its process
//! stretch is the unframed plan shifted in time, it ends at rest, and re-sampled at 1 ms the
//! approach keeps the clearance and the leads the lead clearance, by the node's own exact
//! distance.

use kerf_approach::{FrameSettings, Surroundings};
use kerf_msgs::msg::PlanStretches;
use kerf_msgs::trajectory_msgs::{JointTrajectory, JointTrajectoryPoint};

/// What [`check_framed`] measured.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    /// Duration of the approach, start → backed-off first process point (s).
    pub approach: f64,
    /// Duration of the lead-in (s).
    pub lead_in: f64,
    /// Smallest distance over the approach at 1 ms (m), everything measured.
    pub approach_clearance: f64,
    /// Smallest distance over the lead-in and lead-out at 1 ms (m), the process contact
    /// left out.
    pub lead_clearance: f64,
}

/// Re-sampling step (s).
const STEP: f64 = 0.001;

fn time(p: &JointTrajectoryPoint) -> f64 {
    p.time_from_start.as_secs_f64()
}

/// The quintic Hermite of two points (positions, velocities, accelerations; the executor's
/// interpolation, e.g. JTC `interpolate_between_points`) at `t`.
fn quintic(a: &JointTrajectoryPoint, b: &JointTrajectoryPoint, t: f64) -> Vec<f64> {
    let h = time(b) - time(a);
    let s = (t - time(a)) / h;
    let (s2, s3) = (s * s, s * s * s);
    let (s4, s5) = (s3 * s, s3 * s2);
    let h00 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5;
    let h10 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5;
    let h20 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5;
    let h01 = 10.0 * s3 - 15.0 * s4 + 6.0 * s5;
    let h11 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5;
    let h21 = 0.5 * s3 - s4 + 0.5 * s5;
    (0..a.positions.len())
        .map(|j| {
            h00 * a.positions[j]
                + h10 * h * a.velocities[j]
                + h20 * h * h * a.accelerations[j]
                + h01 * b.positions[j]
                + h11 * h * b.velocities[j]
                + h21 * h * h * b.accelerations[j]
        })
        .collect()
}

/// The smallest clearance over points `from..=to` of `t`, re-sampled every [`STEP`].
fn min_over(
    t: &JointTrajectory,
    from: usize,
    to: usize,
    world: &dyn Surroundings,
    process: bool,
) -> (f64, String) {
    let mut best = (f64::INFINITY, String::new());
    for k in from..to {
        let (a, b) = (&t.points[k], &t.points[k + 1]);
        let steps = ((time(b) - time(a)) / STEP).ceil().max(1.0) as usize;
        for i in 0..=steps {
            let at = time(a) + (time(b) - time(a)) * i as f64 / steps as f64;
            let c = world.clearance(&quintic(a, b, at), process);
            assert!(c.distance.is_finite(), "{c:?} at {at} s");
            if c.distance < best.0 {
                best = (c.distance, c.obstacle);
            }
        }
    }
    best
}

fn p_last(t: &JointTrajectory) -> &JointTrajectoryPoint {
    t.points.last().expect("points")
}

/// The index of the first point at `q` (within 1e-9), at rest.
fn rest_at(t: &JointTrajectory, q: &[f64]) -> usize {
    t.points
        .iter()
        .position(|p| {
            p.positions.iter().zip(q).all(|(a, b)| (a - b).abs() < 1e-9)
                && p.velocities.iter().all(|v| v.abs() < 1e-9)
        })
        .unwrap_or_else(|| panic!("no point at rest at {q:?}"))
}

/// Checks a framed answer against its unframed plan (module documentation) and measures it.
pub fn check_framed(
    framed: &JointTrajectory,
    stretches: &PlanStretches,
    unframed: &JointTrajectory,
    start: &[f64],
    world: &dyn Surroundings,
    settings: &FrameSettings,
) -> Measured {
    assert_eq!(stretches.start, "given");
    assert_eq!(stretches.start_positions, start);
    assert_eq!(framed.joint_names, unframed.joint_names);
    // Starts at the start, at rest, at time 0.
    let first = &framed.points[0];
    assert_eq!(time(first), 0.0);
    assert_eq!(first.positions, start);
    assert!(first.velocities.iter().all(|v| v.abs() < 1e-12));
    // The process stretch is the unframed plan, shifted by process_start_time.
    let t0 = stretches.process_start_time;
    let at = framed
        .points
        .iter()
        .position(|p| (time(p) - t0).abs() < 1e-9)
        .expect("a point at process_start_time");
    for (k, p) in unframed.points.iter().enumerate() {
        let f = &framed.points[at + k];
        assert_eq!(f.positions, p.positions, "process point {k}");
        assert_eq!(f.velocities, p.velocities, "process point {k}");
        if !p.accelerations.is_empty() {
            assert_eq!(f.accelerations, p.accelerations, "process point {k}");
        }
        assert!((time(f) - t0 - time(p)).abs() < 1e-9, "process point {k}");
    }
    let end = at + unframed.points.len() - 1;
    assert!((time(&framed.points[end]) - stretches.process_end_time).abs() < 1e-9);
    // Ends at rest.
    let last = framed.points.last().expect("points");
    assert!(last.velocities.iter().all(|v| v.abs() < 1e-9), "{last:?}");
    assert!(
        last.accelerations.iter().all(|v| v.abs() < 1e-9),
        "{last:?}"
    );
    assert!((time(last) - stretches.duration).abs() < 1e-9);
    // The approach ends at rest at the first process point backed off; the lead-in follows.
    let pre = world
        .back_off(&unframed.points[0].positions, settings.lead_distance())
        .expect("back-off of the first process point");
    let pre_at = rest_at(framed, &pre);
    assert!(pre_at < at);
    let (approach, obstacle) = min_over(framed, 0, pre_at, world, false);
    assert!(
        approach >= settings.clearance() - 1e-9,
        "approach {approach} m from {obstacle}"
    );
    let lead_in = min_over(framed, pre_at, at, world, true).0;
    let lead_out = min_over(framed, end, framed.points.len() - 1, world, true).0;
    let lead = lead_in.min(lead_out);
    // The lead clearance kept: at most half the process's own at its ends (kerf_approach::frame).
    let ends = world
        .clearance(&unframed.points[0].positions, true)
        .distance
        .min(world.clearance(&p_last(unframed).positions, true).distance);
    let kept = settings.lead_clearance().min(0.5 * ends);
    assert!(lead >= kept - 1e-9, "lead {lead} m, kept {kept} m");
    Measured {
        approach: time(&framed.points[pre_at]),
        lead_in: t0 - time(&framed.points[pre_at]),
        approach_clearance: approach,
        lead_clearance: lead,
    }
}
