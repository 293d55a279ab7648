//! RTOs as boxes inside the feasible domain (issue 16, item 3): the box of
//! free, lead/tilt-feasible GFD samples (`Gfd::free_box`), the QPs'
//! interval constraints, and whole plans with `options.rto_constraint`
//! `box` against the paper's `equality` on case 1, case 2 and a tube saddle
//! (`common::saddle`: collisions of the head's fork with the main tube and
//! a 30° turn of the nominal axis force RTO insertions in the paper's loop).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_bspline::{BSpline, KnotVector};
use kerf_budget::Budget;
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::gfd::{Gfd, GridBox};
use kerf_mjto::kinematics::{forward, tool_axis};
use kerf_mjto::mesh::load;
use kerf_mjto::orientation::PathFrames;
use kerf_mjto::planner::Planner;
use kerf_mjto::request::RtoConstraint;
use kerf_mjto::rotary::{JerkFactor, RotaryQp};
use kerf_mjto::standoff::{solve_standoff, MPathProblem};
use kerf_mjto::{AxisLimits, CutPlan, CutRequest, LaserMachine, PlanError};

mod common;
use common::case;
use common::saddle::{Saddle, TempMesh};

fn machine() -> LaserMachine {
    LaserMachine::default_machine().unwrap()
}

fn world_of(request: &CutRequest) -> CollisionWorld {
    let head = HeadModel::from_urdf(machine().robot().urdf()).unwrap();
    CollisionWorld::new(
        head,
        &load(&request.mesh).unwrap(),
        &request.workpiece_pose.isometry().unwrap(),
        request.options.clearance,
    )
    .unwrap()
}

/// The GFD of CL point `i` of a request, centred on the nominal axis at the
/// reference standoff, as the planner builds it.
fn gfd_at(request: &CutRequest, i: usize) -> (Gfd, PathFrames) {
    let v = request.validate().unwrap();
    let frames = PathFrames::new(&v.points, &v.axes, &v.u);
    let o = v.axes[i];
    let q5 = o.z.clamp(-1.0, 1.0).acos();
    let q4 = o.y.atan2(o.x);
    let m = machine();
    let g = Gfd::build(
        i,
        v.u[i],
        &v.points[i],
        [q4, q5, request.options.reference_standoff],
        &request.options.gfd,
        &request.options.weights,
        request.max_lead_angle,
        request.max_tilt_angle,
        &|a| frames.lead_tilt_at(i, a),
        m.limits(),
    );
    (g, frames)
}

/// Every sample of the box is a candidate, free in a fresh world, inside
/// lead/tilt, joint ranges and strokes; the box's corners are grid values;
/// and every face that could still grow is blocked by a rejected or
/// colliding sample. Returns the number of faces a colliding sample blocks.
#[allow(clippy::too_many_arguments)]
fn check_box(
    name: &str,
    g: &Gfd,
    b: &GridBox,
    frames: &PathFrames,
    request: &CutRequest,
    world: &CollisionWorld,
    max_steps: [usize; 3],
    start: [usize; 3],
) -> usize {
    let limits = *machine().limits();
    let axes = g.grid_axes();
    for k in 0..3 {
        assert_eq!(b.lo[k], axes[k][b.lo_index[k]], "{name}");
        assert_eq!(b.hi[k], axes[k][b.hi_index[k]], "{name}");
        assert!(b.lo_index[k] <= start[k] && start[k] <= b.hi_index[k]);
    }
    let samples = g.box_candidates(b);
    assert!(!samples.is_empty());
    for c in &samples {
        let c = c.expect("every box sample is a candidate");
        let q = g.joint_vector(c);
        assert!(world.is_free(&q), "{name}: box sample {q:?} collides");
        let (lead, tilt) = frames.lead_tilt_at(g.cl_index, &tool_axis(q[3], q[4]));
        assert!(lead.abs() <= request.max_lead_angle && tilt.abs() <= request.max_tilt_angle);
        for (j, l) in limits.iter().enumerate() {
            assert!(
                q[j] >= l.min && q[j] <= l.max,
                "{name}: q{} = {}",
                j + 1,
                q[j]
            );
        }
        assert!(b.contains(&g.candidates[c].q, 0.0));
    }
    // Maximal: each face is at the grid's end, at max_steps, or its next
    // layer holds a rejected or colliding sample.
    let mut by_collision = 0;
    for k in 0..3 {
        for up in [false, true] {
            let next = if up {
                (b.hi_index[k] + 1 < axes[k].len() && b.hi_index[k] - start[k] < max_steps[k])
                    .then(|| b.hi_index[k] + 1)
            } else {
                (b.lo_index[k] > 0 && start[k] - b.lo_index[k] < max_steps[k])
                    .then(|| b.lo_index[k] - 1)
            };
            let Some(layer) = next else { continue };
            let (mut lo, mut hi) = (b.lo_index, b.hi_index);
            lo[k] = layer;
            hi[k] = layer;
            let layer_box = GridBox {
                lo_index: lo,
                hi_index: hi,
                ..*b
            };
            let layer = g.box_candidates(&layer_box);
            let collides = layer
                .iter()
                .any(|c| c.is_some_and(|c| !world.is_free(&g.joint_vector(c))));
            let blocked = collides || layer.iter().any(Option::is_none);
            assert!(blocked, "{name}: face {k} {up} could grow");
            by_collision += usize::from(collides);
        }
    }
    by_collision
}

