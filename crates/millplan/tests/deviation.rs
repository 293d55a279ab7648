//! The executed tool path (issue 13, item 1): the deviation of the tool tip from the planned
//! path when the executor interpolates a published milling trajectory at its control period.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_millplan::deviation::executed_deviation;
use kerf_millplan::{MillPlanner, MillRequest};

/// The executor's control period (s): 250 Hz.
const PERIOD: f64 = 0.004;

#[test]
fn the_constant_plan_stays_on_the_path_and_a_bent_one_does_not() {
    let planner = MillPlanner::with_default_cell().unwrap();
    let request = MillRequest {
        planner: "naive".into(),
        ..MillRequest::default()
    };
    let out = planner.plan(&request).unwrap();
    let trajectory = &out.executed.scaling.trajectory;
    let d = executed_deviation(planner.cell(), trajectory, PERIOD).unwrap();
    println!("naive: {d:?}");
    // Constant g: the joints move smoothly and the interpolation stays on the path.
    assert!(d.max_off_path < 5e-5, "{d:?}");
    assert!(d.max_off_plane < 5e-5, "{d:?}");
    assert!(d.samples > 1000, "{d:?}");

    // The same trajectory with joint 4 bent by 0.01 rad in the middle: the tip leaves the path.
    let mut bent = trajectory.clone();
    let mid = bent.request.points.len() / 2;
    bent.request.points[mid].positions[3] += 0.01;
    let e = executed_deviation(planner.cell(), &bent, PERIOD).unwrap();
    assert!(e.max_off_path > 10.0 * d.max_off_path.max(1e-6), "{e:?}");
    assert!(executed_deviation(planner.cell(), trajectory, 0.0).is_err());
}
