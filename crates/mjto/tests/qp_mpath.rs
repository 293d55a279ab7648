//! Tests of the M-path QP of the standoff axis (seed 001 eq. 46-54, 62,
//! Appendix A).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use kerf_bspline::{collocation, fit, jerk_hessian, BSpline, BandedSym, KnotVector};
use kerf_mjto::error::ConstraintFamily;
use kerf_mjto::qp::{
    mpath_dense_objective, mpath_tikhonov_weight, solve_mpath, MPathProblem, MPathSolution,
};
use kerf_mjto::PlanError;
use nalgebra::{DMatrix, DVector, Vector3};

/// One test setup: knots, Hessian, parameters, CL points and axes.
struct Setup {
    kv: KnotVector,
    h: BandedSym,
    params: Vec<f64>,
    points: Vec<Vector3<f64>>,
    axes: Vec<Vector3<f64>>,
}

impl Setup {
    /// `m` CL points on a curved 3D path with a varying tool axis, and a
    /// quintic of `nc` coefficients; Greville parameters when `m == nc`
    /// (square N), uniform ones otherwise (least squares).
    fn new(m: usize, nc: usize) -> Self {
        let kv = KnotVector::clamped_uniform(5, nc).unwrap();
        let h = jerk_hessian(&kv).unwrap();
        let t = kv.knots();
        let params: Vec<f64> = if m == nc {
            (0..nc)
                .map(|j| t[j + 1..=j + 5].iter().sum::<f64>() / 5.0)
                .collect()
        } else {
            (0..m).map(|i| i as f64 / (m - 1) as f64).collect()
        };
        let points = params
            .iter()
            .map(|&u| {
                Vector3::new(
                    0.5 + 0.3 * u,
                    0.4 + 0.1 * (3.0 * u).sin(),
                    0.8 + 0.01 * (9.0 * u).sin(),
                )
            })
            .collect();
        let axes = params
            .iter()
            .map(|&u| Vector3::new(0.3 * (2.0 * u).sin(), 0.2 * u, 1.0).normalize())
            .collect();
        Self {
            kv,
            h,
            params,
            points,
            axes,
        }
    }

    fn problem<'a>(&'a self, stroke: (f64, f64), via: &'a [(usize, f64)]) -> MPathProblem<'a> {
        MPathProblem {
            knots: &self.kv,
            hessian: &self.h,
            params: &self.params,
            points: &self.points,
            axes: &self.axes,
            stroke,
            via,
            reference: 0.0,
        }
    }

    /// `J_M(w) = Σ_a P_aᵀ H P_a`, `P_a = N⁺(C_a − O_a w)` (eq. 48-52).
    fn jerk(&self, w: &[f64]) -> f64 {
        (0..3)
            .map(|a| {
                let m: Vec<f64> = (0..w.len())
                    .map(|i| self.points[i][a] - self.axes[i][a] * w[i])
                    .collect();
                let p = fit(&self.kv, &self.params, &m).unwrap();
                quad(&self.h, &p)
            })
            .sum()
    }

    fn n_dense(&self) -> DMatrix<f64> {
        collocation(&self.kv, &self.params).unwrap().to_dense()
    }
}

fn quad(h: &BandedSym, x: &[f64]) -> f64 {
    h.mul_vec(x).iter().zip(x).map(|(a, b)| a * b).sum()
}

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
}

/// The dense form of Appendix A, restricted to standoffs on the spline
/// (`w = N s`): Hessian `NᵀDN + 2τNᵀN` and linear term `Nᵀf − 2τ w_ref
/// Nᵀ1` in s.
fn dense_in_s(setup: &Setup, p: &MPathProblem) -> (DMatrix<f64>, DVector<f64>, DMatrix<f64>) {
    let (d, f) = mpath_dense_objective(p).unwrap();
    let tau = mpath_tikhonov_weight(setup.points.len());
    let n = setup.n_dense();
    let hs = n.transpose() * &d * &n + n.transpose() * &n * (2.0 * tau);
    let ones = DVector::from_element(n.nrows(), 1.0);
    let fs = n.transpose() * &f - n.transpose() * ones * (2.0 * tau * p.reference);
    (hs, fs, n)
}

