//! Tests of the rotary-axis jerk QP (seed 001 eq. 15, 19-45, 57-61).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use kerf_bspline::{basis_row, derivative_operator, jerk_hessian, BSpline, BandedSym, KnotVector};
use kerf_mjto::error::ConstraintFamily;
use kerf_mjto::qp::{solve_rotary, RotaryProblem, RotarySolution};
use kerf_mjto::{AxisLimits, LaserMachine, PlanError};
use nalgebra::{DMatrix, DVector};

const VIA: [(f64, f64); 3] = [(0.0, 0.0), (0.37, 1.0), (1.0, 0.5)];

fn loose() -> AxisLimits {
    AxisLimits {
        min: -10.0,
        max: 10.0,
        vel: 1e3,
        acc: 1e5,
        jerk: 1e7,
    }
}

/// Table 2 row of q4 (rad, rad/s, rad/s², rad/s³).
fn q4_limits() -> AxisLimits {
    LaserMachine::default_machine().unwrap().limits()[3]
}

fn problem<'a>(
    kv: &'a KnotVector,
    h: &'a BandedSym,
    limits: AxisLimits,
    (sigma, feedrate): (f64, f64),
    via: &'a [(f64, f64)],
) -> RotaryProblem<'a> {
    RotaryProblem {
        axis_name: "q4",
        knots: kv,
        hessian: h,
        limits,
        sigma,
        feedrate,
        boundary: [0.0; 4],
        via,
    }
}

/// Largest |q^{(r)}(u)|·(f/σ)^r over 4001 samples (eq. 13), r = 0..3.
fn sampled_peaks(kv: &KnotVector, coeffs: &[f64], sigma: f64, f: f64) -> [f64; 4] {
    let spline = BSpline::new(kv.clone(), coeffs.to_vec()).unwrap();
    let mut peaks = [0.0_f64; 4];
    for i in 0..=4000 {
        let e = spline.eval(i as f64 / 4000.0);
        for (r, p) in peaks.iter_mut().enumerate() {
            *p = p.max(e[r].abs() * (f / sigma).powi(r as i32));
        }
    }
    peaks
}

fn quad(h: &BandedSym, x: &[f64]) -> f64 {
    h.mul_vec(x).iter().zip(x).map(|(a, b)| a * b).sum()
}

/// Equality rows of the problem (eq. 45, then eq. 59) as a dense matrix.
fn equality_matrix(kv: &KnotVector, p: &RotaryProblem) -> (DMatrix<f64>, DVector<f64>) {
    let n = kv.n_coeffs();
    let mut rows = Vec::new();
    for ((u, d), v) in [(0.0, 1), (1.0, 1), (0.0, 2), (1.0, 2)]
        .into_iter()
        .zip(p.boundary)
    {
        rows.push((basis_row(kv, u, d).unwrap(), v));
    }
    for &(u, q) in p.via {
        rows.push((basis_row(kv, u, 0).unwrap(), q));
    }
    let mut c = DMatrix::zeros(rows.len(), n);
    let mut d = DVector::zeros(rows.len());
    for (i, (r, v)) in rows.iter().enumerate() {
        for (t, x) in r.values.iter().enumerate() {
            c[(i, r.start + t)] = *x;
        }
        d[i] = *v;
    }
    (c, d)
}

/// Checks the vias (to `tol`) and the zero boundary derivatives of eq. 45
/// (to `tol` times the derivative scale).
fn check_equalities(kv: &KnotVector, s: &RotarySolution, via: &[(f64, f64)], tol: f64) {
    let spline = BSpline::new(kv.clone(), s.coeffs.clone()).unwrap();
    for &(u, q) in via {
        let v = spline.eval(u)[0];
        assert!((v - q).abs() < tol, "via at u = {u}: {v} vs {q}");
    }
    for u in [0.0, 1.0] {
        let e = spline.eval(u);
        assert!(e[1].abs() < tol * 10.0, "q_u({u}) = {}", e[1]);
        assert!(e[2].abs() < tol * 100.0, "q_uu({u}) = {}", e[2]);
    }
}

