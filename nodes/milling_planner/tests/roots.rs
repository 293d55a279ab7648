//! `allowed_file_roots` (issue 11, item 4): a request's policy file must resolve under an
//! allowed root or the shipped data, links resolved; outside is POLICY_ERROR.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_milling_planner::{DefaultPolicies, MillService};
use kerf_millplan::MillPlanner;
use kerf_msgs::msg::MillPlan;
use kerf_robot::roots::AllowedRoots;
use kerf_ros::planner::PlanningService;

#[test]
fn policies_outside_the_allowed_roots_are_refused_before_planning() {
    let d = std::env::temp_dir().join(format!("kerf_mill_roots_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    let (jobs, private) = (d.join("jobs"), d.join("private"));
    std::fs::create_dir_all(&jobs).unwrap();
    std::fs::create_dir_all(&private).unwrap();
    std::fs::write(jobs.join("mine.safetensors"), "x").unwrap();
    std::fs::write(private.join("other.safetensors"), "x").unwrap();
    std::os::unix::fs::symlink(
        private.join("other.safetensors"),
        jobs.join("link.safetensors"),
    )
    .unwrap();
    let planner = MillPlanner::with_default_cell().unwrap();
    let policies = DefaultPolicies {
        ddpg: "/nonexistent/ddpg.safetensors".into(),
        fixed_g: "/nonexistent/fixed_g.safetensors".into(),
    };
    let service = MillService::new(planner, policies, String::new())
        .unwrap()
        .with_allowed_roots(AllowedRoots::only(std::slice::from_ref(&jobs)).unwrap());
    let text = |file: &std::path::Path| {
        format!(
            "request_id: r\nplanner: ddpg\npolicy_file: {}\npoints: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\n",
            file.display()
        )
    };
    assert!(service
        .request_from_text(&text(&jobs.join("mine.safetensors")))
        .is_ok());
    for outside in [
        private.join("other.safetensors"),
        jobs.join("link.safetensors"),
    ] {
        let answer = service.request_from_text(&text(&outside)).unwrap_err();
        assert_eq!(answer.status, MillPlan::POLICY_ERROR, "{}", answer.message);
        assert!(
            answer.message.contains("outside the allowed roots"),
            "{}",
            answer.message
        );
        assert_eq!(answer.planner, "ddpg");
    }
    std::fs::remove_dir_all(&d).unwrap();
}
