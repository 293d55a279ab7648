//! The robot descriptions in `urdf/` load with the specified joints and limits.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::{FRAC_PI_2, PI};

use kerf_robot::{JointKind, RobotModel};
use nalgebra::Vector3;

#[test]
fn laser_cutter_joints_and_limits_match_seed_001_table_2() {
    let robot = common::laser_cutter();
    assert_eq!(robot.name(), "laser_cutter");
    assert_eq!(robot.root_link(), "base_link");
    assert_eq!(robot.tip_link(), "tool0");
    assert_eq!(robot.joint_names(), ["q1", "q2", "q3", "q4", "q5", "q6"]);
    // (kind, axis, min, max, velocity, acceleration, jerk), Table 2, SI units.
    use JointKind::{Prismatic as P, Revolute as R};
    let expected = [
        (P, Vector3::x(), 0.0, 1.6, 2.0, 12.0, 120.0),
        (P, Vector3::y(), 0.0, 1.4, 2.0, 12.0, 120.0),
        (P, Vector3::z(), 0.0, 3.0, 2.0, 12.0, 120.0),
        (R, Vector3::z(), -2.0 * PI, 2.0 * PI, 10.0, 80.0, 200.0),
        (R, Vector3::y(), -FRAC_PI_2, FRAC_PI_2, 10.0, 80.0, 200.0),
        (P, Vector3::z(), -0.1, 0.02, 2.0, 40.0, 400.0),
    ];
    for (joint, (kind, axis, min, max, vel, acc, jerk)) in robot.joints().iter().zip(expected) {
        assert_eq!(joint.kind, kind, "{}", joint.name);
        assert_eq!(joint.axis.into_inner(), axis, "{}", joint.name);
        assert_eq!(joint.min_position, min, "{}", joint.name);
        assert_eq!(joint.max_position, max, "{}", joint.name);
        assert_eq!(joint.max_velocity, vel, "{}", joint.name);
        assert_eq!(joint.max_acceleration, Some(acc), "{}", joint.name);
        assert_eq!(joint.max_jerk, Some(jerk), "{}", joint.name);
        assert!(joint.max_effort > 0.0, "{}", joint.name);
        assert_eq!(
            joint.origin,
            nalgebra::Isometry3::identity(),
            "{}",
            joint.name
        );
    }
    assert_eq!(robot.joint_index("q5"), Some(4));
    assert_eq!(robot.joint_index("tool0"), None);
}

#[test]
fn irb6660_joints_and_limits_match_abb_data() {
    let robot = common::irb6660();
    assert_eq!(robot.root_link(), "base_link");
    assert_eq!(robot.tip_link(), "tool0");
    let names: Vec<String> = (1..=6).map(|i| format!("joint_{i}")).collect();
    assert_eq!(robot.joint_names(), names);
    // (axis, min °, max °, speed °/s, origin m, acceleration rad/s² from the YAML)
    let expected = [
        (Vector3::z(), -180.0, 180.0, 110.0, [0.0, 0.0, 0.8145], 3.5),
        (Vector3::y(), -42.0, 85.0, 130.0, [0.300, 0.0, 0.0], 4.0),
        (Vector3::y(), -20.0, 120.0, 130.0, [0.0, 0.0, 1.280], 4.0),
        (Vector3::x(), -300.0, 300.0, 150.0, [0.0, 0.0, 0.280], 5.0),
        (Vector3::y(), -120.0, 120.0, 120.0, [1.5055, 0.0, 0.0], 4.0),
        (Vector3::x(), -360.0, 360.0, 240.0, [0.200, 0.0, 0.0], 8.0),
    ];
    for (joint, (axis, min, max, speed, origin, acc)) in robot.joints().iter().zip(expected) {
        let f64_deg = |d: f64| d.to_radians();
        assert_eq!(joint.kind, JointKind::Revolute);
        assert_eq!(joint.axis.into_inner(), axis, "{}", joint.name);
        assert!(
            (joint.min_position - f64_deg(min)).abs() < 1e-15,
            "{}",
            joint.name
        );
        assert!(
            (joint.max_position - f64_deg(max)).abs() < 1e-15,
            "{}",
            joint.name
        );
        assert!(
            (joint.max_velocity - f64_deg(speed)).abs() < 1e-15,
            "{}",
            joint.name
        );
        assert_eq!(joint.origin.translation.vector, Vector3::from(origin));
        assert_eq!(joint.origin.rotation.angle(), 0.0);
        assert_eq!(joint.max_acceleration, Some(acc), "{}", joint.name);
        assert_eq!(joint.max_jerk, Some(5.0 * acc), "{}", joint.name);
        // Engineering estimates must stay below "full speed in 0.5 s".
        assert!(acc <= 2.0 * joint.max_velocity, "{}", joint.name);
    }
}