/// With loose limits the optimum is the equality-constrained minimum-jerk
/// spline: equal to a dense KKT solve, interpolating the vias, meeting
/// eq. 45, and stationary: for any direction δ in the null space of the
/// equalities, J(Θ + δ) − J(Θ) = δᵀHδ (no first-order decrease).
#[test]
fn loose_limits_give_the_equality_constrained_minimum() {
    let n = 20;
    let kv = KnotVector::clamped_uniform(5, n).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let p = problem(&kv, &h, loose(), (1.0, 0.5), &VIA);
    let s = solve_rotary(&p).unwrap();
    assert_eq!(s.iterations, 0, "no bound is active: no interior point");
    check_equalities(&kv, &s, &VIA, 1e-9);

    let (c, d) = equality_matrix(&kv, &p);
    let m = c.nrows();
    let mut kkt = DMatrix::zeros(n + m, n + m);
    kkt.view_mut((0, 0), (n, n))
        .copy_from(&(h.to_dense() * 2.0));
    kkt.view_mut((n, 0), (m, n)).copy_from(&c);
    kkt.view_mut((0, n), (n, m)).copy_from(&c.transpose());
    let mut rhs = DVector::zeros(n + m);
    rhs.rows_mut(n, m).copy_from(&d);
    let dense = kkt.lu().solve(&rhs).unwrap();
    for j in 0..n {
        assert!((s.coeffs[j] - dense[j]).abs() < 1e-8, "coefficient {j}");
    }
    let j_dense = quad(&h, dense.rows(0, n).as_slice());
    assert!((s.objective - j_dense).abs() < 1e-9 * j_dense);
    assert!((s.objective - quad(&h, &s.coeffs)).abs() < 1e-9 * j_dense);

    // Null space of the equalities: eigenvectors of CᵀC with eigenvalue 0.
    let eig = (c.transpose() * &c).symmetric_eigen();
    let null: Vec<DVector<f64>> = (0..n)
        .filter(|&k| eig.eigenvalues[k].abs() < 1e-9)
        .map(|k| eig.eigenvectors.column(k).into_owned())
        .collect();
    assert_eq!(null.len(), n - m);
    let mut seed = 12345_u64;
    let mut rand = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    for _ in 0..20 {
        let mut delta = DVector::zeros(n);
        for v in &null {
            delta += v * rand();
        }
        assert!((&c * &delta).amax() < 1e-12);
        let x: Vec<f64> = s
            .coeffs
            .iter()
            .zip(delta.iter())
            .map(|(a, b)| a + b)
            .collect();
        let gain = quad(&h, &x) - s.objective;
        let curvature = quad(&h, delta.as_slice());
        assert!(gain > 0.0);
        assert!(
            (gain - curvature).abs() < 1e-6 * curvature,
            "{gain} vs {curvature}"
        );
    }
}

