//! The M-path problem of the standoff axis (seed 001 eq. 46-54, 62-64,
//! Appendix A) as solved by `kerf_mjto::standoff`, against independent
//! computations: control points from `kerf_bspline::fit` of
//! `C_a − O_a · w` (eq. 49-52), the jerk of the M path from the explicit
//! Hessian of eq. 18, and a dense KKT solve of the QP of eq. 62.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_bspline::{fit, jerk_hessian, BSpline, KnotVector};
use kerf_mjto::error::ConstraintFamily;
use kerf_mjto::gfd::tool_axis;
use kerf_mjto::rotary::JerkFactor;
use kerf_mjto::standoff::{dense_objective, solve_standoff, MPathProblem, MPathSolution, TIKHONOV};
use kerf_mjto::PlanError;
use nalgebra::{DMatrix, DVector, Vector3};

const K: usize = 5;
/// The q6 stroke of Table 2 (m).
const STROKE: (f64, f64) = (-0.1, 0.02);
const REFERENCE: f64 = -0.07;

mod common;
use common::Rng;

/// A path of `m` CL points with `nc` spline coefficients.
struct Path {
    params: Vec<f64>,
    points: Vec<Vector3<f64>>,
    axes: Vec<Vector3<f64>>,
    knots: KnotVector,
    factor: JerkFactor,
}

impl Path {
    /// Parameters u_i: slightly uneven, from 0 to 1.
    fn new(
        m: usize,
        nc: usize,
        c: impl Fn(f64) -> Vector3<f64>,
        o: impl Fn(f64) -> Vector3<f64>,
    ) -> Self {
        let params: Vec<f64> = (0..m)
            .map(|i| {
                let x = i as f64 / (m - 1) as f64;
                x + 0.02 * (std::f64::consts::PI * x).sin() * (1.0 - x)
            })
            .collect();
        let points = params.iter().map(|&u| c(u)).collect();
        let axes = params.iter().map(|&u| o(u)).collect();
        let knots = KnotVector::for_parameters(K, nc, &params).unwrap();
        let factor = JerkFactor::new(&knots).unwrap();
        Self {
            params,
            points,
            axes,
            knots,
            factor,
        }
    }

    fn problem<'a>(&'a self, via: &'a [(usize, f64)], stroke: (f64, f64)) -> MPathProblem<'a> {
        MPathProblem {
            knots: &self.knots,
            factor: &self.factor,
            params: &self.params,
            points: &self.points,
            axes: &self.axes,
            stroke,
            via,
            via_box: &[],
            reference: REFERENCE,
        }
    }

    /// w_i = q6(u_i) of the standoff spline with coefficients s
    /// (`BSpline::eval`, not the collocation matrix).
    fn w_of(&self, s: &[f64]) -> Vec<f64> {
        let q6 = BSpline::new(self.knots.clone(), s.to_vec()).unwrap();
        self.params.iter().map(|&u| q6.eval(u)[0]).collect()
    }

    /// Control points of the M path for the standoff values w at the CL
    /// points: per axis, the fit (eq. 49-52) of `M_a = C_a − O_a w`
    /// (eq. 2/3: M = C − q6 O).
    fn control_points(&self, w: &[f64]) -> [Vec<f64>; 3] {
        [0, 1, 2].map(|a| {
            let values: Vec<f64> = self
                .points
                .iter()
                .zip(&self.axes)
                .zip(w)
                .map(|((c, o), w)| c[a] - o[a] * w)
                .collect();
            fit(&self.knots, &self.params, &values).unwrap()
        })
    }

    /// J_M = Σ_a P_aᵀ H P_a (eq. 48) with H of eq. 18, dense.
    fn jerk(&self, w: &[f64]) -> f64 {
        let h = jerk_hessian(&self.knots).unwrap().to_dense();
        self.control_points(w)
            .iter()
            .map(|p| {
                let p = DVector::from_column_slice(p);
                (p.transpose() * &h * &p)[(0, 0)]
            })
            .sum()
    }
}

/// A curved path with a turning tool axis (q4 0.3 → 1.1, q5 0.2 → 0.7).
fn curved(m: usize, nc: usize) -> Path {
    Path::new(
        m,
        nc,
        |u| {
            Vector3::new(
                0.5 + 0.3 * u,
                0.7 + 0.01 * (2.0 * std::f64::consts::PI * u).sin(),
                0.3 + 0.005 * (3.0 * std::f64::consts::PI * u).cos(),
            )
        },
        |u| tool_axis(0.3 + 0.8 * u, 0.2 + 0.5 * u),
    )
}