/// Minimiser of the dense form under the RTO equalities (dense KKT).
fn dense_minimiser(setup: &Setup, p: &MPathProblem) -> DVector<f64> {
    let (hs, fs, n) = dense_in_s(setup, p);
    let nc = hs.nrows();
    let k = p.via.len();
    let mut kkt = DMatrix::zeros(nc + k, nc + k);
    kkt.view_mut((0, 0), (nc, nc)).copy_from(&hs);
    let mut rhs = DVector::zeros(nc + k);
    rhs.rows_mut(0, nc).copy_from(&(-fs));
    for (r, &(i, v)) in p.via.iter().enumerate() {
        for c in 0..nc {
            kkt[(nc + r, c)] = n[(i, c)];
            kkt[(c, nc + r)] = n[(i, c)];
        }
        rhs[nc + r] = v;
    }
    let sol = kkt.lu().solve(&rhs).unwrap();
    &n * sol.rows(0, nc)
}

/// Minimiser of the dense form under the RTO equalities and the stroke,
/// by Clarabel on the dense problem.
fn dense_bounded_minimiser(setup: &Setup, p: &MPathProblem) -> DVector<f64> {
    let (hs, fs, n) = dense_in_s(setup, p);
    let nc = hs.nrows();
    let scale = hs.amax();
    let (mut pi, mut pj, mut pv) = (vec![], vec![], vec![]);
    for j in 0..nc {
        for i in 0..=j {
            pi.push(i);
            pj.push(j);
            pv.push(hs[(i, j)] / scale);
        }
    }
    let pm = CscMatrix::new_from_triplets(nc, nc, pi, pj, pv);
    let q: Vec<f64> = fs.iter().map(|v| v / scale).collect();
    let (mut ai, mut aj, mut av, mut b) = (vec![], vec![], vec![], vec![]);
    let mut push = |row: usize, sign: f64, rhs: f64, b: &mut Vec<f64>| {
        let r = b.len();
        for c in 0..nc {
            ai.push(r);
            aj.push(c);
            av.push(sign * n[(row, c)]);
        }
        b.push(sign * rhs);
    };
    for &(i, v) in p.via {
        push(i, 1.0, v, &mut b);
    }
    let n_eq = b.len();
    for i in 0..n.nrows() {
        push(i, 1.0, p.stroke.1, &mut b);
        push(i, -1.0, p.stroke.0, &mut b);
    }
    let m = b.len();
    let a = CscMatrix::new_from_triplets(m, nc, ai, aj, av);
    let cones = [
        SupportedConeT::ZeroConeT(n_eq),
        SupportedConeT::NonnegativeConeT(m - n_eq),
    ];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(1e-12)
        .tol_gap_rel(1e-12)
        .tol_feas(1e-12)
        .build()
        .unwrap();
    let mut solver = DefaultSolver::new(&pm, &q, &a, &b, &cones, settings).unwrap();
    solver.solve();
    assert!(matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ));
    &n * DVector::from_vec(solver.solution.x.clone())
}