#[test]
fn the_box_holds_only_free_feasible_samples_and_is_maximal() {
    let saddle = Saddle::default();
    let mesh = TempMesh::new("box", &saddle.mesh());
    let request = saddle.request(&mesh.reference(), 0.1);
    let world = world_of(&request);
    let budget = Budget::unlimited();
    let mut limited = 0;
    let mut by_collision = 0;
    // Every tenth CL point of the loop: beside the rib, on the flanks and
    // through the vertical.
    for i in (0..request.points.len()).step_by(10) {
        let (mut g, frames) = gfd_at(&request, i);
        let Some(p) = g
            .nearest_free(g.reference, &request.options.weights, &world, &budget)
            .unwrap()
        else {
            continue;
        };
        let start = g.grid_index(p).unwrap();
        for steps in [[2, 2, 1], [6, 4, 2]] {
            let b = g
                .free_box(p, steps, None, &world, &budget)
                .unwrap()
                .unwrap();
            by_collision += check_box(
                &format!("CL {i}"),
                &g,
                &b,
                &frames,
                &request,
                &world,
                steps,
                start,
            );
            let size: usize = (0..3).map(|k| b.hi_index[k] - b.lo_index[k] + 1).product();
            let full: usize = (0..3)
                .map(|k| {
                    (start[k] + steps[k]).min(g.grid_axes()[k].len() - 1) + 1
                        - start[k].saturating_sub(steps[k])
                })
                .product();
            if size < full {
                limited += 1;
            }
        }
        // Grown away from a configuration: never towards it on an axis
        // where the candidate differs from it.
        let q = g.candidates[p].q;
        let away = [q[0] + 1.0, q[1] - 1.0, q[2]];
        let b = g
            .free_box(p, [6, 4, 2], Some(away), &world, &budget)
            .unwrap()
            .unwrap();
        assert_eq!(b.hi[0], q[0]);
        assert_eq!(b.lo[1], q[1]);
    }
    // Not trivial: on some points the lead/tilt limits or collisions (the
    // rib, the tube) stop a box.
    assert!(limited > 0);
    assert!(by_collision > 0);
}