/// A path that bulges by `amplitude` (m) along a constant tilted tool axis
/// O, on top of a gentle sideways curve: a standoff following the bulge
/// takes it out of the M path.
fn bulge(m: usize, nc: usize, amplitude: f64) -> Path {
    let o = Vector3::new(0.3, 0.0, 1.0).normalize();
    Path::new(
        m,
        nc,
        move |u| {
            Vector3::new(
                0.5 + 0.3 * u,
                0.7 + 0.02 * (std::f64::consts::PI * u).sin(),
                0.3,
            ) + amplitude * (4.0 * std::f64::consts::PI * u).sin() * o
        },
        move |_| o,
    )
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Independent checks of a solution: its w is the q6 spline at the CL
/// points, its control points are the fit of C − O w.
fn check_consistent(path: &Path, sol: &MPathSolution) {
    assert_eq!(sol.w.len(), path.params.len());
    assert_eq!(sol.standoff_coeffs.len(), path.knots.n_coeffs());
    let w = path.w_of(&sol.standoff_coeffs);
    assert!(max_diff(&w, &sol.w) < 1e-7, "{}", max_diff(&w, &sol.w));
    let p = path.control_points(&w);
    for (mine, theirs) in p.iter().zip(&sol.control_points) {
        let scale = mine.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        assert!(max_diff(mine, theirs) < 1e-9 * scale);
    }
}

#[test]
fn dense_objective_is_the_jerk_of_the_fitted_m_path() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    // Square (one coefficient per CL point, interpolation) and least
    // squares (40 CL points, 12 coefficients).
    for (m, nc) in [(12, 12), (40, 12), (30, 18)] {
        let path = curved(m, nc);
        let (d, f) = dense_objective(&path.problem(&[], STROKE)).unwrap();
        assert_eq!((d.nrows(), d.ncols(), f.len()), (nc, nc, nc));
        // D is symmetric positive semidefinite (eq. 53, A4).
        let asym = (&d - d.transpose()).amax();
        assert!(asym <= 1e-12 * d.amax(), "{asym}");
        let eig = d.clone().symmetric_eigenvalues();
        assert!(eig.min() >= -1e-9 * eig.max(), "{}", eig.min());
        let c = path.jerk(&vec![0.0; m]);
        for trial in 0..5 {
            let s: Vec<f64> = (0..nc).map(|_| REFERENCE + 0.04 * rng.signed()).collect();
            let sv = DVector::from_column_slice(&s);
            let quad = 0.5 * (sv.transpose() * &d * &sv)[(0, 0)] + f.dot(&sv) + c;
            let direct = path.jerk(&path.w_of(&s));
            assert!(
                (quad - direct).abs() <= 1e-8 * direct,
                "m {m}, n+1 {nc}, trial {trial}: ½sᵀDs + fᵀs + c = {quad}, Σ PᵀHP = {direct}"
            );
            // The quadratic part alone: J(s) + J(−s) − 2 J(0) = sᵀ D s.
            let minus: Vec<f64> = s.iter().map(|v| -v).collect();
            let second = direct + path.jerk(&path.w_of(&minus)) - 2.0 * c;
            let sds = (sv.transpose() * &d * &sv)[(0, 0)];
            assert!((second - sds).abs() <= 1e-7 * sds, "{second} vs {sds}");
        }
    }
}

/// The collocation matrix N (N_ij = N_j(u_i)) from `BSpline::eval` of unit
/// coefficient vectors.
fn collocation_dense(path: &Path) -> DMatrix<f64> {
    let nc = path.knots.n_coeffs();
    let mut n = DMatrix::zeros(path.params.len(), nc);
    for j in 0..nc {
        let mut e = vec![0.0; nc];
        e[j] = 1.0;
        let b = BSpline::new(path.knots.clone(), e).unwrap();
        for (i, &u) in path.params.iter().enumerate() {
            n[(i, j)] = b.eval(u)[0];
        }
    }
    n
}

/// The minimiser of ½ sᵀ D s + fᵀ s + t ‖N s − w_ref‖² subject to
/// w_i = (N s)_i = v_i at the RTOs (eq. 62 without the stroke, plus a
/// Tikhonov term of weight t), from the dense KKT system (LU).
fn kkt(path: &Path, d: &DMatrix<f64>, f: &DVector<f64>, t: f64, via: &[(usize, f64)]) -> Vec<f64> {
    let n = collocation_dense(path);
    let nc = d.nrows();
    let mv = via.len();
    let mut a = DMatrix::zeros(nc + mv, nc + mv);
    a.view_mut((0, 0), (nc, nc))
        .copy_from(&(d + 2.0 * t * n.transpose() * &n));
    let mut b = DVector::zeros(nc + mv);
    let ones = DVector::from_element(n.nrows(), REFERENCE);
    b.rows_mut(0, nc)
        .copy_from(&(-f + 2.0 * t * n.transpose() * ones));
    for (r, &(i, v)) in via.iter().enumerate() {
        for j in 0..nc {
            a[(nc + r, j)] = n[(i, j)];
            a[(j, nc + r)] = n[(i, j)];
        }
        b[nc + r] = v;
    }
    let x = a.lu().solve(&b).expect("KKT system singular");
    x.iter().take(nc).copied().collect()
}

