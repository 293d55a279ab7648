//! The job-shop parts and cut requests of issue 16 item 4 (`kerf_testparts::jobshop`,
//! `crates/mjto/cases/jobshop/*.yaml`, `urdf/meshes/jobshop_*.obj`): committed files equal the
//! generator, meshes closed and outward, CL points on the surface, axes unit and normal,
//! closed contours closed, spacing f Δt, every request valid, and the geometric claims each
//! case's expected answer rests on (checked with the planner's collision world, no planning).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;
use support::{closest_on_triangle, repo_root, tri, v};

use std::collections::HashMap;

use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::kinematics::tool_axis;
use kerf_mjto::mesh::{self, MeshData};
use kerf_mjto::{CutRequest, LaserMachine};
use kerf_testparts::jobshop::{self, Expectation, JobShop, JobShopCase, Part};
use nalgebra::Vector3;

fn shop() -> JobShop {
    jobshop::generate().unwrap()
}

fn committed(case: &JobShopCase) -> CutRequest {
    let file = case.file();
    let text = std::fs::read_to_string(repo_root().join(&file))
        .unwrap_or_else(|e| panic!("{file}: {e} (run the gen_jobshop example)"));
    CutRequest::from_yaml(&text).unwrap_or_else(|e| panic!("{file}: {e}"))
}

fn committed_mesh(part: &Part) -> MeshData {
    mesh::load(&part.mesh_reference()).unwrap()
}

/// Distance from p to the mesh and the unit normals of every triangle within 1e-9 m of the
/// nearest distance (a point on a facet edge has two).
fn nearest(mesh: &MeshData, p: &Vector3<f64>) -> (f64, Vec<Vector3<f64>>) {
    let hits: Vec<(f64, Vector3<f64>)> = mesh
        .triangles
        .iter()
        .map(|t| {
            let abc = tri(mesh, t);
            let d = (closest_on_triangle(p, &abc) - p).norm();
            (d, (abc[1] - abc[0]).cross(&(abc[2] - abc[0])).normalize())
        })
        .collect();
    let best = hits.iter().map(|h| h.0).fold(f64::INFINITY, f64::min);
    let normals = hits
        .into_iter()
        .filter(|h| h.0 <= best + 1e-9)
        .map(|h| h.1)
        .collect();
    (best, normals)
}