#[test]
fn the_rotary_qp_stays_inside_its_boxes_and_no_jerkier_than_equality() {
    let knots = KnotVector::clamped_uniform(5, 20).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let limits = AxisLimits {
        min: -3.0,
        max: 3.0,
        vel: 10.0,
        acc: 100.0,
        jerk: 1e4,
    };
    // A zig-zag of picks; the boxes ±0.05 rad around them.
    let picks = [
        (0.0, 0.0),
        (0.2, 0.1),
        (0.4, -0.05),
        (0.6, 0.12),
        (0.8, -0.02),
        (1.0, 0.0),
    ];
    let boxes: Vec<(f64, f64, f64)> = picks
        .iter()
        .map(|&(u, q)| (u, q - 0.05, q + 0.05))
        .collect();
    let base = RotaryQp {
        axis_name: "q5",
        knots: &knots,
        factor: &factor,
        limits,
        sigma: 0.5,
        feedrate: 0.1,
        boundary: [0.0; 4],
        via: &picks,
        via_box: &[],
        corridor: &[],
        free_end_slopes: false,
    };
    let (eq, _) = base.solve().unwrap();
    let (bx, _) = RotaryQp {
        via: &[],
        via_box: &boxes,
        ..base
    }
    .solve()
    .unwrap();
    let spline = BSpline::new(knots.clone(), bx.clone()).unwrap();
    for &(u, lo, hi) in &boxes {
        let q = spline.eval(u)[0];
        assert!(
            q >= lo - 1e-7 && q <= hi + 1e-7,
            "q({u}) = {q} outside [{lo}, {hi}]"
        );
    }
    let (j_eq, j_box) = (factor.jerk_cost(&eq), factor.jerk_cost(&bx));
    assert!(j_box < 0.5 * j_eq, "box {j_box} vs equality {j_eq}");
    // A zero-width box is the equality.
    let points: Vec<(f64, f64, f64)> = picks.iter().map(|&(u, q)| (u, q, q)).collect();
    let (pt, _) = RotaryQp {
        via: &[],
        via_box: &points,
        ..base
    }
    .solve()
    .unwrap();
    let max_diff = eq
        .iter()
        .zip(&pt)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(max_diff < 1e-6, "{max_diff}");
    // An empty interval is bad input.
    let bad = [(0.5, 0.2, 0.1)];
    assert!(matches!(
        RotaryQp {
            via: &[],
            via_box: &bad,
            ..base
        }
        .solve(),
        Err(PlanError::InvalidRequest { .. })
    ));
}

#[test]
fn the_m_path_qp_stays_inside_its_q6_intervals() {
    // A straight 0.2 m cut along x with the axis turning in the x-z plane.
    let n = 40;
    let params: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
    let points: Vec<nalgebra::Vector3<f64>> = params
        .iter()
        .map(|&u| nalgebra::Vector3::new(0.5 + 0.2 * u, 0.5, 0.5))
        .collect();
    let axes: Vec<nalgebra::Vector3<f64>> = params
        .iter()
        .map(|&u| tool_axis(0.0, 0.3 * (6.0 * u).sin()))
        .collect();
    let knots = KnotVector::for_parameters(5, 14, &params).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let via = [(0usize, -0.07), (13, -0.055), (26, -0.085), (39, -0.07)];
    let via_box: Vec<(usize, f64, f64)> = via
        .iter()
        .map(|&(i, v)| (i, v - 0.015, v + 0.015))
        .collect();
    let base = MPathProblem {
        knots: &knots,
        factor: &factor,
        params: &params,
        points: &points,
        axes: &axes,
        stroke: (-0.1, 0.02),
        via: &via,
        via_box: &[],
        reference: -0.07,
    };
    let eq = solve_standoff(&base).unwrap();
    for &(i, v) in &via {
        assert!((eq.w[i] - v).abs() < 1e-6);
    }
    let bx = solve_standoff(&MPathProblem {
        via: &[],
        via_box: &via_box,
        ..base
    })
    .unwrap();
    for &(i, lo, hi) in &via_box {
        assert!(
            bx.w[i] >= lo - 1e-7 && bx.w[i] <= hi + 1e-7,
            "w[{i}] = {}",
            bx.w[i]
        );
    }
    // Looser constraints: the M path's jerk is not larger.
    let jerk = |s: &[Vec<f64>; 3]| -> f64 { s.iter().map(|c| factor.jerk_cost(c)).sum() };
    assert!(jerk(&bx.control_points) <= jerk(&eq.control_points) * (1.0 + 1e-6));
    let bad = [(5usize, -0.05, -0.06)];
    assert!(solve_standoff(&MPathProblem {
        via: &[],
        via_box: &bad,
        ..base
    })
    .is_err());
}

