//! [`kerf_approach::frame`] on a gantry tool with exact distances: a disk tool of radius R
//! moved by two prismatic joints (x, y) over a part filling y < 0, its axis +y. The process
//! mills a slot with the tool 1 mm into the part (a working contact only the lead-in and
//! lead-out may touch); a clamp stands between some starts and the part.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_approach::{
    frame, ApproachError, Clearance, FrameSettings, JointLimit, Route, Sample, Stage, Surroundings,
};

const R: f64 = 0.02;
const PERIOD: f64 = 0.004;
const CLAMP: ([f64; 2], f64) = ([0.30, 0.10], 0.05);

struct Gantry {
    clamp: bool,
    /// A wall at x = 0.3 m across the whole stroke.
    wall: bool,
}

impl Surroundings for Gantry {
    fn clearance(&self, q: &[f64], process: bool) -> Clearance {
        let mut best = Clearance::new(f64::INFINITY, "nothing");
        if !process {
            best = Clearance::new(q[1] - R, "part");
        }
        if self.wall {
            let d = (q[0] - 0.3).abs() - 0.01 - R;
            if d < best.distance {
                best = Clearance::new(d, "wall");
            }
        }
        if self.clamp {
            let (c, r) = CLAMP;
            let d = ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2)).sqrt() - r - R;
            if d < best.distance {
                best = Clearance::new(d, "clamp");
            }
        }
        best
    }
    fn lipschitz(&self) -> Vec<f64> {
        vec![1.0, 1.0]
    }
    fn back_off(&self, q: &[f64], distance: f64) -> Result<Vec<f64>, ApproachError> {
        Ok(vec![q[0], q[1] + distance])
    }
}

fn limits() -> Vec<JointLimit> {
    ["x", "y"]
        .iter()
        .map(|n| JointLimit {
            name: (*n).into(),
            min_position: -1.0,
            max_position: 1.0,
            max_velocity: 0.5,
            max_acceleration: 2.0,
            max_jerk: 20.0,
        })
        .collect()
}

/// A rest-to-rest slot along x at y = R - 1 mm (1 mm into the part), quintic in time.
fn slot(x0: f64, x1: f64) -> Vec<Sample> {
    let y = R - 0.001;
    let t_end = 1.0;
    (0..=250)
        .map(|k| {
            let t = k as f64 * PERIOD;
            let s = t / t_end;
            let p = 10.0 * s.powi(3) - 15.0 * s.powi(4) + 6.0 * s.powi(5);
            let v = (30.0 * s.powi(2) - 60.0 * s.powi(3) + 30.0 * s.powi(4)) / t_end;
            let a = (60.0 * s - 180.0 * s.powi(2) + 120.0 * s.powi(3)) / (t_end * t_end);
            Sample {
                t,
                q: vec![x0 + (x1 - x0) * p, y],
                qd: vec![(x1 - x0) * v, 0.0],
                qdd: vec![(x1 - x0) * a, 0.0],
            }
        })
        .collect()
}

fn settings() -> FrameSettings {
    FrameSettings::builder()
        .clearance(0.01)
        .lead_distance(0.03)
        .retract_distance(0.05)
        .build()
        .unwrap()
}

#[test]
fn a_process_is_framed_from_the_start_to_the_tool_axis_back_off() {
    let process = slot(0.5, 0.7);
    let framed = frame(
        &[0.5, 0.4],
        process.clone(),
        &limits(),
        &Gantry {
            clamp: false,
            wall: false,
        },
        &settings(),
    )
    .unwrap();
    let tl = &framed.timeline;
    assert_eq!(framed.approach_route, Route::Direct);
    assert!(!framed.retract_to_safe_pose);
    let first = &tl.samples[0];
    assert_eq!(first.q, vec![0.5, 0.4]);
    assert_eq!(first.t, 0.0);
    // The process is unchanged, shifted in time to process_start.
    let at = tl
        .samples
        .iter()
        .position(|s| (s.t - tl.process_start).abs() < 1e-12)
        .unwrap();
    for (k, p) in process.iter().enumerate() {
        let s = &tl.samples[at + k];
        assert_eq!(s.q, p.q);
        assert!((s.t - tl.process_start - p.t).abs() < 1e-12);
    }
    assert!((tl.process_end - tl.process_start - 1.0).abs() < 1e-12);
    // Ends at rest 5 cm above the slot's end.
    let last = tl.samples.last().unwrap();
    assert!((last.q[0] - 0.7).abs() < 1e-12 && (last.q[1] - (R - 0.001 + 0.05)).abs() < 1e-12);
    assert!(last.qd.iter().all(|v| v.abs() < 1e-12));
    // Every sample within the velocity limits; before the lead-in, and after the lead-out's
    // first 3 cm, the approach clearance to the part.
    for s in &tl.samples {
        assert!(s.qd.iter().all(|v| v.abs() <= 0.5 + 1e-9), "{s:?}");
        let outside = s.t < tl.process_start && s.q[1] >= R + 0.03 - 0.001 - 1e-9;
        if outside {
            assert!(s.q[1] - R >= 0.01, "{s:?}");
        }
    }
    // Times strictly increase.
    assert!(tl.samples.windows(2).all(|w| w[1].t > w[0].t));
}