/// The solution's own consistency: standoffs on the q6 spline, vias met,
/// stroke kept, and control points equal to `N⁺(C_a − O_a w)`.
fn check_solution(setup: &Setup, p: &MPathProblem, s: &MPathSolution, tol: f64) {
    let n = setup.n_dense();
    let w_spline = &n * DVector::from_vec(s.standoff_coeffs.clone());
    for (i, &w) in s.w.iter().enumerate() {
        assert!((w_spline[i] - w).abs() < 1e-12, "w[{i}] is not N s");
        assert!(
            w >= p.stroke.0 - tol && w <= p.stroke.1 + tol,
            "w[{i}] = {w}"
        );
    }
    for &(i, v) in p.via {
        assert!((s.w[i] - v).abs() < tol, "via at {i}: {} vs {v}", s.w[i]);
    }
    for a in 0..3 {
        let m: Vec<f64> = (0..s.w.len())
            .map(|i| setup.points[i][a] - setup.axes[i][a] * s.w[i])
            .collect();
        let expect = fit(&setup.kv, &setup.params, &m).unwrap();
        for (x, e) in s.control_points[a].iter().zip(&expect) {
            assert!((x - e).abs() < 1e-7, "axis {a}: control point {x} vs {e}");
        }
    }
}

/// Appendix A: `½wᵀDw + fᵀw + c` equals `Σ_a P_aᵀHP_a` for random w, with
/// c the value at w = 0 (square and least-squares N).
#[test]
fn dense_objective_equals_the_m_path_jerk() {
    for (m, nc) in [(12, 12), (20, 12)] {
        let setup = Setup::new(m, nc);
        let p = setup.problem((-0.1, 0.02), &[]);
        let (d, f) = mpath_dense_objective(&p).unwrap();
        assert_eq!((d.nrows(), d.ncols(), f.len()), (m, m, m));
        assert!((&d - d.transpose()).amax() < 1e-9 * d.amax());
        let c = setup.jerk(&vec![0.0; m]);
        let mut seed = 7;
        for _ in 0..5 {
            let w = DVector::from_iterator(m, (0..m).map(|_| 0.05 * lcg(&mut seed)));
            let q = 0.5 * w.dot(&(&d * &w)) + f.dot(&w) + c;
            let direct = setup.jerk(w.as_slice());
            assert!((q - direct).abs() < 1e-8 * direct, "{q} vs {direct}");
        }
    }
}

/// With the stroke inactive, the sparse lifted solve equals the minimiser
/// of the dense D, f form (with the same Tikhonov term) under the RTO
/// equalities, for square and least-squares N.
#[test]
fn sparse_solve_equals_the_dense_minimiser() {
    for (m, nc) in [(12, 12), (20, 12)] {
        let setup = Setup::new(m, nc);
        let via = [(0, 0.0), (m / 2, -0.01), (m - 1, 0.0)];
        let p = setup.problem((-1.0, 1.0), &via);
        let s = solve_mpath(&p).unwrap();
        check_solution(&setup, &p, &s, 1e-10);
        let dense = dense_minimiser(&setup, &p);
        for (i, w) in s.w.iter().enumerate() {
            assert!(
                (w - dense[i]).abs() < 1e-8,
                "m = {m}: w[{i}] {w} vs {}",
                dense[i]
            );
        }
        // The M path is smoother than with a constant standoff.
        assert!(setup.jerk(&s.w) < setup.jerk(&vec![0.0; m]));
    }
}

/// A narrow stroke becomes active; the result equals Clarabel on the dense
/// bounded problem and keeps every constraint.
#[test]
fn active_stroke_matches_the_dense_bounded_minimiser() {
    for (m, nc) in [(12, 12), (20, 12)] {
        let setup = Setup::new(m, nc);
        let via = [(0, 0.0), (m - 1, 0.0)];
        let free = solve_mpath(&setup.problem((-1.0, 1.0), &via)).unwrap();
        let lowest = free.w.iter().fold(f64::INFINITY, |a, &v| a.min(v));
        assert!(
            lowest < -1e-3,
            "the free standoff dips below zero ({lowest})"
        );
        let stroke = (0.5 * lowest, 1.0);
        let p = setup.problem(stroke, &via);
        let s = solve_mpath(&p).unwrap();
        check_solution(&setup, &p, &s, 1e-10);
        let at_bound = s.w.iter().filter(|&&w| (w - stroke.0).abs() < 1e-9).count();
        assert!(at_bound > 0, "the stroke is active");
        let reference = dense_bounded_minimiser(&setup, &p);
        for (i, w) in s.w.iter().enumerate() {
            assert!(
                (w - reference[i]).abs() < 1e-6,
                "m = {m}: w[{i}] {w} vs {}",
                reference[i]
            );
        }
        assert!(setup.jerk(&s.w) >= setup.jerk(&free.w));
    }
}