#[test]
fn committed_files_equal_the_generator_output() {
    let dir = std::env::temp_dir().join(format!("kerf_jobshop_test_{}", std::process::id()));
    let (shop, written) = jobshop::write_files(&dir).unwrap();
    assert_eq!(written.len(), shop.parts.len() + shop.cases.len());
    for (rel, path) in &written {
        let fresh = std::fs::read(path).unwrap();
        let committed = std::fs::read(repo_root().join(rel)).unwrap_or_default();
        assert!(
            fresh == committed,
            "{rel} is stale: regenerate it with `{}`",
            jobshop::REGENERATE_COMMAND
        );
    }
    // No stray committed request: every yaml under cases/jobshop is a case.
    let listed: Vec<String> = std::fs::read_dir(repo_root().join("crates/mjto/cases/jobshop"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(listed.len(), shop.cases.len(), "{listed:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn meshes_are_closed_outward_small_and_as_thick_as_stated() {
    for part in &shop().parts {
        let mesh = committed_mesh(part);
        assert_eq!(
            mesh, part.mesh,
            "{}: the committed mesh loads as generated",
            part.name
        );
        assert!(
            mesh.triangles.len() <= jobshop::MAX_TRIANGLES,
            "{}: {} triangles",
            part.name,
            mesh.triangles.len()
        );
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &mesh.triangles {
            let abc = tri(&mesh, t);
            let area = 0.5 * (abc[1] - abc[0]).cross(&(abc[2] - abc[0])).norm();
            assert!(
                area > 1e-8,
                "{}: degenerate triangle {t:?} ({area:e} m²)",
                part.name
            );
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "{}: directed edge {a}->{b} used {n} times", part.name);
            assert_eq!(
                directed.get(&(b, a)),
                Some(&1),
                "{}: edge {a}->{b} has no opposite (open or inconsistently oriented)",
                part.name
            );
        }
        // Divergence theorem: V = Σ a · (b × c) / 6 over outward triangles; a thin solid has
        // V ≈ (head-side area) × thickness (the head-side vertices are the first half).
        let half = (mesh.vertices.len() / 2) as u32;
        let volume: f64 = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = tri(&mesh, t);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum();
        let area: f64 = mesh
            .triangles
            .iter()
            .filter(|t| t.iter().all(|&k| k < half))
            .map(|t| {
                let [a, b, c] = tri(&mesh, t);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum();
        let rel = volume / (area * part.thickness) - 1.0;
        assert!(volume > 0.0, "{}: signed volume {volume}", part.name);
        assert!(
            rel.abs() < 0.05,
            "{}: volume {volume:e} vs area {area} × {} ({:.2} % off)",
            part.name,
            part.thickness,
            rel * 100.0
        );
        assert!(
            (0.0015..=0.005).contains(&part.thickness),
            "{}: {} m is not a job-shop sheet or tube wall",
            part.name,
            part.thickness
        );
        println!(
            "{}: {} triangles, thickness {} m, volume/area {:.5} m",
            part.name,
            mesh.triangles.len(),
            part.thickness,
            volume / area
        );
    }
}

#[test]
fn cl_points_lie_on_the_surface_with_normal_unit_axes() {
    let shop = shop();
    for case in &shop.cases {
        let part = shop.part_of(case).unwrap();
        let mesh = committed_mesh(part);
        let req = committed(case);
        let (mut worst_d, mut worst_a) = (0.0f64, 0.0f64);
        for (i, (p, a)) in req.points.iter().zip(&req.axes).enumerate() {
            let axis = v(a);
            assert!((axis.norm() - 1.0).abs() < 1e-9, "{} axis {i}", case.name);
            let (d, normals) = nearest(&mesh, &v(p));
            assert!(
                d <= part.surface_tolerance,
                "{} point {i} is {d:e} m off the mesh (tolerance {:e})",
                case.name,
                part.surface_tolerance
            );
            // The axis is the outward normal of the facet under the point (on an edge, of
            // one of the two), within the angle a facet spans.
            let angle = normals
                .iter()
                .map(|n| n.dot(&axis).clamp(-1.0, 1.0).acos())
                .fold(f64::INFINITY, f64::min);
            assert!(
                angle <= part.axis_tolerance,
                "{} point {i}: axis {:.3e} rad from the facet normal (allowance {:.3e})",
                case.name,
                angle,
                part.axis_tolerance
            );
            worst_d = worst_d.max(d);
            worst_a = worst_a.max(angle);
        }
        println!(
            "{}: {} points, worst distance {worst_d:.2e} m, worst axis-facet angle {worst_a:.2e} rad",
            case.name,
            req.points.len()
        );
    }
}

/// The analytic normal of each part at a point of its head-side surface.
fn analytic_normal(part: &str, p: &Vector3<f64>) -> Vector3<f64> {
    match part {
        "tube" => Vector3::new(0.0, p.y, p.z).normalize(),
        "panel" => {
            let r = jobshop::PanelParams::default().radius;
            Vector3::new(0.0, p.y, p.z + r).normalize()
        }
        _ => Vector3::z(),
    }
}

#[test]
fn axes_are_the_surface_normals_and_contours_close() {
    let shop = shop();
    for case in &shop.cases {
        let req = committed(case);
        for (i, (p, a)) in req.points.iter().zip(&req.axes).enumerate() {
            // Points are rounded to 1 nm: on the 50 mm tube that turns the normal computed
            // from them by up to 2e-8 rad.
            let err = (v(a) - analytic_normal(case.part, &v(p))).norm();
            assert!(
                err < 1e-7,
                "{} axis {i} is {err:e} off the normal",
                case.name
            );
        }
        let (first, last) = (req.points[0], *req.points.last().unwrap());
        if case.closed {
            assert_eq!(
                first, last,
                "{}: a closed contour ends where it starts",
                case.name
            );
            assert_eq!(req.axes[0], *req.axes.last().unwrap(), "{}", case.name);
        } else {
            assert!((v(&first) - v(&last)).norm() > 0.05, "{}", case.name);
        }
    }
}

#[test]
fn points_are_spaced_at_feedrate_times_period() {
    for case in &shop().cases {
        let req = committed(case);
        let h = req.feedrate * req.sample_period;
        let n = req.points.len() - 1;
        for (i, w) in req.points.windows(2).enumerate() {
            let d = (v(&w[1]) - v(&w[0])).norm();
            // Chords of a curved path are shorter than the arc step; a closed contour splits
            // its length into the smallest whole number n of steps ≤ f Δt (at most 1/n
            // shorter).
            let low = h * (1.0 - 1.0 / n as f64) * (1.0 - 2e-3);
            assert!(
                d <= h * (1.0 + 1e-6) && d >= low,
                "{} step {i}: {d} m, f Δt = {h} m",
                case.name
            );
        }
    }
}

#[test]
fn every_request_validates_with_job_shop_parameters() {
    let shop = shop();
    assert!(shop.cases.len() >= 12);
    for case in &shop.cases {
        let req = committed(case);
        let val = req
            .validate()
            .unwrap_or_else(|e| panic!("{}: {e}", case.name));
        assert_eq!(
            req, case.request,
            "{}: the file parses to the generated request",
            case.name
        );
        assert_eq!(req.mesh, shop.part_of(case).unwrap().mesh_reference());
        let feed = req.feedrate * 60.0;
        match case.expect {
            Expectation::Infeasible { .. } => assert!(feed > 100.0, "{}", case.name),
            _ => assert!((5.0..=20.0).contains(&feed), "{}: {feed} m/min", case.name),
        }
        assert!((req.max_lead_angle.to_degrees() - 10.0).abs() < 1e-9);
        assert!((req.max_tilt_angle.to_degrees() - 10.0).abs() < 1e-9);
        assert!(
            (20..=600).contains(&req.points.len()),
            "{}: {} points",
            case.name,
            req.points.len()
        );
        // The nominal M points are well inside the strokes.
        let lim = *LaserMachine::default_machine().unwrap().limits();
        for (c, o) in val.points.iter().zip(&val.axes) {
            let m = c + o * 0.07;
            for k in 0..3 {
                assert!(
                    m[k] > lim[k].min + 0.1 && m[k] < lim[k].max - 0.1,
                    "{}",
                    case.name
                );
            }
        }
    }
}

#[test]
fn saddles_pass_the_tool_axis_through_the_vertical_twice() {
    let shop = shop();
    let r_main = jobshop::TubeParams::default().radius;
    let mut ratios = Vec::new();
    for case in shop.cases.iter().filter(|c| c.part == "tube") {
        let req = committed(case);
        let ys: Vec<f64> = req.axes.iter().map(|a| a[1]).collect();
        let crossings = ys
            .windows(2)
            .filter(|w| (w[0] > 0.0 && w[1] <= 0.0) || (w[0] < 0.0 && w[1] >= 0.0))
            .count();
        // Starting on the vertical (y = 0), the loop crosses it once in the middle and comes
        // back to it at the end.
        assert_eq!(ys[0], 0.0, "{}", case.name);
        assert_eq!(crossings, 2, "{}: {crossings} crossings", case.name);
        let ratio = req
            .points
            .iter()
            .map(|p| p[0].hypot(p[1]))
            .fold(0.0, f64::max)
            / r_main;
        let tilt = ys.iter().map(|y| y.abs().asin()).fold(0.0, f64::max);
        assert!(
            (tilt - ratio.asin()).abs() < 1e-3,
            "{}: tilt {tilt}",
            case.name
        );
        ratios.push((ratio * 100.0).round() / 100.0);
    }
    assert_eq!(ratios, [0.4, 0.7, 0.95]);
}

/// The head and a case's workpiece, in the machine frame.
struct Scene {
    world: CollisionWorld,
    points: Vec<Vector3<f64>>,
}

impl Scene {
    fn new(shop: &JobShop, name: &str) -> Self {
        let case = shop.cases.iter().find(|c| c.name == name).unwrap();
        let req = committed(case);
        let val = req.validate().unwrap();
        let machine = LaserMachine::default_machine().unwrap();
        let head = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
        let mesh = committed_mesh(shop.part_of(case).unwrap());
        let world = CollisionWorld::new(head, &mesh, &val.workpiece_pose, 0.0).unwrap();
        Self {
            world,
            points: val.points,
        }
    }

    /// Free with the tool axis (q4, q5) and standoff q6 at CL point `c`?
    fn free(&self, c: &Vector3<f64>, q4: f64, q5: f64, q6: f64) -> bool {
        let m = c - tool_axis(q4, q5) * q6;
        self.world.is_free(&[m.x, m.y, m.z, q4, q5, q6])
    }

    /// Free for some axis inside the lead/tilt box of ±`allowance` about the vertical and
    /// some standoff? Axes `normalize(z + a x + b y)`, |a|, |b| ≤ tan(allowance), 2.5° steps
    /// (q4 swept over a half turn at the vertical), q6 from −0.1 to 0.02 m in 20 mm steps.
    fn any_free(&self, c: &Vector3<f64>, allowance: f64) -> bool {
        let steps = (allowance.to_degrees() / 2.5).round() as i32;
        let q6s = [-0.1, -0.08, -0.06, -0.04, -0.02, 0.0, 0.02];
        for i in -steps..=steps {
            for j in -steps..=steps {
                let (a, b) = (
                    (allowance * i as f64 / steps as f64).tan(),
                    (allowance * j as f64 / steps as f64).tan(),
                );
                let o = Vector3::new(a, b, 1.0).normalize();
                let q4s: Vec<f64> = if i == 0 && j == 0 {
                    (0..18).map(|k| (k as f64 * 10.0).to_radians()).collect()
                } else {
                    vec![o.y.atan2(o.x)]
                };
                let q5 = o.z.clamp(-1.0, 1.0).acos();
                for &q4 in &q4s {
                    if q6s.iter().any(|&q6| self.free(c, q4, q5, q6)) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Case 5: next to the angle's tall wall the nominal (vertical) axis collides at every q4 and
/// standoff, and an 8° tilt away from the wall (inside the 10° allowance, fork arms along the
/// cut) is free at every CL point.
#[test]
fn wall_cases_nominal_axis_collides_and_a_tilt_inside_the_allowance_clears() {
    let shop = shop();
    let away = -8f64.to_radians(); // q4 = 90°: O = (0, sin q5, cos q5) leans to −y, off the wall
    for name in ["angle_wall_trim", "angle_wall_hole"] {
        let scene = Scene::new(&shop, name);
        let mut colliding = 0;
        for (i, c) in scene.points.iter().enumerate() {
            assert!(
                scene.free(c, std::f64::consts::FRAC_PI_2, away, -0.07),
                "{name} point {i}: the 8° tilt away from the wall collides"
            );
            let nominal_free = (0..18).any(|k| {
                let q4 = (k as f64 * 10.0).to_radians();
                [-0.1, -0.085, -0.07, -0.055]
                    .iter()
                    .any(|&q6| scene.free(c, q4, 0.0, q6))
            });
            colliding += usize::from(!nominal_free);
        }
        let n = scene.points.len();
        if name == "angle_wall_trim" {
            assert_eq!(
                colliding, n,
                "{name}: the nominal axis collides at every point"
            );
        } else {
            assert!(
                colliding > n / 10 && colliding < n,
                "{name}: nominal axis collides at {colliding} of {n} points"
            );
        }
        println!("{name}: nominal axis collides at {colliding} of {n} points");
    }
}

/// The COLLISION refusal: 30 mm from the wall no axis inside the allowance and no standoff
/// is free (every fifth point).
#[test]
fn too_close_to_the_wall_no_orientation_inside_the_allowance_is_free() {
    let shop = shop();
    let scene = Scene::new(&shop, "angle_too_close");
    for (i, c) in scene.points.iter().enumerate().step_by(5) {
        assert!(
            !scene.any_free(c, 10f64.to_radians()),
            "point {i} has a free orientation"
        );
    }
    // The search finds free orientations where they exist: the wall trim 85 mm out.
    let wall = Scene::new(&shop, "angle_wall_trim");
    assert!(wall.any_free(&wall.points[0], 10f64.to_radians()));
}

/// Beside the channel walls the fork arms decide: parallel to the walls (along x, q4 = 90°:
/// the arms lie along c_axis y = (−sin q4, cos q4, 0)) the head clears them, pointing at a wall
/// (q4 = 0) they hit it where the cut is 60 mm from it. For the floor trim that is along the
/// cut, for the cross trim across it: the planner must choose q4 (the nominal axis is
/// vertical).
#[test]
fn channel_trims_clear_the_walls_only_with_the_forks_parallel_to_them() {
    let shop = shop();
    for name in ["channel_floor_trim", "channel_cross_trim", "channel_cutout"] {
        let scene = Scene::new(&shop, name);
        for (i, c) in scene.points.iter().enumerate() {
            assert!(
                scene.free(c, std::f64::consts::FRAC_PI_2, 0.0, -0.07),
                "{name} point {i}: forks parallel to the walls collide"
            );
        }
        let (first, last) = (scene.points[0], *scene.points.last().unwrap());
        for c in [first, last] {
            assert!(
                !scene.free(&c, 0.0, 0.0, -0.07),
                "{name}: forks towards a wall are free"
            );
        }
    }
}

/// The septic smoothstep `35x⁴ − 84x⁵ + 70x⁶ − 20x⁷` (C³ from 0 to 1) and its integral.
fn smoothstep(x: f64) -> (f64, f64) {
    let x = x.clamp(0.0, 1.0);
    let (x4, x5) = (x.powi(4), x.powi(5));
    (
        35.0 * x4 - 84.0 * x5 + 70.0 * x4 * x * x - 20.0 * x5 * x * x,
        7.0 * x5 - 14.0 * x5 * x + 10.0 * x5 * x * x - 2.5 * x4 * x4,
    )
}

/// The machine can make the saddle cuts r/R = 0.4 and 0.7 at 10 m/min with 10° allowances
/// (what their expectation `Plan` rests on), by the recipe of issue 16's hand-made plan: q4
/// fixed at 90°, q5 a fraction k of the nominal tilt (the axis then stays within
/// (1 − k) · asin(r/R) < 10° of the normal), q6 = −0.07 m (r/R = 0.4) or the longer −0.1 m
/// (r/R = 0.7: at −0.07 the fork arms touch the main tube where the axis tilts 35°), the
/// exact saddle curve (which the CL points sample) run at the loop-angle rate
/// that gives the requested feed where the curve is longest per radian (the feed never
/// exceeds it and reaches it), with 0.5 s septic ramps. Checked every 1 ms: every joint's
/// velocity, acceleration and jerk by finite differences within Table 2, the axis within 10°
/// of the normal, the head collision-free. (Not shown for r/R = 0.95: at a constant 10 m/min its
/// nominal tilt needs 2.5 times the q5 jerk limit, and the smallest fraction that keeps 10°
/// still 2.2 times; it needs a slower feed near its steepest tilt.)
#[test]
fn saddles_r040_and_r070_have_a_hand_made_plan_at_10_m_min() {
    let shop = shop();
    let tube = jobshop::TubeParams::default();
    let machine = LaserMachine::default_machine().unwrap();
    let lim = *machine.limits();
    for (name, k, standoff) in [("saddle_r040", 0.6, -0.07), ("saddle_r070", 0.8, -0.1)] {
        let case = shop.cases.iter().find(|c| c.name == name).unwrap();
        let req = committed(case);
        let pose = req.workpiece_pose.isometry().unwrap();
        let scene = Scene::new(&shop, name);
        let ratio = req
            .points
            .iter()
            .map(|p| p[0].hypot(p[1]))
            .fold(0.0, f64::max)
            / tube.radius;
        let curve = jobshop::saddle_curve(&tube, ratio * tube.radius).unwrap();
        // |dP/dθ| by central differences of the exact curve (t = θ / 2π).
        let tau = std::f64::consts::TAU;
        let speed = |theta: f64| {
            let h = 1e-6;
            (curve((theta + h) / tau).0 - curve((theta - h) / tau).0).norm() / (2.0 * h)
        };
        let longest = (0..20_000)
            .map(|i| speed(tau * i as f64 / 20_000.0))
            .fold(0.0, f64::max);
        let omega = req.feedrate / longest;
        let ramp = 0.5;
        let cruise = tau / omega - ramp;
        assert!(cruise > 0.0, "{name}: no cruise");
        let total = cruise + 2.0 * ramp;
        let theta = |t: f64| {
            if t < ramp {
                omega * ramp * smoothstep(t / ramp).1
            } else if t <= ramp + cruise {
                omega * (ramp / 2.0 + t - ramp)
            } else {
                tau - omega * ramp * smoothstep((total - t) / ramp).1
            }
        };
        let dt = 1e-3;
        let steps = (total / dt).ceil() as usize;
        let mut q: Vec<[f64; 6]> = Vec::with_capacity(steps + 1);
        let (mut worst_angle, mut feed_peak) = (0.0f64, 0.0f64);
        let mut previous: Option<Vector3<f64>> = None;
        for i in 0..=steps {
            let t = (i as f64 * dt).min(total);
            let (p, n) = curve(theta(t) / tau);
            let (c, n) = (pose * nalgebra::Point3::from(p), pose.rotation * n);
            let q5 = k * n.y.atan2(n.z);
            let (q4, q6) = (std::f64::consts::FRAC_PI_2, standoff);
            let o = tool_axis(q4, q5);
            worst_angle = worst_angle.max(o.angle(&n));
            let m = c.coords - o * q6;
            let contacts = scene.world.colliding_links(&[m.x, m.y, m.z, q4, q5, q6]);
            assert!(
                contacts.is_empty(),
                "{name}: the hand-made plan touches with {contacts:?} at t = {t}"
            );
            if let Some(prev) = previous {
                feed_peak = feed_peak.max((c.coords - prev).norm() / dt);
            }
            previous = Some(c.coords);
            let m = c.coords - o * q6;
            q.push([m.x, m.y, m.z, q4, q5, q6]);
        }
        assert!(
            worst_angle <= 10f64.to_radians(),
            "{name}: axis {worst_angle} rad off"
        );
        assert!(
            feed_peak <= req.feedrate * (1.0 + 1e-6) && feed_peak >= req.feedrate * 0.99,
            "{name}: feed peak {feed_peak}"
        );
        let mut ratios = [[0.0f64; 3]; 6];
        for (j, l) in lim.iter().enumerate() {
            let mut d: Vec<f64> = q.iter().map(|s| s[j]).collect();
            assert!(
                d.iter().all(|&v| v >= l.min && v <= l.max),
                "{name}: q{} stroke",
                j + 1
            );
            for (m, limit) in [l.vel, l.acc, l.jerk].into_iter().enumerate() {
                d = d.windows(2).map(|w| (w[1] - w[0]) / dt).collect();
                let peak = d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                ratios[j][m] = peak / limit;
                assert!(
                    peak <= limit,
                    "{name}: q{} derivative {} peak {peak} > {limit}",
                    j + 1,
                    m + 1
                );
            }
        }
        println!(
            "{name}: hand-made plan, k = {k}, cycle {total:.3} s, axis within {:.2}° of the normal, peak / limit (v, a, j): {}",
            worst_angle.to_degrees(),
            ratios
                .iter()
                .enumerate()
                .map(|(j, r)| format!("q{} {:.2} {:.2} {:.2}", j + 1, r[0], r[1], r[2]))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}
