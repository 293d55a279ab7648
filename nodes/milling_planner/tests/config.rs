//! The node's parameters: the shipped cell (and its cache, when fresh) load by default, the
//! default policies can be replaced, and bad parameters are refused with the parameter's name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::Path;

use kerf_milling_planner::{
    config::DEFAULT_QUEUE_DEPTH, NodeConfig, NodeError, SetupError, KNOWN_PARAMS,
};
use kerf_millplan::{plan::IndicatorSource, PlannerKind};
use kerf_ros::Params;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

fn config(params: &[&str]) -> Result<NodeConfig, NodeError> {
    NodeConfig::from_params(&Params::from_assignments(
        "milling_planner",
        KNOWN_PARAMS,
        params,
    )?)
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "kerf_milling_planner_config_{name}_{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn shipped_cell_and_policies_by_default_and_replaced_by_parameters() {
    let c = config(&[]).unwrap();
    assert_eq!(c.harness.queue_depth, DEFAULT_QUEUE_DEPTH);
    assert!(
        c.cell_source.ends_with("irb6660_milling.yaml"),
        "{}",
        c.cell_source
    );
    // The shipped cell: seed 004 Table 1, 100 segments, spindle 2000..4000 rpm.
    assert_eq!(c.planner.cell().path().segments().len(), 100);
    assert_eq!(
        c.planner.cell().state_limits().spindle_rpm,
        [2000.0, 4000.0]
    );
    // The cache note says whether the shipped cache applies, and why not when it does not.
    if c.planner.cache().is_some() {
        assert!(
            c.cache_note.contains("indicator_cache.bin"),
            "{}",
            c.cache_note
        );
    } else {
        assert!(
            c.cache_note.contains("dp and naive build per-path caches"),
            "{}",
            c.cache_note
        );
    }
    assert!(c
        .default_policy(PlannerKind::Ddpg)
        .unwrap()
        .ends_with("crates/millplan/policies/ddpg.safetensors"));
    assert!(c
        .default_policy(PlannerKind::FixedG)
        .unwrap()
        .ends_with("crates/millplan/policies/fixed_g.safetensors"));
    assert_eq!(c.indicator_source, IndicatorSource::Direct);
    assert_eq!(c.planner.indicator_source(), IndicatorSource::Direct);
    assert_eq!(c.default_policy(PlannerKind::Dp), None);
    assert_eq!(c.default_policy(PlannerKind::Naive), None);
    // The approach's surroundings: the shipped collision cell (issue 27).
    assert!(
        c.surroundings
            .source()
            .ends_with("urdf/cells/irb6660_plate.yaml"),
        "{}",
        c.surroundings.source()
    );
    assert_eq!(c.surroundings.object_names(), ["stock", "fixture_plate"]);

    // Explicit cell file and policies; the policies need not exist at start-up.
    let cell = format!("cell_file:={ROOT}/urdf/irb6660_milling.yaml");
    let c = config(&[
        &cell,
        "queue_depth:=3",
        "ddpg_policy_file:=/nonexistent/a.safetensors",
        "fixed_g_policy_file:=b.safetensors",
        "indicator_source:=cache",
        "eval_threads:=2",
        &format!("collision_cell_file:={ROOT}/urdf/cells/irb6660_plate.yaml"),
    ])
    .unwrap();
    assert!(c.surroundings.source().starts_with(ROOT));
    assert_eq!(c.harness.queue_depth, 3);
    assert_eq!(c.indicator_source, IndicatorSource::Cache);
    assert_eq!(c.planner.indicator_source(), IndicatorSource::Cache);
    assert!(c.cell_source.ends_with("urdf/irb6660_milling.yaml"));
    assert_eq!(
        c.default_policy(PlannerKind::Ddpg),
        Some(Path::new("/nonexistent/a.safetensors"))
    );
    assert_eq!(
        c.default_policy(PlannerKind::FixedG),
        Some(Path::new("b.safetensors"))
    );
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let e = config(&["queue_depth:=0"]).unwrap_err().to_string();
    assert!(e.contains("'queue_depth'") && e.contains(">= 1"), "{e}");
    let e = config(&["queue_depth:=-3"]).unwrap_err().to_string();
    assert!(e.contains("'queue_depth'") && e.contains("got -3"), "{e}");
    let e = config(&["queue_depth:=2.5"]).unwrap_err().to_string();
    assert!(
        e.contains("'queue_depth'") && e.contains("expected integer"),
        "{e}"
    );
    let e = config(&["indicator_source:=lookup"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("'indicator_source'") && e.contains("direct or cache"),
        "{e}"
    );
    let e = config(&["eval_threads:=0"]).unwrap_err().to_string();
    assert!(e.contains("'eval_threads'") && e.contains(">= 1"), "{e}");
    let e = config(&["eval_threads:=1.5"]).unwrap_err().to_string();
    assert!(e.contains("'eval_threads'"), "{e}");
    let e = config(&["urdf_file:=/x.urdf"]).unwrap_err().to_string();
    assert!(e.contains("'urdf_file'") && e.contains("unknown"), "{e}");
    for name in [
        "cell_file",
        "indicator_cache_file",
        "ddpg_policy_file",
        "fixed_g_policy_file",
        "collision_cell_file",
    ] {
        let e = config(&[&format!("{name}:=''")]).unwrap_err();
        assert!(matches!(e, NodeError::Config { .. }), "{name}: {e}");
        let e = e.to_string();
        assert!(
            e.contains(&format!("'{name}'")) && e.contains("empty"),
            "{e}"
        );
    }
    // The collision cell is loaded at start-up: a missing file, or a cell of another robot.
    for (file, expect) in [
        (
            "/nonexistent/plate.yaml".to_string(),
            "/nonexistent/plate.yaml",
        ),
        (
            format!("{ROOT}/urdf/cells/laser_bpillar.yaml"),
            "robot.name is 'laser_cutter'",
        ),
    ] {
        let e = config(&[&format!("collision_cell_file:={file}")]).unwrap_err();
        assert!(matches!(e, NodeError::Config { .. }), "{e}");
        let e = e.to_string();
        assert!(
            e.contains("'collision_cell_file'") && e.contains(expect),
            "{e}"
        );
    }
    let e = config(&["cell_file:=/nonexistent/cell.yaml"]).unwrap_err();
    assert!(matches!(e, NodeError::Setup(SetupError::Cell(_))), "{e}");
    assert!(e.to_string().contains("/nonexistent/cell.yaml"), "{e}");

    // A given cache must load: garbage is refused, naming the file.
    let dir = scratch("cache");
    let garbage = dir.join("garbage.bin");
    std::fs::write(&garbage, "not a cache\n").unwrap();
    let e = config(&[&format!("indicator_cache_file:={}", garbage.display())]).unwrap_err();
    assert!(matches!(e, NodeError::Setup(SetupError::Planner(_))), "{e}");
    let e = e.to_string();
    assert!(
        e.contains("garbage.bin") && e.contains("not a cache file"),
        "{e}"
    );
    let missing = dir.join("missing.bin");
    let e = config(&[&format!("indicator_cache_file:={}", missing.display())]).unwrap_err();
    assert!(e.to_string().contains("missing.bin"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