#[test]
fn socp_solution_is_the_minimiser_of_the_dense_qp() {
    // (CL points, coefficients, RTOs). The Tikhonov weight t of the SOCP
    // grows with trace(D) (~n⁶) while the smallest eigenvalue of D does
    // not: in the first four t is small and the answer is that of eq. 62;
    // in the last two t is 100 and 2000 times the smallest eigenvalue, and
    // the M-path jerk ends 8e-5 and 5e-4 above the minimum of eq. 62
    // (printed; 4.4e-3 for 240 CL points and n + 1 = 63).
    let cases = [
        (20, 6, vec![(0usize, -0.06), (19, -0.08)]),
        (30, 8, vec![(0, -0.06), (29, -0.06)]),
        (12, 12, vec![(0, -0.07), (11, -0.06)]),
        (40, 12, vec![(0, -0.07), (17, -0.05), (39, -0.08)]),
        (30, 16, vec![(0, -0.06), (29, -0.06)]),
        (100, 30, vec![(0, -0.07), (50, -0.06), (99, -0.07)]),
    ];
    for (k, (m, nc, via)) in cases.into_iter().enumerate() {
        let path = curved(m, nc);
        let problem = path.problem(&via, STROKE);
        let sol = solve_standoff(&problem).unwrap();
        check_consistent(&path, &sol);
        assert!(sol.iterations > 0);
        for &(i, v) in &via {
            assert!((sol.w[i] - v).abs() < 1e-7);
        }
        let (d, f) = dense_objective(&problem).unwrap();
        // The minimiser of eq. 62 without the stroke ...
        let s = kkt(&path, &d, &f, 0.0, &via);
        let w = path.w_of(&s);
        for &(i, v) in &via {
            assert!((w[i] - v).abs() < 1e-9);
        }
        // ... whose q6 coefficients (the stroke bounds them, convex hull)
        // are well inside the stroke: the stroke is inactive.
        assert!(
            s.iter()
                .all(|&c| c > STROKE.0 + 5e-3 && c < STROKE.1 - 5e-3),
            "{s:?}"
        );
        // The SOCP minimises J_M + t ‖N s − w_ref‖² with the Tikhonov
        // weight t = TIKHONOV ‖R‖²_F / ‖N‖²_F = TIKHONOV trace(D) / (2 ‖N‖²_F)
        // (standoff.rs); its answer is that problem's minimiser to the
        // solver's accuracy.
        let n = collocation_dense(&path);
        let t = TIKHONOV * d.trace() / (2.0 * n.norm_squared());
        let w_t = path.w_of(&kkt(&path, &d, &f, t, &via));
        let err_t = max_diff(&w_t, &sol.w);
        assert!(err_t < 5e-6, "case {k}: max |w − w_KKT(t)| = {err_t:e} m");
        let j_sol = path.jerk(&sol.w);
        let j_kkt = path.jerk(&w);
        let err = max_diff(&w, &sol.w);
        let eig = d.clone().symmetric_eigenvalues();
        println!(
            "m {m:3}, n+1 {nc:2}: eig(D) in [{:.2e}, {:.2e}], t = {t:.2e}, \
             max |w − w_eq62| = {err:.2e} m, J_M / J_M(eq. 62) − 1 = {:.2e}",
            eig.min(),
            eig.max(),
            j_sol / j_kkt - 1.0
        );
        // Never below the minimum of eq. 62 (to the 1e-7 accuracy of the
        // dense KKT reference and of the RTO equalities of the solution).
        assert!(j_sol >= j_kkt * (1.0 - 1e-7), "{j_sol} < {j_kkt}");
        if k < 4 {
            // Small t (at most ~3 times the smallest eigenvalue of D): the
            // minimiser of eq. 62 itself, to the solver's accuracy.
            assert!(t < 3.0 * eig.min(), "{t} {}", eig.min());
            assert!(err < 3e-6, "case {k}: max |w − w_KKT| = {err:e} m");
            assert!(j_sol <= j_kkt * (1.0 + 1e-8), "{j_sol} vs {j_kkt}");
        }
    }
}

