//! `allowed_file_roots` (issue 11, item 4): a request's policy file must resolve under an
//! allowed root or the shipped data, links resolved; outside is POLICY_ERROR. The policy file
//! is resolved as every file a request names (issue 33, item 4): a path, `file://` or
//! `package://kerf/`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::PathBuf;

use kerf_milling_planner::{DefaultPolicies, MillService};
use kerf_millplan::MillPlanner;
use kerf_msgs::msg::MillPlan;
use kerf_robot::roots::AllowedRoots;
use kerf_ros::planner::PlanningService;

/// A scratch directory with `jobs/mine.safetensors` (under the allowed root),
/// `private/other.safetensors` (outside it) and `jobs/link.safetensors` (a link to the
/// latter), and a service allowing `jobs` only.
struct Fixture {
    dir: PathBuf,
    jobs: PathBuf,
    private: PathBuf,
    service: MillService,
}

impl Fixture {
    fn new(name: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("kerf_mill_roots_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (jobs, private) = (dir.join("jobs"), dir.join("private"));
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
        Self {
            dir,
            jobs,
            private,
            service,
        }
    }

    /// The text request of a ddpg plan with `policy_file`.
    fn text(policy_file: &str) -> String {
        format!(
            "request_id: r\nplanner: ddpg\npolicy_file: \"{policy_file}\"\npoints: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\n"
        )
    }

    /// The answer to a request naming `policy_file`, which must be refused POLICY_ERROR.
    fn refused(&self, policy_file: &str) -> MillPlan {
        let answer = *self
            .service
            .request_from_text(&Self::text(policy_file))
            .unwrap_err();
        assert_eq!(answer.status, MillPlan::POLICY_ERROR, "{}", answer.message);
        assert_eq!(answer.planner, "ddpg");
        answer
    }
}

impl Drop for Fixture {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

#[test]
fn policies_outside_the_allowed_roots_are_refused_before_planning() {
    let f = Fixture::new("paths");
    let mine = f.jobs.join("mine.safetensors");
    assert!(f
        .service
        .request_from_text(&Fixture::text(&mine.display().to_string()))
        .is_ok());
    for outside in [
        f.private.join("other.safetensors"),
        f.jobs.join("link.safetensors"),
    ] {
        let answer = f.refused(&outside.display().to_string());
        assert!(
            answer.message.contains("outside the allowed roots"),
            "{}",
            answer.message
        );
    }
}

#[test]
fn file_uri_policies_resolve_before_the_roots_check() {
    let f = Fixture::new("uris");
    let inside = format!("file://{}", f.jobs.join("mine.safetensors").display());
    let request = f
        .service
        .request_from_text(&Fixture::text(&inside))
        .unwrap();
    assert_eq!(request.policy_file.as_deref(), Some(inside.as_str()));
    let outside = format!("file://{}", f.private.join("other.safetensors").display());
    let answer = f.refused(&outside);
    assert!(
        answer.message.contains("outside the allowed roots"),
        "{}",
        answer.message
    );
    // Another host or scheme is refused by the resolver, naming the reference.
    for bad in ["file://otherhost/x.safetensors", "http://h/x.safetensors"] {
        let answer = f.refused(bad);
        assert!(answer.message.contains(bad), "{}", answer.message);
    }
}