/// Independent checks of a plan: planner verdicts, a fresh world at every
/// sample, lead/tilt at every sample.
fn check_plan(name: &str, request: &CutRequest, plan: &CutPlan) {
    assert!(
        plan.metrics.within_limits,
        "{name}: {:?}",
        plan.metrics.limit_violations
    );
    assert_eq!(plan.metrics.colliding_samples, 0);
    let world = world_of(request);
    let v = request.validate().unwrap();
    let frames = PathFrames::new(&v.points, &v.axes, &v.u);
    let law = kerf_mjto::timelaw::TimeLaw::new(
        v.sigma,
        request.feedrate,
        request.feed_acceleration,
        request.feed_jerk,
    )
    .unwrap();
    let limits = machine().limits().to_owned();
    for (k, (q, &t)) in plan.positions.iter().zip(&plan.times).enumerate() {
        assert!(world.is_free(q), "{name}: sample {k} collides");
        let u = (law.eval(t)[0] / v.sigma).clamp(0.0, 1.0);
        let (lead, tilt) = frames.lead_tilt(u, &forward(q).1);
        assert!(
            lead.abs() <= request.max_lead_angle * (1.0 + 1e-9),
            "{name}: lead at {k}"
        );
        assert!(
            tilt.abs() <= request.max_tilt_angle * (1.0 + 1e-9),
            "{name}: tilt at {k}"
        );
        for (j, l) in limits.iter().enumerate() {
            assert!(plan.velocities[k][j].abs() <= l.vel * (1.0 + 1e-6));
            assert!(plan.accelerations[k][j].abs() <= l.acc * (1.0 + 1e-6));
        }
    }
    for (j, l) in limits.iter().enumerate() {
        assert!(
            plan.metrics.peak_jerk[j] <= l.jerk * (1.0 + 1e-6),
            "{name}: q{} jerk",
            j + 1
        );
    }
}

/// Plans `request` with both RTO constraints; returns (equality, box).
fn both(request: &CutRequest) -> (CutPlan, CutPlan) {
    let mut planner = Planner::new(machine()).unwrap();
    let mut r = request.clone();
    r.options.rto_constraint = RtoConstraint::Equality;
    let eq = planner.plan(&r).unwrap();
    r.options.rto_constraint = RtoConstraint::Box;
    let bx = planner.plan(&r).unwrap();
    (eq, bx)
}

fn report(name: &str, eq: &CutPlan, bx: &CutPlan) {
    for (what, p) in [("equality", eq), ("box", bx)] {
        println!(
            "{name} {what}: RMS jerk q4 {:.3} q5 {:.3} rad/s³, peak q4 {:.3} q5 {:.3}, {} RTOs, {} iterations",
            p.metrics.rms_jerk[3],
            p.metrics.rms_jerk[4],
            p.metrics.peak_jerk[3],
            p.metrics.peak_jerk[4],
            p.rtos.len(),
            p.iterations
        );
    }
}

#[test]
fn case1_and_case2_with_boxes_are_valid_and_no_jerkier_than_equality() {
    for name in ["case1", "case2"] {
        let request = case(name);
        let (eq, bx) = both(&request);
        report(name, &eq, &bx);
        check_plan(name, &request, &bx);
        check_plan(name, &request, &eq);
        for j in [3, 4] {
            assert!(
                bx.metrics.rms_jerk[j] <= eq.metrics.rms_jerk[j] * (1.0 + 1e-9),
                "{name}: q{} RMS jerk box {} > equality {}",
                j + 1,
                bx.metrics.rms_jerk[j],
                eq.metrics.rms_jerk[j]
            );
        }
    }
}

#[test]
fn a_saddle_beside_a_rib_loses_its_q5_zig_zags_with_boxes() {
    let saddle = Saddle::default();
    let mesh = TempMesh::new("plan", &saddle.mesh());
    let request = saddle.request(&mesh.reference(), 0.1);
    let (eq, bx) = both(&request);
    report("saddle", &eq, &bx);
    check_plan("saddle equality", &request, &eq);
    check_plan("saddle box", &request, &bx);
    // The rib forces insertions in the paper's loop.
    assert!(eq.rtos.iter().any(|r| r.inserted_at_iteration > 0));
    assert!(
        bx.metrics.rms_jerk[4] < 0.8 * eq.metrics.rms_jerk[4],
        "q5 RMS jerk box {} vs equality {}",
        bx.metrics.rms_jerk[4],
        eq.metrics.rms_jerk[4]
    );
    // At the 10 m/min the boxes still give a valid plan (the
    // equalities were INFEASIBLE there when this was written: q4 jerk bounds,
    // largest feasible feed 4.3 m/min, BENCHMARKS.md).
    let fast = saddle.request(&mesh.reference(), 10.0 / 60.0);
    let plan = Planner::new(machine()).unwrap().plan(&fast).unwrap();
    check_plan("saddle box 10 m/min", &fast, &plan);
}