/// A constant tool axis and a path that waves along it: the optimal
/// standoff absorbs the wave (M becomes a jerk-free quadratic), so w is far
/// from constant and the M-path jerk drops to ~0.
#[test]
fn constant_axis_standoff_smooths_the_m_path() {
    let nc = 30;
    let mut setup = Setup::new(nc, nc);
    setup.axes = vec![Vector3::z(); nc];
    setup.points = setup
        .params
        .iter()
        .map(|&u| {
            Vector3::new(
                0.2 + 0.5 * u,
                0.3 + 0.1 * u,
                0.8 + 0.004 * (6.0 * std::f64::consts::PI * u).sin(),
            )
        })
        .collect();
    let via = [(0, 0.0), (nc - 1, 0.0)];
    let p = setup.problem((-0.1, 0.1), &via);
    let s = solve_mpath(&p).unwrap();
    check_solution(&setup, &p, &s, 1e-10);
    let flat = setup.jerk(&vec![0.0; nc]);
    let optimal = setup.jerk(&s.w);
    assert!(flat > 1.0, "the wave has jerk ({flat})");
    assert!(optimal < 1e-9 * flat, "{optimal} vs {flat}");
    let spread = s.w.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    assert!(spread > 3e-3, "w follows the wave ({spread})");
    // M_z = C_z − w is the quadratic through the end points closest to
    // C_z − w_ref: here the wave's amplitude is carried by w.
    let mz: Vec<f64> = (0..nc).map(|i| setup.points[i][2] - s.w[i]).collect();
    let spline = BSpline::new(
        setup.kv.clone(),
        fit(&setup.kv, &setup.params, &mz).unwrap(),
    );
    let third = spline.unwrap().eval(0.5)[3];
    assert!(third.abs() < 1e-6, "M_z''' = {third}");
}

/// RTOs outside the stroke (family Stroke) or contradicting each other
/// (family Rto) are reported as infeasible.
#[test]
fn infeasible_rtos_are_reported() {
    let setup = Setup::new(12, 12);
    let outside = [(0, 0.0), (5, 0.05)];
    match solve_mpath(&setup.problem((-0.1, 0.02), &outside)) {
        Err(PlanError::Infeasible {
            problem,
            family,
            detail,
            max_feasible_feedrate,
        }) => {
            assert_eq!(problem, "M path");
            assert_eq!(family, ConstraintFamily::Stroke);
            assert!(detail.contains("CL point 5"), "{detail}");
            assert_eq!(max_feasible_feedrate, None);
        }
        other => panic!("expected Infeasible, got {other:?}"),
    }
    let clash = [(5, 0.0), (5, 0.01)];
    match solve_mpath(&setup.problem((-0.1, 0.02), &clash)) {
        Err(PlanError::Infeasible { family, .. }) => assert_eq!(family, ConstraintFamily::Rto),
        other => panic!("expected Infeasible, got {other:?}"),
    }
}

