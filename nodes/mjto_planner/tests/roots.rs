//! `allowed_file_roots` (issue 11, item 4): a request's mesh must resolve under an allowed root
//! or the shipped data, links resolved; outside is MESH_ERROR naming the path, not its contents.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mjto::error::status;
use kerf_mjto_planner::{CutService, NodeConfig, KNOWN_PARAMS};
use kerf_ros::{planner::PlanningService, Params};

fn scratch() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("kerf_mjto_roots_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("jobs")).unwrap();
    std::fs::create_dir_all(d.join("private")).unwrap();
    d
}

fn request(mesh: &str) -> String {
    format!(
        "request_id: r\nfeedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
         max_tilt_angle: 0.1\nmesh: {mesh}\n0.6 0.2 0.1 0 0 1\n0.7 0.2 0.1 0 0 1\n"
    )
}

#[test]
fn meshes_outside_the_allowed_roots_are_refused_before_planning() {
    let d = scratch();
    let (jobs, private) = (d.join("jobs"), d.join("private"));
    std::fs::write(jobs.join("part.stl"), "solid x\nendsolid x\n").unwrap();
    std::fs::write(private.join("key.stl"), "TOP SECRET").unwrap();
    std::os::unix::fs::symlink(private.join("key.stl"), jobs.join("link.stl")).unwrap();

    let param = format!("allowed_file_roots:=['{}']", jobs.display());
    let cfg = NodeConfig::from_params(
        &Params::from_assignments("mjto_planner", KNOWN_PARAMS, &[param.as_str()]).unwrap(),
    )
    .unwrap();
    let service = CutService::new(cfg.machine, String::new())
        .unwrap()
        .with_allowed_roots(cfg.allowed_roots);

    // Inside a root, and the shipped data: converted (planning would read them).
    let inside = jobs.join("part.stl");
    assert!(service
        .request_from_text(&request(&inside.display().to_string()))
        .is_ok());
    assert!(service
        .request_from_text(&request("package://kerf/urdf/meshes/bpillar.obj"))
        .is_ok());
    // Outside, directly or through a link: MESH_ERROR naming the path, never the contents.
    for outside in [private.join("key.stl"), jobs.join("link.stl")] {
        let answer = service
            .request_from_text(&request(&outside.display().to_string()))
            .unwrap_err();
        assert_eq!(answer.status, status::MESH_ERROR, "{}", answer.message);
        assert!(
            answer.message.contains("outside the allowed roots"),
            "{}",
            answer.message
        );
        assert!(!answer.message.contains("SECRET"), "{}", answer.message);
    }
    // A root that does not exist is refused at start-up, by name.
    let e = NodeConfig::from_params(
        &Params::from_assignments(
            "mjto_planner",
            KNOWN_PARAMS,
            &["allowed_file_roots:=['/no/such/dir']"],
        )
        .unwrap(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("allowed_file_roots"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}