#[test]
fn the_option_parses_defaults_to_box_and_refuses_other_text() {
    let base = "points: [[0, 0, 0], [0.1, 0, 0]]\naxes: [[0, 0, 1], [0, 0, 1]]\n\
                feedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
                max_tilt_angle: 0.1\nmesh: m.stl\n";
    let r = CutRequest::from_yaml(base).unwrap();
    assert_eq!(r.options.rto_constraint, RtoConstraint::Box);
    for (text, want) in [
        ("equality", RtoConstraint::Equality),
        ("box", RtoConstraint::Box),
    ] {
        let r =
            CutRequest::from_yaml(&format!("{base}options: {{rto_constraint: {text}}}\n")).unwrap();
        assert_eq!(r.options.rto_constraint, want);
        assert_eq!(RtoConstraint::parse(text).unwrap(), want);
        assert_eq!(want.as_str(), text);
    }
    // The default is not written, so request files written before the
    // option read and write the same.
    let base_request = CutRequest::from_yaml(base).unwrap();
    assert!(!serde_yaml_ng::to_string(&base_request)
        .unwrap()
        .contains("rto_constraint"));
    for bad in ["Box", "boxes", "1"] {
        let e = CutRequest::from_yaml(&format!("{base}options: {{rto_constraint: {bad}}}\n"))
            .unwrap_err();
        assert!(matches!(e, PlanError::InvalidRequest { .. }), "{e}");
        assert!(e.to_string().contains("rto_constraint"), "{bad}: {e}");
        let e = RtoConstraint::parse(bad).unwrap_err();
        assert!(e.to_string().contains("options.rto_constraint"), "{e}");
    }
    assert_eq!(RtoConstraint::parse("").unwrap(), RtoConstraint::Box);
}

#[test]
fn the_corridor_option_parses_defaults_to_allowance_and_refuses_other_text() {
    use kerf_mjto::request::OrientationCorridor;
    let base = "points: [[0, 0, 0], [0.1, 0, 0]]\naxes: [[0, 0, 1], [0, 0, 1]]\n\
                feedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
                max_tilt_angle: 0.1\nmesh: m.stl\n";
    let r = CutRequest::from_yaml(base).unwrap();
    assert_eq!(
        r.options.orientation_corridor,
        OrientationCorridor::Allowance
    );
    for (text, want) in [
        ("none", OrientationCorridor::None),
        ("allowance", OrientationCorridor::Allowance),
    ] {
        let r = CutRequest::from_yaml(&format!(
            "{base}options: {{orientation_corridor: {text}}}\n"
        ))
        .unwrap();
        assert_eq!(r.options.orientation_corridor, want);
        assert_eq!(OrientationCorridor::parse(text).unwrap(), want);
        assert_eq!(want.as_str(), text);
    }
    // The default is not written: request files written before the option read the same.
    assert!(!serde_yaml_ng::to_string(&r)
        .unwrap()
        .contains("orientation_corridor"));
    for bad in ["Allowance", "off", "1"] {
        let e = CutRequest::from_yaml(&format!("{base}options: {{orientation_corridor: {bad}}}\n"))
            .unwrap_err();
        assert!(e.to_string().contains("orientation_corridor"), "{bad}: {e}");
        let e = OrientationCorridor::parse(bad).unwrap_err();
        assert!(
            e.to_string().contains("options.orientation_corridor"),
            "{e}"
        );
    }
    assert_eq!(
        OrientationCorridor::parse("").unwrap(),
        OrientationCorridor::Allowance
    );
}