#[test]
fn a_blocked_direct_approach_goes_via_a_safe_pose_or_names_the_obstacle() {
    let world = Gantry {
        clamp: true,
        wall: false,
    };
    // From the left of the clamp, low, to the slot on its right: the direct move is blocked;
    // without a configured safe pose, the point 0.3 m up the tool axis above the slot's start
    // is (0.15 m is still within the clamp's reach).
    let start = [0.10, 0.10];
    let framed = frame(&start, slot(0.5, 0.7), &limits(), &world, &settings()).unwrap();
    assert_eq!(framed.approach_route, Route::ViaSafePose(1));
    assert_eq!(framed.auto_via, Some(0.3));
    assert!(framed.approach_closest.distance >= 0.01);
    // A configured safe pose is tried first.
    let via = FrameSettings::builder()
        .safe_poses(vec![vec![0.3, 0.5]])
        .build()
        .unwrap();
    let framed = frame(&start, slot(0.5, 0.7), &limits(), &world, &via).unwrap();
    assert_eq!(framed.approach_route, Route::ViaSafePose(0));
    assert_eq!(framed.auto_via, None);
    // A wall across the stroke: no route; the error names it.
    let walled = Gantry {
        clamp: false,
        wall: true,
    };
    let e = frame(&start, slot(0.5, 0.7), &limits(), &walled, &via).unwrap_err();
    assert!(
        matches!(
            e,
            ApproachError::InStage {
                stage: Stage::Approach,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("wall"), "{e}");
    assert!(
        e.to_string()
            .starts_with("approach: no collision-free approach"),
        "{e}"
    );
}

#[test]
fn the_lead_in_grows_until_its_start_is_clear() {
    // The slot is 1 mm into the part; with a 4 cm clearance and a 1 cm lead distance, the
    // lead-in's start 1, 2 and 4 cm up the axis is 9, 19 and 39 mm from the part: 8 cm
    // (79 mm) is the first clear one.
    let s = FrameSettings::builder()
        .clearance(0.04)
        .lead_distance(0.01)
        .build()
        .unwrap();
    let world = Gantry {
        clamp: false,
        wall: false,
    };
    let framed = frame(&[0.5, 0.4], slot(0.5, 0.7), &limits(), &world, &s).unwrap();
    assert!(
        (framed.lead_in_distance - 0.08).abs() < 1e-12,
        "{}",
        framed.lead_in_distance
    );
    // The retract's 5 cm end is 49 mm from the part: clear.
    assert!((framed.lead_out_distance - 0.05).abs() < 1e-12);
    // A lead distance that never gets clear within the doublings is refused.
    let short = FrameSettings::builder()
        .clearance(0.5)
        .lead_distance(0.01)
        .build()
        .unwrap();
    let e = frame(&[0.5, 0.9], slot(0.5, 0.7), &limits(), &world, &short).unwrap_err();
    assert!(
        matches!(
            e,
            ApproachError::InStage {
                stage: Stage::LeadIn,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("part"), "{e}");
}

#[test]
fn a_start_in_the_part_and_a_safe_pose_out_of_reach_are_refused() {
    let e = frame(
        &[0.5, 0.0],
        slot(0.5, 0.7),
        &limits(),
        &Gantry {
            clamp: false,
            wall: false,
        },
        &settings(),
    )
    .unwrap_err();
    assert!(
        matches!(e.root(), ApproachError::InCollision { obstacle, .. } if obstacle == "part"),
        "{e}"
    );
    let far = FrameSettings::builder()
        .retract_safe_pose(Some(vec![0.5, 2.0]))
        .build()
        .unwrap();
    let e = far.check_reach(&limits()).unwrap_err();
    assert!(e.to_string().contains("outside its limits"), "{e}");
    let nan = FrameSettings::builder()
        .safe_poses(vec![vec![0.5, f64::NAN]])
        .build()
        .unwrap_err();
    assert!(nan.to_string().contains("safe_poses[0][1]"), "{nan}");
}

#[test]
fn the_retract_can_end_at_a_safe_pose() {
    let s = FrameSettings::builder()
        .retract_safe_pose(Some(vec![0.0, 0.5]))
        .build()
        .unwrap();
    let framed = frame(
        &[0.5, 0.4],
        slot(0.5, 0.7),
        &limits(),
        &Gantry {
            clamp: false,
            wall: false,
        },
        &s,
    )
    .unwrap();
    assert!(framed.retract_to_safe_pose);
    assert_eq!(framed.timeline.samples.last().unwrap().q, vec![0.0, 0.5]);
}