/// A brute-force reference: eq. 61 in the direct form handed to Clarabel
/// (fine for 20 coefficients, where H spans few orders of magnitude).
fn clarabel_direct(kv: &KnotVector, h: &BandedSym, p: &RotaryProblem) -> Vec<f64> {
    let n = kv.n_coeffs();
    let s = h.max_abs();
    let (mut pi, mut pj, mut pv) = (vec![], vec![], vec![]);
    for (i, j, v) in h.upper_triplets() {
        pi.push(i);
        pj.push(j);
        pv.push(2.0 * v / s);
    }
    let pm = CscMatrix::new_from_triplets(n, n, pi, pj, pv);
    let (c, d) = equality_matrix(kv, p);
    let (mut ai, mut aj, mut av, mut b) = (vec![], vec![], vec![], vec![]);
    for r in 0..c.nrows() {
        for j in 0..n {
            if c[(r, j)] != 0.0 {
                ai.push(r);
                aj.push(j);
                av.push(c[(r, j)]);
            }
        }
        b.push(d[r]);
    }
    let n_eq = b.len();
    let l = p.limits;
    let mut push = |row: Vec<(usize, f64)>, hi: f64| {
        let r = b.len();
        for (j, v) in row {
            ai.push(r);
            aj.push(j);
            av.push(v);
        }
        b.push(hi);
    };
    for j in 0..n {
        push(vec![(j, 1.0)], l.max);
        push(vec![(j, -1.0)], -l.min);
    }
    for (r, lim) in [(1, l.vel), (2, l.acc), (3, l.jerk)] {
        let bound = lim * (p.sigma / p.feedrate).powi(r as i32);
        for row in derivative_operator(kv, r).unwrap().rows {
            let scale = row.values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let plus: Vec<_> = row
                .values
                .iter()
                .enumerate()
                .map(|(t, v)| (row.start + t, v / scale))
                .collect();
            let minus = plus.iter().map(|&(j, v)| (j, -v)).collect();
            push(plus, bound / scale);
            push(minus, bound / scale);
        }
    }
    let m = b.len();
    let a = CscMatrix::new_from_triplets(m, n, ai, aj, av);
    let cones = [
        SupportedConeT::ZeroConeT(n_eq),
        SupportedConeT::NonnegativeConeT(m - n_eq),
    ];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .build()
        .unwrap();
    let mut solver = DefaultSolver::new(&pm, &vec![0.0; n], &a, &b, &cones, settings).unwrap();
    solver.solve();
    assert_eq!(solver.solution.status, SolverStatus::Solved);
    solver.solution.x.clone()
}

/// Tight velocity, acceleration, jerk and position limits in turn: the
/// interior point runs, the limit is met on dense samples (eq. 13), its
/// coefficient bound (eq. 15) is active, the cost rises above the loose
/// optimum, and the answer equals a brute-force solve of the direct form.
#[test]
fn active_limits_are_respected_and_optimal() {
    let n = 20;
    let kv = KnotVector::clamped_uniform(5, n).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let (sigma, f) = (1.0, 0.5);
    let base = solve_rotary(&problem(&kv, &h, loose(), (sigma, f), &VIA)).unwrap();
    let peak = sampled_peaks(&kv, &base.coeffs, sigma, f);
    let cases = [
        (
            1,
            AxisLimits {
                vel: 0.8 * peak[1],
                ..loose()
            },
        ),
        (
            2,
            AxisLimits {
                acc: 0.8 * peak[2],
                ..loose()
            },
        ),
        (
            3,
            AxisLimits {
                jerk: 0.8 * peak[3],
                ..loose()
            },
        ),
        (
            0,
            AxisLimits {
                max: 1.05,
                ..loose()
            },
        ),
    ];
    for (r, limits) in cases {
        let p = problem(&kv, &h, limits, (sigma, f), &VIA);
        let s = solve_rotary(&p).unwrap();
        assert!(s.iterations > 0, "r = {r}: a bound is active");
        check_equalities(&kv, &s, &VIA, 1e-8);
        let lim = [limits.max, limits.vel, limits.acc, limits.jerk][r];
        let got = sampled_peaks(&kv, &s.coeffs, sigma, f)[r];
        assert!(got <= lim * (1.0 + 1e-9), "r = {r}: {got} > {lim}");
        // The coefficient bound of eq. 15 is active.
        let coeff_peak = if r == 0 {
            s.coeffs.iter().fold(0.0_f64, |m, v| m.max(*v))
        } else {
            let d = derivative_operator(&kv, r).unwrap().mul_vec(&s.coeffs);
            d.iter().fold(0.0_f64, |m, v| m.max(v.abs())) * (f / sigma).powi(r as i32)
        };
        assert!(
            (coeff_peak - lim).abs() < 1e-7 * lim,
            "r = {r}: {coeff_peak} vs {lim}"
        );
        assert!(s.objective > base.objective * (1.0 + 1e-6), "r = {r}");
        // The brute-force answer is only accurate to its stopping
        // tolerance: ours must be as good and close.
        let reference = clarabel_direct(&kv, &h, &p);
        let j_ref = quad(&h, &reference);
        assert!(
            s.objective <= j_ref * (1.0 + 1e-9),
            "r = {r}: {} vs {j_ref}",
            s.objective
        );
        assert!(
            s.objective >= j_ref * (1.0 - 1e-4),
            "r = {r}: {} vs {j_ref}",
            s.objective
        );
        for (a, b) in s.coeffs.iter().zip(&reference) {
            assert!((a - b).abs() < 1e-3, "r = {r}: coefficients {a} vs {b}");
        }
    }
}

