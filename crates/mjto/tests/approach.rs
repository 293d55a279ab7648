//! Issue 27, item 1, on the real machine: `kerf_approach` certifies a move from a pose clear of
//! the part to case 1's first planned point against the shipped head and B-pillar, with the
//! exact distance of [`CollisionWorld::distance_up_to`] and [`HeadModel::lipschitz`]. Every
//! sample of the certified move, re-checked at 1 ms with the exact distance, keeps the
//! clearance, and every joint stays within its velocity limit; an approach through the part
//! is refused naming the workpiece.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::case;
use kerf_approach::{ApproachPlanner, ApproachSettings, Clearance, JointLimit};
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::mesh::MeshCache;
use kerf_mjto::planner::Planner;
use kerf_mjto::LaserMachine;

/// Clearance kept by the approach (m). The process's first point has the nozzle 0.84 mm from
/// the part (its cutting standoff), so an approach ending there cannot keep more; the node's
/// integration will end the approach backed off along the tool axis and let the process's
/// lead-in close the rest.
const CLEARANCE: f64 = 0.0005;
/// The executor's control period (s).
const PERIOD: f64 = 0.004;

struct Setup {
    world: CollisionWorld,
    limits: Vec<JointLimit>,
    lipschitz: Vec<f64>,
    first: Vec<f64>,
}

fn setup() -> Setup {
    let machine = LaserMachine::default_machine().unwrap();
    let head = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    let lipschitz = head.lipschitz().to_vec();
    let request = case("case1");
    let v = request.validate().unwrap();
    let mesh = MeshCache::new().get(&request.mesh).unwrap();
    let world = CollisionWorld::new(head, &mesh, &v.workpiece_pose, CLEARANCE).unwrap();
    let limits: Vec<JointLimit> = machine
        .limits()
        .iter()
        .enumerate()
        .map(|(i, l)| JointLimit {
            name: format!("q{}", i + 1),
            min_position: l.min,
            max_position: l.max,
            max_velocity: l.vel,
            max_acceleration: l.acc,
            max_jerk: l.jerk,
        })
        .collect();
    let plan = Planner::new(machine).unwrap().plan(&request).unwrap();
    let first = plan.joint_trajectory().points[0].positions.clone();
    Setup {
        world,
        limits,
        lipschitz,
        first,
    }
}

/// The certifier's distance: exact below the cutoff (clearance plus the farthest any head
/// point moves in one period at the velocity limits), the cutoff above it.
fn distance(s: &Setup, q: &[f64]) -> Clearance {
    let cutoff = CLEARANCE
        + PERIOD
            * s.lipschitz
                .iter()
                .zip(&s.limits)
                .map(|(l, j)| l * j.max_velocity)
                .sum::<f64>();
    let Ok(q6) = <[f64; 6]>::try_from(q) else {
        return Clearance::new(f64::NAN, "a configuration of 6 joints");
    };
    match s.world.distance_up_to(&q6, cutoff) {
        Ok(Some(d)) => Clearance::new(d.distance, format!("workpiece (head link {})", d.link)),
        Ok(None) => Clearance::new(cutoff, "workpiece"),
        Err(_) => Clearance::new(f64::NAN, "workpiece"),
    }
}

fn settings(s: &Setup) -> ApproachSettings {
    ApproachSettings::builder()
        .clearance(CLEARANCE)
        .control_period(PERIOD)
        .lipschitz(s.lipschitz.clone())
        .build()
        .unwrap()
}

/// `q` with `shift` added to each joint, or subtracted where that would leave its range.
fn shifted(q: &[f64], shift: &[f64], limits: &[JointLimit]) -> Vec<f64> {
    q.iter()
        .zip(shift)
        .zip(limits)
        .map(|((q, d), l)| {
            if q + d <= l.max_position {
                q + d
            } else {
                q - d
            }
        })
        .collect()
}

#[test]
fn an_approach_to_case_1_is_certified_on_the_real_head_and_part() {
    let s = setup();
    // The safe pose: 0.3 m above the first point on the vertical gantry axis q3, the head as
    // it cuts; the start: off to the side from there, the wrist turned.
    let safe = shifted(&s.first, &[0.0, 0.0, 0.3, 0.0, 0.0, 0.0], &s.limits);
    let start = shifted(&safe, &[0.15, 0.15, 0.0, 0.3, 0.3, 0.0], &s.limits);
    let world = |q: &[f64]| distance(&s, q);
    for (what, q) in [
        ("start", &start),
        ("safe pose", &safe),
        ("first point", &s.first),
    ] {
        let q6: [f64; 6] = q.clone().try_into().unwrap();
        eprintln!(
            "{what}: {:.4} m from the part",
            s.world.distance(&q6).unwrap().distance
        );
    }
    let settings = ApproachSettings::builder()
        .clearance(CLEARANCE)
        .control_period(PERIOD)
        .lipschitz(s.lipschitz.clone())
        .safe_pose(safe.clone())
        .build()
        .unwrap();
    let planner = ApproachPlanner::new(settings, s.limits.clone(), &world).unwrap();
    let started = std::time::Instant::now();
    let checked = planner.approach(&start, &s.first).unwrap();
    eprintln!(
        "approach certified in {:.3} s: {:?}, {:.3} s long, closest {:.4} m ({})",
        started.elapsed().as_secs_f64(),
        checked.route,
        checked.path.duration(),
        checked.closest.distance,
        checked.closest.obstacle
    );
    // Re-checked at 1 ms with the exact distance, and against the velocity limits.
    let samples = checked.path.samples(0.001).unwrap();
    for p in &samples {
        let q: [f64; 6] = p.q.clone().try_into().unwrap();
        let d = s.world.distance(&q).unwrap().distance;
        assert!(d >= CLEARANCE - 1e-9, "t = {} s: {d} m", p.t);
        for (v, l) in p.qd.iter().zip(&s.limits) {
            assert!(
                v.abs() <= l.max_velocity * (1.0 + 1e-9),
                "{v} over {}",
                l.name
            );
        }
    }
    let last = &samples.last().unwrap().q;
    assert!(last.iter().zip(&s.first).all(|(a, b)| (a - b).abs() < 1e-9));
}

#[test]
fn approaches_into_the_part_are_refused_naming_it() {
    let s = setup();
    let world = |q: &[f64]| distance(&s, q);
    let planner = ApproachPlanner::new(settings(&s), s.limits.clone(), &world).unwrap();
    // The head lowered 5 cm into the part: the start is in collision.
    let mut inside = s.first.clone();
    inside[2] -= 0.05;
    let q: [f64; 6] = inside.clone().try_into().unwrap();
    assert!(s.world.distance(&q).unwrap().distance < CLEARANCE);
    let e = planner.approach(&inside, &s.first).unwrap_err().to_string();
    assert!(e.contains("start") && e.contains("workpiece"), "{e}");
    // From beside and above the first point with the wrist turned, the direct move sweeps the
    // nozzle through the part, and no safe pose is configured: refused, naming the workpiece,
    // the time and the configuration.
    let beside = shifted(&s.first, &[0.15, 0.15, 0.15, 0.3, 0.3, 0.0], &s.limits);
    let e = planner.approach(&beside, &s.first).unwrap_err().to_string();
    eprintln!("{e}");
    assert!(e.contains("workpiece"), "{e}");
}