#[test]
fn a_bulge_along_a_constant_axis_is_taken_by_the_standoff() {
    let path = bulge(40, 20, 0.01);
    let via = [(0usize, REFERENCE), (39, REFERENCE)];
    let sol = solve_standoff(&path.problem(&via, STROKE)).unwrap();
    check_consistent(&path, &sol);
    // The standoff follows the ±1 cm bulge: not constant.
    let (lo, hi) = sol
        .w
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    assert!(hi - lo > 0.015, "w in [{lo}, {hi}]");
    assert!(lo > STROKE.0 && hi < STROKE.1);
    // The M path is much smoother than with the constant standoff.
    let constant = vec![REFERENCE; 40];
    let j_opt = path.jerk(&sol.w);
    let j_const = path.jerk(&constant);
    assert!(j_opt < 0.05 * j_const, "{j_opt} vs {j_const}");
    // Optimal: moving any interior q6 coefficient (which leaves the RTO
    // values at the clamped ends unchanged) by 1 mm costs jerk.
    for j in 1..19 {
        let mut s = sol.standoff_coeffs.clone();
        s[j] += 1e-3;
        let w = path.w_of(&s);
        assert_eq!(w[0], sol.w[0]);
        assert!(path.jerk(&w) > j_opt, "coefficient {j}");
    }
    // w cannot change the sideways curve of the path (perpendicular to
    // O): the M path is as smooth as the path without the bulge at a
    // constant standoff, whose M path is that curve alone (and a
    // linear motion along O).
    let plain = bulge(40, 20, 0.0);
    let j_plain = plain.jerk(&constant);
    println!("J_M: constant standoff {j_const:.4e}, optimal {j_opt:.4e}, without the bulge {j_plain:.4e}");
    assert!(j_opt < 1.01 * j_plain, "{j_opt} vs {j_plain}");
}

#[test]
fn an_active_stroke_keeps_every_w_inside_with_some_at_the_bound() {
    // A ±8 cm bulge: following it needs a q6 range of 16 cm, more than
    // the 12 cm stroke.
    let path = bulge(40, 20, 0.08);
    let via = [(0usize, REFERENCE), (39, REFERENCE)];
    let wide = solve_standoff(&path.problem(&via, (-1.0, 1.0))).unwrap();
    let below = wide.w.iter().cloned().fold(f64::INFINITY, f64::min);
    let above = wide.w.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(below < STROKE.0 - 0.04, "{below}");
    assert!(above - below > 0.15, "[{below}, {above}]");
    let sol = solve_standoff(&path.problem(&via, STROKE)).unwrap();
    check_consistent(&path, &sol);
    for &(i, v) in &via {
        assert!((sol.w[i] - v).abs() < 1e-7);
    }
    // Every w inside the stroke, and (the stroke bounds the q6
    // coefficients, convex hull) the whole q6 curve.
    assert!(sol.w.iter().all(|&w| (STROKE.0..=STROKE.1).contains(&w)));
    let q6 = BSpline::new(path.knots.clone(), sol.standoff_coeffs.clone()).unwrap();
    for i in 0..=2000 {
        let v = q6.eval(i as f64 / 2000.0)[0];
        assert!(v >= STROKE.0 - 1e-8 && v <= STROKE.1 + 1e-8, "{v}");
    }
    // The bound is active: coefficients at both ends of the stroke, and w
    // reaches within 1 cm of each (a w exactly at an end would need all
    // k + 1 coefficients of its span there).
    let at = |bound: f64| {
        sol.standoff_coeffs
            .iter()
            .filter(|&&c| (c - bound).abs() < 1e-7)
            .count()
    };
    assert!(
        at(STROKE.0) >= 1 && at(STROKE.1) >= 1,
        "{:?}",
        sol.standoff_coeffs
    );
    let lo = sol.w.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = sol.w.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(lo < STROKE.0 + 0.01 && hi > STROKE.1 - 0.01, "[{lo}, {hi}]");
    // The bound costs smoothness, but the standoff still helps.
    let j = path.jerk(&sol.w);
    let j_wide = path.jerk(&wide.w);
    let j_const = path.jerk(&[REFERENCE; 40]);
    println!("J_M: stroke (-1, 1) {j_wide:.4e}, Table 2 stroke {j:.4e}, constant {j_const:.4e}");
    assert!(j > j_wide * 10.0);
    assert!(j < 0.5 * j_const);
}