#[test]
fn descriptions_load_without_limits_yaml() {
    for name in ["laser_cutter.urdf", "irb6660.urdf"] {
        let robot = RobotModel::from_strings(&common::read(name), None)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(robot.dof(), 6, "{name}");
        for joint in robot.joints() {
            assert_eq!(joint.max_acceleration, None, "{name} {}", joint.name);
            assert_eq!(joint.max_jerk, None, "{name} {}", joint.name);
        }
    }
}

#[test]
fn every_link_has_a_pose_and_the_head_has_collision_geometry() {
    let robot = common::laser_cutter();
    let poses = robot.link_poses(&[0.1, 0.2, 0.3, 0.4, 0.5, -0.05]).unwrap();
    let names: Vec<&str> = poses.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "base_link",
            "x_carriage",
            "y_carriage",
            "z_ram",
            "c_axis",
            "a_axis",
            "nozzle",
            "tool0"
        ]
    );
    for head_link in ["z_ram", "c_axis", "a_axis", "nozzle"] {
        let link = robot
            .urdf()
            .links
            .iter()
            .find(|l| l.name == head_link)
            .unwrap();
        assert!(
            !link.collision.is_empty(),
            "{head_link} needs collision geometry"
        );
    }
    // The nozzle shapes lie on the +O side of the CL point (nozzle frame z
    // axis = O), the lowest one starting just above it (standoff gap).
    let nozzle = robot
        .urdf()
        .links
        .iter()
        .find(|l| l.name == "nozzle")
        .unwrap();
    let mut lowest = f64::INFINITY;
    for c in &nozzle.collision {
        let urdf_rs::Geometry::Cylinder { length, .. } = c.geometry else {
            panic!("nozzle collision shapes are cylinders along O");
        };
        assert_eq!(c.origin.rpy.0, [0.0; 3], "nozzle cylinders are along O");
        assert_eq!(
            &c.origin.xyz.0[..2],
            &[0.0, 0.0],
            "nozzle cylinders are on O"
        );
        lowest = lowest.min(c.origin.xyz.0[2] - length / 2.0);
    }
    assert!(
        lowest > 0.0 && lowest < 0.005,
        "nozzle starts at {lowest} m"
    );

    let robot = common::irb6660();
    let poses = robot.link_poses(&[0.0; 6]).unwrap();
    assert_eq!(poses.len(), 8);
    for link in robot.urdf().links.iter().filter(|l| l.name != "tool0") {
        assert!(
            !link.collision.is_empty(),
            "{} needs collision geometry",
            link.name
        );
    }
}

#[test]
fn laser_nozzle_never_touches_the_c_axis_housing_or_fork() {
    // Nozzle (q6 link) and c_axis (q4 link) are not adjacent, so their
    // collision shapes must stay apart over the whole q5/q6 range.
    let robot = common::laser_cutter();
    let link = |name: &str| robot.urdf().links.iter().find(|l| l.name == name).unwrap();
    // c_axis shapes (axis-aligned in the c_axis frame): the motor housing
    // cylinder bottom and the inner faces of the fork boxes.
    let mut housing_bottom = f64::INFINITY;
    let mut fork_inner = f64::INFINITY;
    for c in &link("c_axis").collision {
        match c.geometry {
            urdf_rs::Geometry::Cylinder { length, .. } => {
                housing_bottom = housing_bottom.min(c.origin.xyz.0[2] - length / 2.0)
            }
            urdf_rs::Geometry::Box { ref size } => {
                fork_inner = fork_inner.min(c.origin.xyz.0[1].abs() - size.0[1] / 2.0)
            }
            _ => panic!("unexpected c_axis shape"),
        }
    }
    assert!(housing_bottom.is_finite() && fork_inner.is_finite());
    let mut rng = common::SplitMix64::new(11);
    for _ in 0..500 {
        let q = rng.joint_vector(&robot);
        let poses = robot.link_poses(&q).unwrap();
        let pose_of = |name: &str| poses.iter().find(|(n, _)| n == name).unwrap().1;
        let nozzle_in_c = pose_of("c_axis").inverse() * pose_of("nozzle");
        for c in &link("nozzle").collision {
            let urdf_rs::Geometry::Cylinder { radius, length } = c.geometry else {
                panic!("nozzle shapes are cylinders");
            };
            let z_mid = c.origin.xyz.0[2];
            for end in [z_mid - length / 2.0, z_mid + length / 2.0] {
                for k in 0..32 {
                    let a = k as f64 * std::f64::consts::TAU / 32.0;
                    let p = nozzle_in_c
                        * nalgebra::Point3::new(radius * a.cos(), radius * a.sin(), end);
                    assert!(
                        p.z < housing_bottom,
                        "nozzle reaches C housing at q = {q:?}"
                    );
                    assert!(
                        p.y.abs() < fork_inner,
                        "nozzle reaches the fork at q = {q:?}"
                    );
                }
            }
        }
    }
}
