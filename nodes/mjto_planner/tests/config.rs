//! The node's parameters: the shipped machine loads by default or from files, and bad
//! parameters are refused with the parameter's name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mjto_planner::{
    config::DEFAULT_QUEUE_DEPTH, NodeConfig, NodeError, SetupError, KNOWN_PARAMS,
};
use kerf_ros::Params;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

fn config(params: &[&str]) -> Result<NodeConfig, NodeError> {
    // The node knows its own parameters and the planner harness's.
    let known: Vec<&str> = KNOWN_PARAMS
        .iter()
        .chain(kerf_ros::planner::HARNESS_PARAMS)
        .copied()
        .collect();
    NodeConfig::from_params(&Params::from_assignments("mjto_planner", &known, params)?)
}

#[test]
fn shipped_machine_by_default_and_from_files() {
    let c = config(&[]).unwrap();
    assert_eq!(c.harness.queue_depth, DEFAULT_QUEUE_DEPTH);
    // seed 001 Table 2: q4 jerk 200 rad/s³, q6 stroke [-0.1, 0.02] m.
    assert_eq!(c.machine.limits()[3].jerk, 200.0);
    assert_eq!(c.machine.limits()[5].min, -0.1);

    let urdf = format!("urdf_file:={ROOT}/urdf/laser_cutter.urdf");
    let limits = format!("joint_limits_file:={ROOT}/urdf/laser_cutter_limits.yaml");
    let c = config(&[&urdf, &limits, "queue_depth:=3", "plan_timeout:=2.5"]).unwrap();
    assert_eq!(c.harness.queue_depth, 3);
    assert_eq!(
        c.harness.plan_timeout,
        std::time::Duration::from_millis(2500)
    );
    assert_eq!(c.machine.limits()[0].acc, 12.0);
    assert!(c.machine_source.contains("laser_cutter_limits.yaml"));
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let e = config(&["queue_depth:=0"]).unwrap_err().to_string();
    assert!(e.contains("'queue_depth'") && e.contains(">= 1"), "{e}");
    let e = config(&["queue_depth:=2.5"]).unwrap_err().to_string();
    assert!(
        e.contains("'queue_depth'") && e.contains("expected integer"),
        "{e}"
    );
    for bad in [
        "plan_timeout:=0.0",
        "plan_timeout:=-1.0",
        "plan_timeout:=1e9",
    ] {
        let e = config(&[bad]).unwrap_err().to_string();
        assert!(e.contains("'plan_timeout'"), "{bad}: {e}");
    }
    let e = config(&["control_rate:=100.0"]).unwrap_err().to_string();
    assert!(e.contains("'control_rate'") && e.contains("unknown"), "{e}");
    let limits = format!("joint_limits_file:={ROOT}/urdf/laser_cutter_limits.yaml");
    let e = config(&[&limits]).unwrap_err().to_string();
    assert!(
        e.contains("'joint_limits_file'") && e.contains("without urdf_file"),
        "{e}"
    );
    // The IRB 6660 is not the laser cutter: its joints are not q1..q6.
    let urdf = format!("urdf_file:={ROOT}/urdf/irb6660.urdf");
    let limits = format!("joint_limits_file:={ROOT}/urdf/irb6660_limits.yaml");
    let e = config(&[&urdf, &limits]).unwrap_err();
    assert!(matches!(e, NodeError::Setup(SetupError::Machine(_))), "{e}");
    assert!(e.to_string().contains("q1"), "{e}");
    let e = config(&["urdf_file:=/nonexistent/machine.urdf"]).unwrap_err();
    assert!(matches!(e, NodeError::Setup(SetupError::Machine(_))), "{e}");
}

/// Issue 27: the approach and retract parameters are read and checked like every other; a
/// safe pose the machine cannot reach stops the node naming the parameter.
#[test]
fn approach_parameters_are_checked_and_safe_poses_must_be_reachable() {
    let c = config(&[
        "approach.clearance:=0.02",
        "approach.lead_distance:=0.05",
        "retract.distance:=0.1",
        "approach.safe_pose:=[0.8, 0.7, 1.6, 0.0, 0.0, -0.05]",
    ])
    .unwrap();
    assert_eq!(c.harness.framing.clearance(), 0.02);
    assert_eq!(c.harness.framing.lead_distance(), 0.05);
    assert_eq!(c.harness.framing.retract_distance(), 0.1);
    let service =
        kerf_mjto_planner::CutService::new(c.machine.clone(), c.machine_source.clone()).unwrap();
    use kerf_ros::planner::PlanningService;
    c.harness.check_reach(service.approach_limits()).unwrap();

    for (bad, name) in [
        ("approach.clearance:=0.0", "approach.clearance"),
        ("approach.lead_distance:=-1.0", "approach.lead_distance"),
        ("retract.distance:=0.0", "retract.distance"),
        ("approach.control_period:=0.0", "approach.control_period"),
    ] {
        let e = config(&[bad]).unwrap_err().to_string();
        assert!(e.contains(&format!("'{name}'")), "{bad}: {e}");
    }
    // q6's stroke is [-0.1, 0.02] m: a retract pose at q6 = 0.5 m is out of reach.
    let far = config(&["retract.safe_pose:=[0.8, 0.7, 1.6, 0.0, 0.0, 0.5]"]).unwrap();
    let e = far
        .harness
        .check_reach(service.approach_limits())
        .unwrap_err()
        .to_string();
    assert!(e.contains("'retract.safe_pose'") && e.contains("q6"), "{e}");
    let short = config(&["approach.safe_pose:=[0.8, 0.7]"]).unwrap();
    let e = short
        .harness
        .check_reach(service.approach_limits())
        .unwrap_err()
        .to_string();
    assert!(e.contains("'approach.safe_pose'"), "{e}");
}