fn family(r: Result<MPathSolution, PlanError>) -> ConstraintFamily {
    match r {
        Err(PlanError::Infeasible {
            problem,
            family,
            max_feasible_feedrate,
            ..
        }) => {
            assert_eq!(problem, "M path");
            assert_eq!(max_feasible_feedrate, None);
            family
        }
        other => panic!("expected Infeasible, got {other:?}"),
    }
}

#[test]
fn rto_values_outside_the_stroke_are_rto_infeasible() {
    let path = curved(30, 12);
    for v in [-0.15, 0.05, STROKE.0 - 1e-3] {
        let via = [(0usize, REFERENCE), (14, v), (29, REFERENCE)];
        assert_eq!(
            family(solve_standoff(&path.problem(&via, STROKE))),
            ConstraintFamily::Rto
        );
    }
    // Two different values at one CL point contradict each other.
    let via = [
        (0usize, REFERENCE),
        (14, -0.05),
        (14, -0.06),
        (29, REFERENCE),
    ];
    assert_eq!(
        family(solve_standoff(&path.problem(&via, STROKE))),
        ConstraintFamily::Rto
    );
    // RTO values inside the stroke at adjacent CL points, one at each end
    // of it: 12 coefficients cannot jump by 12 cm between neighbours 1/29
    // apart without leaving the stroke elsewhere.
    let via = [
        (0usize, REFERENCE),
        (14, STROKE.0),
        (15, STROKE.1),
        (29, REFERENCE),
    ];
    assert_eq!(
        family(solve_standoff(&path.problem(&via, STROKE))),
        ConstraintFamily::Stroke
    );
}

#[test]
fn invalid_inputs_are_errors_not_panics() {
    let path = curved(20, 12);
    let via = [(0usize, REFERENCE), (19, REFERENCE)];
    assert!(solve_standoff(&path.problem(&via, STROKE)).is_ok());
    let invalid = |r: Result<MPathSolution, PlanError>, what: &str| match r {
        Err(PlanError::InvalidRequest { .. }) => {}
        other => panic!("{what}: {other:?}"),
    };
    // Stroke and reference.
    for stroke in [
        (0.02, -0.1),
        (0.0, 0.0),
        (f64::NAN, 0.02),
        (-0.1, f64::INFINITY),
    ] {
        invalid(
            solve_standoff(&path.problem(&via, stroke)),
            &format!("{stroke:?}"),
        );
    }
    let p = MPathProblem {
        reference: f64::NAN,
        ..path.problem(&via, STROKE)
    };
    invalid(solve_standoff(&p), "NaN reference");
    // RTOs: an index past the CL points, a NaN value.
    invalid(
        solve_standoff(&path.problem(&[(0, REFERENCE), (20, REFERENCE)], STROKE)),
        "index 20",
    );
    invalid(
        solve_standoff(&path.problem(&[(0, REFERENCE), (5, f64::NAN)], STROKE)),
        "NaN RTO",
    );
    // Lengths that disagree.
    let short = &path.axes[..19];
    let p = MPathProblem {
        axes: short,
        ..path.problem(&via, STROKE)
    };
    invalid(solve_standoff(&p), "19 axes");
    assert!(dense_objective(&p).is_err());
    let p = MPathProblem {
        points: &path.points[..18],
        ..path.problem(&[], STROKE)
    };
    assert!(dense_objective(&p).is_err());
    // A factor of other knots.
    let other = JerkFactor::new(&KnotVector::clamped_uniform(K, 13).unwrap()).unwrap();
    let p = MPathProblem {
        factor: &other,
        ..path.problem(&via, STROKE)
    };
    assert!(matches!(solve_standoff(&p), Err(PlanError::Solver { .. })));
    assert!(dense_objective(&p).is_err());
    // Fewer CL points than coefficients, parameters outside [0, 1], NaN
    // geometry: errors.
    let p = MPathProblem {
        params: &path.params[..10],
        points: &path.points[..10],
        axes: &path.axes[..10],
        ..path.problem(&[(0, REFERENCE)], STROKE)
    };
    assert!(solve_standoff(&p).is_err());
    let mut params = path.params.clone();
    params[5] = 1.5;
    let p = MPathProblem {
        params: &params,
        ..path.problem(&via, STROKE)
    };
    assert!(solve_standoff(&p).is_err());
    let mut points = path.points.clone();
    points[3].x = f64::NAN;
    let p = MPathProblem {
        points: &points,
        ..path.problem(&via, STROKE)
    };
    assert!(solve_standoff(&p).is_err());
    let mut axes = path.axes.clone();
    axes[7] = Vector3::new(f64::NAN, 0.0, 1.0);
    let p = MPathProblem {
        axes: &axes,
        ..path.problem(&via, STROKE)
    };
    assert!(solve_standoff(&p).is_err());
}