/// Too high a feedrate for q4's Table 2 limits: Infeasible, family
/// velocity/acceleration/jerk, with the largest feasible feedrate f*;
/// 0.99 f* solves, 1.01 f* does not.
#[test]
fn feedrate_infeasibility_reports_the_largest_feasible_feedrate() {
    let kv = KnotVector::clamped_uniform(5, 40).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let via = [(0.0, 0.0), (0.5, 2.5), (1.0, 0.0)];
    let sigma = 0.3;
    let err = solve_rotary(&problem(&kv, &h, q4_limits(), (sigma, 1.0), &via)).unwrap_err();
    let PlanError::Infeasible {
        problem: name,
        family,
        max_feasible_feedrate,
        ..
    } = &err
    else {
        panic!("expected Infeasible, got {err}");
    };
    assert_eq!(name, "q4");
    assert!(
        matches!(
            family,
            ConstraintFamily::Velocity | ConstraintFamily::Acceleration | ConstraintFamily::Jerk
        ),
        "{err}"
    );
    println!("{err}");
    let fstar = max_feasible_feedrate.expect("a feedrate family reports f*");
    assert!(fstar > 0.0 && fstar < 1.0, "{fstar}");
    let below = solve_rotary(&problem(&kv, &h, q4_limits(), (sigma, 0.99 * fstar), &via)).unwrap();
    let lim = q4_limits();
    let peaks = sampled_peaks(&kv, &below.coeffs, sigma, 0.99 * fstar);
    assert!(peaks[1] <= lim.vel * (1.0 + 1e-9));
    assert!(peaks[2] <= lim.acc * (1.0 + 1e-9));
    assert!(peaks[3] <= lim.jerk * (1.0 + 1e-9));
    let above = solve_rotary(&problem(&kv, &h, q4_limits(), (sigma, 1.01 * fstar), &via));
    assert!(
        matches!(above, Err(PlanError::Infeasible { .. })),
        "1.01 f* must be infeasible: {above:?}"
    );
}

/// An RTO outside the position range of q5 is reported as the position
/// bounds or the RTO equalities, without a feedrate.
#[test]
fn rto_outside_the_position_range_is_named() {
    let kv = KnotVector::clamped_uniform(5, 30).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let q5 = LaserMachine::default_machine().unwrap().limits()[4];
    let via = [(0.0, 0.0), (0.5, 2.0), (1.0, 0.2)];
    let mut p = problem(&kv, &h, q5, (0.5, 0.1), &via);
    p.axis_name = "q5";
    match solve_rotary(&p) {
        Err(PlanError::Infeasible {
            problem,
            family,
            max_feasible_feedrate,
            detail,
        }) => {
            assert_eq!(problem, "q5");
            assert!(
                matches!(family, ConstraintFamily::Position | ConstraintFamily::Rto),
                "{family:?}"
            );
            assert_eq!(max_feasible_feedrate, None);
            assert!(detail.contains("RTO 1"), "{detail}");
        }
        other => panic!("expected Infeasible, got {other:?}"),
    }
}

/// Two RTOs asking different angles at the same parameter contradict each
/// other: the RTO equalities are named.
#[test]
fn contradicting_rtos_are_named() {
    let kv = KnotVector::clamped_uniform(5, 30).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let via = [(0.0, 0.0), (0.5, 0.3), (0.5, 0.4), (1.0, 0.2)];
    match solve_rotary(&problem(&kv, &h, q4_limits(), (0.5, 0.1), &via)) {
        Err(PlanError::Infeasible {
            family,
            max_feasible_feedrate,
            ..
        }) => {
            assert_eq!(family, ConstraintFamily::Rto);
            assert_eq!(max_feasible_feedrate, None);
        }
        other => panic!("expected Infeasible, got {other:?}"),
    }
}

