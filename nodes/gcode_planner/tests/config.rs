//! The node's parameters: the machine and the surroundings its approaches keep clear of
//! (issue 27), bad ones refused with the parameter's name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_gcode_planner::{surroundings::MachineSurroundings, NodeConfig, NodeError, KNOWN_PARAMS};
use kerf_ros::Params;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

fn config(params: &[&str]) -> Result<NodeConfig, NodeError> {
    NodeConfig::from_params(&Params::from_assignments(
        "gcode_planner",
        KNOWN_PARAMS,
        params,
    )?)
}

#[test]
fn each_machine_has_its_surroundings() {
    let c = config(&[]).unwrap();
    assert!(matches!(c.surroundings, MachineSurroundings::Laser(_)));
    let c = config(&["machine:=irb6660"]).unwrap();
    match &c.surroundings {
        MachineSurroundings::Irb(cell) => {
            assert!(
                cell.source().ends_with("urdf/cells/irb6660_plate.yaml"),
                "{}",
                cell.source()
            );
        }
        other => panic!("{other:?}"),
    }
    let file = format!("collision_cell_file:={ROOT}/urdf/cells/irb6660_plate.yaml");
    let c = config(&["machine:=irb6660", &file]).unwrap();
    assert!(c.surroundings.source().contains(ROOT));
}

#[test]
fn a_bad_collision_cell_is_refused_by_name() {
    for (params, expect) in [
        (vec!["machine:=irb6660", "collision_cell_file:=''"], "empty"),
        (
            vec![
                "machine:=irb6660",
                "collision_cell_file:=/nonexistent/plate.yaml",
            ],
            "/nonexistent/plate.yaml",
        ),
        (
            vec!["collision_cell_file:=/any/plate.yaml"],
            "is for machine irb6660",
        ),
    ] {
        let e = config(&params).unwrap_err();
        assert!(matches!(e, NodeError::Config { .. }), "{e}");
        let e = e.to_string();
        assert!(
            e.contains("'collision_cell_file'") && e.contains(expect),
            "{e}"
        );
    }
}