/// 628 CL points (the paper's case) with 628 coefficients (square N,
/// Greville parameters) and with 300 (least squares), inactive and active
/// stroke. Timings are printed, not asserted.
#[test]
fn n628_solves() {
    for (m, nc) in [(628, 628), (628, 300)] {
        let setup = Setup::new(m, nc);
        let via = [
            (0, -0.02),
            (120, -0.02),
            (250, -0.02),
            (400, -0.02),
            (520, -0.02),
            (m - 1, -0.02),
        ];
        let free = solve_mpath(&setup.problem((-0.1, 0.02), &via)).unwrap();
        let lo = free.w.iter().fold(f64::INFINITY, |a, &v| a.min(v));
        let hi = free.w.iter().fold(f64::NEG_INFINITY, |a, &v| a.max(v));
        // A stroke that cuts 30 % off both ends of the free range, the
        // RTOs (−0.02) staying inside.
        let r = hi - lo;
        let narrow = ((lo + 0.3 * r).min(-0.0201), (hi - 0.3 * r).max(-0.0199));
        assert!(narrow.0 > lo && narrow.1 < hi, "{narrow:?} in [{lo}, {hi}]");
        for stroke in [(-0.1, 0.02), narrow] {
            let p = setup.problem(stroke, &via);
            let t = std::time::Instant::now();
            let s = solve_mpath(&p).unwrap();
            println!(
                "M path, {m} points, {nc} coefficients, stroke {stroke:?}: {:?}, {} IPM iterations",
                t.elapsed(),
                s.iterations
            );
            check_solution(&setup, &p, &s, 1e-9);
            let at_bound =
                s.w.iter()
                    .filter(|&&w| (w - stroke.0).abs() < 1e-9 || (w - stroke.1).abs() < 1e-9)
                    .count();
            assert_eq!(
                at_bound > 0,
                stroke == narrow,
                "{at_bound} standoffs at the stroke"
            );
            if m == nc {
                // Square N: the M-path spline interpolates M_i = C_i − w_i O_i.
                for a in 0..3 {
                    let sp = BSpline::new(setup.kv.clone(), s.control_points[a].clone()).unwrap();
                    for i in (0..m).step_by(37) {
                        let mi = setup.points[i][a] - setup.axes[i][a] * s.w[i];
                        assert!((sp.eval(setup.params[i])[0] - mi).abs() < 1e-9);
                    }
                }
            }
        }
    }
}

/// Malformed inputs are InvalidRequest errors, never panics.
#[test]
fn invalid_inputs_are_rejected() {
    let setup = Setup::new(12, 12);
    let via = [(0, 0.0)];
    let mut bad_axis = Setup::new(12, 12);
    bad_axis.axes[3] = Vector3::new(0.0, 0.0, 1.1);
    let mut decreasing = Setup::new(12, 12);
    decreasing.params.swap(4, 5);
    let mut nan_point = Setup::new(12, 12);
    nan_point.points[2].x = f64::NAN;
    let mut short = Setup::new(12, 12);
    short.params.pop();
    // Uniform parameters with as many uniform clamped coefficients: N is
    // numerically singular (Schoenberg-Whitney in floating point).
    let mut singular = Setup::new(200, 200);
    singular.params = (0..200).map(|i| i as f64 / 199.0).collect();
    let far_via = [(12, 0.0)];
    let mut wrong_h = Setup::new(12, 12);
    wrong_h.h = wrong_h.h.scaled(0.5);
    let cases = [
        bad_axis.problem((-0.1, 0.02), &via),
        decreasing.problem((-0.1, 0.02), &via),
        nan_point.problem((-0.1, 0.02), &via),
        short.problem((-0.1, 0.02), &via),
        singular.problem((-0.1, 0.02), &via),
        setup.problem((-0.1, 0.02), &far_via),
        setup.problem((0.02, -0.1), &via),
        setup.problem((-0.1, f64::NAN), &via),
        wrong_h.problem((-0.1, 0.02), &via),
    ];
    for (i, p) in cases.iter().enumerate() {
        match solve_mpath(p) {
            Err(PlanError::InvalidRequest { .. }) => {}
            other => panic!("case {i}: expected InvalidRequest, got {other:?}"),
        }
    }
    let fewer_points = Setup::new(10, 12);
    assert!(matches!(
        solve_mpath(&fewer_points.problem((-0.1, 0.02), &via)),
        Err(PlanError::InvalidRequest { .. })
    ));
}