/// 628 coefficients (one per CL point of the paper's case, 4 ms × 628 =
/// 2.51 s at f = 0.5 m/s): loose and tight-velocity cases solve, meet the
/// vias, eq. 45 and the limits. Timings are printed, not asserted.
#[test]
fn n628_solves() {
    let kv = KnotVector::clamped_uniform(5, 628).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let (f, sigma) = (0.5, 0.5 * 2.51);
    let via = [
        (0.0, 0.1),
        (0.2, 0.5),
        (0.4, 0.3),
        (0.6, -0.2),
        (0.8, 0.0),
        (1.0, 0.1),
    ];
    let t = std::time::Instant::now();
    let s = solve_rotary(&problem(&kv, &h, q4_limits(), (sigma, f), &via)).unwrap();
    println!(
        "rotary n+1 = 628, Table 2 limits: {:?}, {} IPM iterations, cost {:.6}",
        t.elapsed(),
        s.iterations,
        s.objective
    );
    check_equalities(&kv, &s, &via, 1e-8);
    let peaks = sampled_peaks(&kv, &s.coeffs, sigma, f);
    let lim = q4_limits();
    assert!(peaks[1] <= lim.vel && peaks[2] <= lim.acc && peaks[3] <= lim.jerk);

    let tight = AxisLimits {
        vel: 0.8 * peaks[1],
        ..lim
    };
    let t = std::time::Instant::now();
    let s2 = solve_rotary(&problem(&kv, &h, tight, (sigma, f), &via)).unwrap();
    println!(
        "rotary n+1 = 628, velocity limit active: {:?}, {} IPM iterations, cost {:.6}",
        t.elapsed(),
        s2.iterations,
        s2.objective
    );
    assert!(s2.iterations > 0);
    check_equalities(&kv, &s2, &via, 1e-8);
    let peaks2 = sampled_peaks(&kv, &s2.coeffs, sigma, f);
    assert!(
        peaks2[1] <= tight.vel * (1.0 + 1e-9),
        "{} > {}",
        peaks2[1],
        tight.vel
    );
    assert!(s2.objective > s.objective);
}

/// Malformed inputs are InvalidRequest errors, never panics.
#[test]
fn invalid_inputs_are_rejected() {
    let kv = KnotVector::clamped_uniform(5, 12).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let h_small = jerk_hessian(&KnotVector::clamped_uniform(5, 10).unwrap()).unwrap();
    let h_scaled = h.scaled(2.0);
    let nan_via = [(0.5, f64::NAN)];
    let far_via = [(1.5, 0.0)];
    let ok_via = [(0.5, 0.0)];
    let bad_range = AxisLimits {
        min: 1.0,
        max: -1.0,
        ..loose()
    };
    let nan_jerk = AxisLimits {
        jerk: f64::NAN,
        ..loose()
    };
    let mut nan_boundary = problem(&kv, &h, loose(), (1.0, 0.5), &ok_via);
    nan_boundary.boundary[2] = f64::INFINITY;
    let cases = [
        problem(&kv, &h, loose(), (1.0, 0.5), &nan_via),
        problem(&kv, &h, loose(), (1.0, 0.5), &far_via),
        problem(&kv, &h, loose(), (0.0, 0.5), &ok_via),
        problem(&kv, &h, loose(), (1.0, -0.5), &ok_via),
        problem(&kv, &h_small, loose(), (1.0, 0.5), &ok_via),
        problem(&kv, &h_scaled, loose(), (1.0, 0.5), &ok_via),
        problem(&kv, &h, bad_range, (1.0, 0.5), &ok_via),
        problem(&kv, &h, nan_jerk, (1.0, 0.5), &ok_via),
        nan_boundary,
    ];
    for (i, p) in cases.iter().enumerate() {
        match solve_rotary(p) {
            Err(PlanError::InvalidRequest { .. }) => {}
            other => panic!("case {i}: expected InvalidRequest, got {other:?}"),
        }
    }
}
