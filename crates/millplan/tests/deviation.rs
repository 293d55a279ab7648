//! The executed tool path (issue 13, item 1): the deviation of the tool tip from the planned
//! path when the executor interpolates a published milling trajectory at its control period.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::sync::OnceLock;

use kerf_millplan::deviation::executed_deviation;
use kerf_millplan::request::RequestLimits;
use kerf_millplan::{MillPlanner, MillRequest, TrajectorySettings};

/// The executor's control period (s): 250 Hz.
const PERIOD: f64 = 0.004;

fn planner() -> &'static MillPlanner {
    static P: OnceLock<MillPlanner> = OnceLock::new();
    P.get_or_init(|| MillPlanner::with_default_cell().expect("planner"))
}

/// Every planner's published trajectory, run by the executor's own interpolation at its
/// control period, keeps the tool tip within the path tolerance (0.05 mm) of the path and of
/// the milling plane; the answer reports that measurement.
#[test]
fn every_planner_keeps_the_tool_on_the_path() {
    let tolerance = TrajectorySettings::default().path_tolerance;
    assert_eq!(tolerance, 5e-5);
    for (kind, limits) in [
        ("naive", None),
        ("ddpg", None),
        ("fixed_g", None),
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
            planner: kind.into(),
            allow_chatter: true,
            limits,
            ..MillRequest::default()
        };
        let out = planner().plan(&request).expect(kind);
        let trajectory = &out.executed.scaling.trajectory;
        let d = executed_deviation(planner().cell(), trajectory, PERIOD).unwrap();
        println!("{kind}: {} points, {d:?}", trajectory.points().len());
        assert!(d.max_off_path <= tolerance, "{kind}: {d:?}");
        assert!(d.max_off_plane <= tolerance, "{kind}: {d:?}");
        assert!(
            d.samples as f64 >= trajectory.duration() / PERIOD,
            "{kind}: {d:?}"
        );
        assert_eq!(d, out.executed.scaling.deviation, "{kind}");
    }
}

#[test]
fn a_bent_trajectory_leaves_the_path() {
    let request = MillRequest {
        planner: "naive".into(),
        ..MillRequest::default()
    };
    let out = planner().plan(&request).unwrap();
    let trajectory = &out.executed.scaling.trajectory;
    let d = executed_deviation(planner().cell(), trajectory, PERIOD).unwrap();
    // The same trajectory with joint 4 bent by 1 mrad in the middle: the tip leaves the path.
    let mut bent = trajectory.clone();
    let mid = bent.request.points.len() / 2;
    bent.request.points[mid].positions[3] += 0.001;
    let e = executed_deviation(planner().cell(), &bent, PERIOD).unwrap();
    println!("bent: {e:?}");
    assert!(
        e.max_off_path > 5e-5 && e.max_off_path > 10.0 * d.max_off_path,
        "{e:?}"
    );
    assert!(executed_deviation(planner().cell(), trajectory, 0.0).is_err());
}
