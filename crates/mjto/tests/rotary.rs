//! The rotary-axis jerk QP (seed 001 eq. 15-45, 57-61) as the SOCP of
//! `kerf_mjto::rotary`, checked against independent computations: the
//! explicit banded Hessian of eq. 18, a quadrature of q'''², a dense KKT
//! solve of the equality-constrained problem, the closed-form minimum-jerk
//! quintic, and dense evaluation of the resulting splines against the
//! limits scaled by eq. 13.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_bspline::{jerk_hessian, BSpline, KnotVector};
use kerf_mjto::error::ConstraintFamily;
use kerf_mjto::rotary::{JerkFactor, RotaryQp};
use kerf_mjto::{AxisLimits, LaserMachine, PlanError};
use nalgebra::{DMatrix, DVector};

const K: usize = 5;

mod common;
use common::Rng;

/// Limits that never bind here (positions ±10 rad, 100 rad/s, 10³ rad/s²,
/// 10⁴ rad/s³; the curves below stay an order of magnitude inside).
///
/// Not wider: with bounds spread over many more orders of magnitude
/// (e.g. 10⁸ rad/s², 10¹⁰ rad/s³) Clarabel stops on some infeasible
/// problems with InsufficientProgress instead of an infeasibility
/// certificate, and `solve` reports `PlanError::Solver`.
fn loose() -> AxisLimits {
    AxisLimits {
        min: -10.0,
        max: 10.0,
        vel: 1e2,
        acc: 1e3,
        jerk: 1e4,
    }
}

fn problem<'a>(
    knots: &'a KnotVector,
    factor: &'a JerkFactor,
    limits: AxisLimits,
    sigma: f64,
    feedrate: f64,
    via: &'a [(f64, f64)],
) -> RotaryQp<'a> {
    RotaryQp {
        axis_name: "q5",
        knots,
        factor,
        limits,
        sigma,
        feedrate,
        boundary: [0.0; 4],
        via,
        via_box: &[],
        corridor: &[],
        free_end_slopes: false,
    }
}

/// Value and derivatives of basis function j at u, from `BSpline::eval` of
/// the unit coefficient vector e_j (independent of `basis_row`).
fn basis(knots: &KnotVector, j: usize, u: f64) -> [f64; 4] {
    let mut e = vec![0.0; knots.n_coeffs()];
    e[j] = 1.0;
    BSpline::new(knots.clone(), e).unwrap().eval(u)
}

/// Dense H of eq. 18 from `kerf_bspline::jerk_hessian`.
fn dense_h(knots: &KnotVector) -> DMatrix<f64> {
    jerk_hessian(knots).unwrap().to_dense()
}

/// `∫₀¹ q'''(u)² du` by composite 3-point Gauss-Legendre on 8 pieces of
/// every knot span (q''' of a quintic is a quadratic per span, so q'''² is
/// integrated exactly), with q''' from `BSpline::eval`.
fn quadrature_jerk(spline: &BSpline) -> f64 {
    let t = spline.knots().knots();
    let nodes = [-(0.6f64.sqrt()), 0.0, 0.6f64.sqrt()];
    let weights = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let mut total = 0.0;
    for w in t.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        for piece in 0..8 {
            let lo = a + (b - a) * piece as f64 / 8.0;
            let hi = a + (b - a) * (piece + 1) as f64 / 8.0;
            let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            for (x, wt) in nodes.iter().zip(&weights) {
                total += wt * half * spline.eval(mid + half * x)[3].powi(2);
            }
        }
    }
    total
}

/// The minimiser of Θᵀ H Θ subject to `rows · Θ = rhs`, from the dense KKT
/// system [2H Aᵀ; A 0] [Θ; λ] = [0; b] (LU).
fn kkt(h: &DMatrix<f64>, rows: &[Vec<f64>], rhs: &[f64]) -> Vec<f64> {
    let n = h.nrows();
    let m = rows.len();
    let mut a = DMatrix::zeros(n + m, n + m);
    a.view_mut((0, 0), (n, n)).copy_from(&(2.0 * h));
    for (i, r) in rows.iter().enumerate() {
        for (j, &v) in r.iter().enumerate() {
            a[(n + i, j)] = v;
            a[(j, n + i)] = v;
        }
    }
    let mut b = DVector::zeros(n + m);
    for (i, &v) in rhs.iter().enumerate() {
        b[n + i] = v;
    }
    let x = a.lu().solve(&b).expect("KKT system singular");
    x.iter().take(n).copied().collect()
}

/// The equality rows of eq. 45 (zero boundary derivatives) and eq. 57-60.
fn equalities(knots: &KnotVector, via: &[(f64, f64)]) -> (Vec<Vec<f64>>, Vec<f64>) {
    let n = knots.n_coeffs();
    let mut rows = Vec::new();
    let mut rhs = Vec::new();
    for (u, d) in [(0.0, 1), (1.0, 1), (0.0, 2), (1.0, 2)] {
        rows.push((0..n).map(|j| basis(knots, j, u)[d]).collect());
        rhs.push(0.0);
    }
    for &(u, q) in via {
        rows.push((0..n).map(|j| basis(knots, j, u)[0]).collect());
        rhs.push(q);
    }
    (rows, rhs)
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Peak |q_u|, |q_uu|, |q_uuu| and the position range of a spline over
/// 4001 equally spaced parameters.
fn peaks(spline: &BSpline) -> ([f64; 3], f64, f64) {
    let mut p = [0.0f64; 3];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..=4000 {
        let d = spline.eval(i as f64 / 4000.0);
        for r in 0..3 {
            p[r] = p[r].max(d[r + 1].abs());
        }
        lo = lo.min(d[0]);
        hi = hi.max(d[0]);
    }
    (p, lo, hi)
}

#[test]
fn jerk_cost_equals_the_banded_hessian_and_a_quadrature() {
    let uniform = KnotVector::clamped_uniform(K, 12).unwrap();
    // Uneven parameters (a short last segment) give uneven knots.
    let params: Vec<f64> = (0..30)
        .map(|i| {
            let x = i as f64 / 29.0;
            if i == 29 {
                1.0
            } else {
                x.powf(1.3) * 0.97
            }
        })
        .collect();
    let uneven = KnotVector::for_parameters(K, 12, &params).unwrap();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for knots in [&uniform, &uneven] {
        assert_eq!(knots.n_coeffs(), 12);
        let factor = JerkFactor::new(knots).unwrap();
        assert_eq!(factor.n_coeffs, 12);
        let h = dense_h(knots);
        for trial in 0..5 {
            let theta: Vec<f64> = (0..12).map(|_| rng.signed()).collect();
            let cost = factor.jerk_cost(&theta);
            let t = DVector::from_column_slice(&theta);
            let banded = (t.transpose() * &h * &t)[(0, 0)];
            let spline = BSpline::new(knots.clone(), theta.clone()).unwrap();
            let quad = quadrature_jerk(&spline);
            assert!(cost > 0.0);
            assert!(
                (cost - banded).abs() <= 1e-9 * banded,
                "trial {trial}: {cost} vs θᵀHθ {banded}"
            );
            assert!(
                (cost - quad).abs() <= 1e-9 * quad,
                "trial {trial}: {cost} vs quadrature {quad}"
            );
        }
        // Quadratics cost nothing (the null space of H): a least-squares fit
        // reproduces a quadratic exactly.
        let fit_params: Vec<f64> = (0..40).map(|i| i as f64 / 39.0).collect();
        let values: Vec<f64> = fit_params
            .iter()
            .map(|x| 3.0 * x * x - 2.0 * x + 0.5)
            .collect();
        let quadratic = kerf_bspline::fit(knots, &fit_params, &values).unwrap();
        let spline = BSpline::new(knots.clone(), quadratic.clone()).unwrap();
        assert!((spline.eval(0.3)[0] - (3.0 * 0.09 - 0.6 + 0.5)).abs() < 1e-12);
        assert!(factor.jerk_cost(&quadratic) < 1e-16);
        // A cubic u³ has q''' = 6: cost 36.
        let cubic: Vec<f64> = {
            let params: Vec<f64> = (0..40).map(|i| i as f64 / 39.0).collect();
            let values: Vec<f64> = params.iter().map(|u| u * u * u).collect();
            kerf_bspline::fit(knots, &params, &values).unwrap()
        };
        assert!((factor.jerk_cost(&cubic) - 36.0).abs() < 1e-8);
    }
    // A wrong length gives NaN, not a panic or a silent partial sum.
    let factor = JerkFactor::new(&uniform).unwrap();
    assert!(factor.jerk_cost(&[1.0; 5]).is_nan());
}

#[test]
fn loose_limits_give_the_equality_constrained_minimiser() {
    let knots = KnotVector::clamped_uniform(K, 12).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let h = dense_h(&knots);
    let cases: [&[(f64, f64)]; 3] = [
        &[(0.0, 0.1), (1.0, 0.9)],
        &[(0.0, 0.2), (0.37, 1.1), (1.0, -0.4)],
        &[(0.0, -0.3), (0.52, 0.25), (1.0, 0.25)],
    ];
    for via in cases {
        let qp = problem(&knots, &factor, loose(), 0.8, 0.25, via);
        let (theta, iterations) = qp.solve().unwrap();
        assert_eq!(theta.len(), 12);
        assert!(iterations > 0);
        let spline = BSpline::new(knots.clone(), theta.clone()).unwrap();
        // Interpolates the vias (eq. 57-60).
        for &(u, q) in via {
            let v = spline.eval(u)[0];
            assert!((v - q).abs() < 1e-7, "q({u}) = {v}, want {q}");
        }
        // Eq. 45 with zero boundary values: q_u and q_uu at 0 and 1 vanish
        // relative to what the coefficients could produce (q_u ~ n|Θ|,
        // q_uu ~ n²|Θ| on these knots).
        let scale = max_abs(&theta);
        let (d0, d1) = (spline.eval(0.0), spline.eval(1.0));
        for (d, r) in [(d0[1], 1), (d1[1], 1), (d0[2], 2), (d1[2], 2)] {
            let size = scale * (12f64).powi(r);
            assert!(d.abs() <= 1e-7 * size, "q^({r}) = {d} at an end");
        }
        // The dense KKT minimiser of Θᵀ H Θ under the same equalities.
        let (rows, rhs) = equalities(&knots, via);
        let exact = kkt(&h, &rows, &rhs);
        let err = theta
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            err <= 1e-5 * max_abs(&exact),
            "{via:?}: max |Θ - Θ_KKT| = {err:e} (|Θ| {})",
            max_abs(&exact)
        );
        // Its cost is the optimum: no lower than the KKT solution's.
        let c = factor.jerk_cost(&theta);
        let c_exact = factor.jerk_cost(&exact);
        assert!(c <= c_exact * (1.0 + 1e-6), "{c} vs {c_exact}");
        assert!(c >= c_exact * (1.0 - 1e-6), "{c} vs {c_exact}");
    }
    // Rest to rest between two vias at the ends, the optimum of ∫q'''² is
    // the minimum-jerk quintic a + (b − a)(10u³ − 15u⁴ + 6u⁵), which the
    // quintic spline space contains.
    let via = [(0.0, 0.1), (1.0, 0.9)];
    let (theta, _) = problem(&knots, &factor, loose(), 0.8, 0.25, &via)
        .solve()
        .unwrap();
    let spline = BSpline::new(knots.clone(), theta).unwrap();
    for i in 0..=100 {
        let u = i as f64 / 100.0;
        let s = 10.0 * u.powi(3) - 15.0 * u.powi(4) + 6.0 * u.powi(5);
        let ds = 30.0 * u * u - 60.0 * u.powi(3) + 30.0 * u.powi(4);
        let d = spline.eval(u);
        assert!((d[0] - (0.1 + 0.8 * s)).abs() < 1e-6, "u = {u}");
        assert!((d[1] - 0.8 * ds).abs() < 1e-4, "u = {u}");
    }
    // Its jerk cost: ∫(0.8 · (60 − 360u + 360u²))² du = 0.64 · 720.
    let cost = factor.jerk_cost(spline.coeffs());
    assert!((cost - 0.64 * 720.0).abs() < 1e-4 * 460.8, "{cost}");
}

/// The rest-to-rest move 0 → 1 over σ = 0.8 m at f = 0.5 m/s (f/σ =
/// 0.625): unconstrained, its peaks are those of the minimum-jerk quintic,
/// 1.875 · 0.625 = 1.172 rad/s, 5.7735 · 0.625² = 2.255 rad/s², 60 · 0.625³
/// = 14.65 rad/s³.
const SIGMA: f64 = 0.8;
const FEED: f64 = 0.5;
const MOVE: [(f64, f64); 2] = [(0.0, 0.0), (1.0, 1.0)];

#[test]
fn tight_limits_hold_on_the_dense_curve_and_are_active() {
    let knots = KnotVector::clamped_uniform(K, 30).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let s = FEED / SIGMA;
    let scale = [s, s * s, s * s * s];
    // Unconstrained peaks, in time units (eq. 13).
    let (theta, _) = problem(&knots, &factor, loose(), SIGMA, FEED, &MOVE)
        .solve()
        .unwrap();
    let (free, _, _) = peaks(&BSpline::new(knots.clone(), theta).unwrap());
    let free: Vec<f64> = (0..3).map(|r| free[r] * scale[r]).collect();
    assert!((free[0] - 1.875 * s).abs() < 1e-3 * free[0], "{free:?}");
    assert!(
        (free[1] - 5.773_503 * s * s).abs() < 1e-3 * free[1],
        "{free:?}"
    );
    assert!(
        (free[2] - 60.0 * s * s * s).abs() < 1e-2 * free[2],
        "{free:?}"
    );

    // One family tightened at a time, below its unconstrained peak.
    let names = ["velocity", "acceleration", "jerk"];
    for (r, limit) in [(0usize, 0.95), (1, 1.8), (2, 11.0)] {
        assert!(limit < free[r]);
        let mut l = loose();
        match r {
            0 => l.vel = limit,
            1 => l.acc = limit,
            _ => l.jerk = limit,
        }
        let qp = problem(&knots, &factor, l, SIGMA, FEED, &MOVE);
        let (theta, _) = qp.solve().unwrap();
        let spline = BSpline::new(knots.clone(), theta.clone()).unwrap();
        let (p, lo, hi) = peaks(&spline);
        let value = p[r] * scale[r];
        assert!(
            value <= limit * (1.0 + 1e-6),
            "{}: peak {value} over the limit {limit}",
            names[r]
        );
        assert!(
            value >= 0.99 * limit,
            "{}: peak {value}, the limit {limit} is not active",
            names[r]
        );
        // The other two stay within their (loose) limits, the vias hold.
        for (o, v) in p.iter().enumerate() {
            let lim = [l.vel, l.acc, l.jerk][o];
            assert!(v * scale[o] <= lim);
        }
        assert!(lo >= l.min && hi <= l.max);
        for &(u, q) in &MOVE {
            assert!((spline.eval(u)[0] - q).abs() < 1e-7);
        }
        // Smoothest under the bound: costlier than the free optimum.
        let free_theta = problem(&knots, &factor, loose(), SIGMA, FEED, &MOVE)
            .solve()
            .unwrap()
            .0;
        assert!(factor.jerk_cost(&theta) > factor.jerk_cost(&free_theta) * (1.0 + 1e-6));
    }

    // All three at once, each a little below its unconstrained peak, plus
    // a position window that the unconstrained curve (in [0, 1]) respects.
    let l = AxisLimits {
        min: -0.01,
        max: 1.01,
        vel: 1.1,
        acc: 2.15,
        jerk: 13.5,
    };
    let (theta, _) = problem(&knots, &factor, l, SIGMA, FEED, &MOVE)
        .solve()
        .unwrap();
    let (p, lo, hi) = peaks(&BSpline::new(knots.clone(), theta).unwrap());
    let value = [p[0] * scale[0], p[1] * scale[1], p[2] * scale[2]];
    // Each within the limit; the jerk is at it. With three active families
    // the interior-point answer overshoots the jerk bound by 2.5e-6
    // relative (13.500034 against 13.5: Clarabel's tolerance, which the
    // post-check of `rotary.rs` accepts because it measures a D₃ row
    // against Σ|a_j|·max|Θ|, ~10⁷ here, not against the bound), so this
    // case is held to 1e-5; the single families above meet 1e-6.
    for (r, limit) in [l.vel, l.acc, l.jerk].into_iter().enumerate() {
        assert!(value[r] <= limit * (1.0 + 1e-5), "{r}: {value:?}");
    }
    assert!(value[2] >= 0.99 * l.jerk, "{value:?}");
    assert!(lo >= l.min - 1e-9 && hi <= l.max + 1e-9, "[{lo}, {hi}]");
}

/// The error of a solve: `(family, max_feasible_feedrate)`.
fn infeasible(r: Result<(Vec<f64>, u32), PlanError>) -> (ConstraintFamily, Option<f64>) {
    match r {
        Err(PlanError::Infeasible {
            problem,
            family,
            max_feasible_feedrate,
            detail,
        }) => {
            assert_eq!(problem, "q5");
            assert!(!detail.is_empty());
            (family, max_feasible_feedrate)
        }
        other => panic!("expected Infeasible, got {other:?}"),
    }
}

#[test]
fn too_high_a_feedrate_is_infeasible_with_the_largest_feasible_one() {
    let knots = KnotVector::clamped_uniform(K, 20).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    // At f = 2 m/s (f/σ = 2.5) the unit rest-to-rest move needs |q_u| >= 1
    // somewhere (its mean), i.e. |q̇| >= 2.5 rad/s against 1; |q_uu| >= 4
    // (bang-bang acceleration), |q̈| >= 25 against 2; |q_uuu| >= 32
    // (bang-bang jerk), |q⃛| >= 500 against 11.
    let cases = [
        (
            AxisLimits {
                vel: 1.0,
                ..loose()
            },
            ConstraintFamily::Velocity,
        ),
        (
            AxisLimits {
                acc: 2.0,
                ..loose()
            },
            ConstraintFamily::Acceleration,
        ),
        (
            AxisLimits {
                jerk: 11.0,
                ..loose()
            },
            ConstraintFamily::Jerk,
        ),
    ];
    for (r, (limits, family)) in cases.into_iter().enumerate() {
        let qp = problem(&knots, &factor, limits, SIGMA, 2.0, &MOVE);
        let (got, f_max) = infeasible(qp.solve());
        assert_eq!(got, family);
        let f_max = f_max.expect("a kinematic family names the largest feedrate");
        assert!(f_max > 0.0 && f_max < 2.0, "{f_max}");
        assert_eq!(qp.max_feasible_feedrate().unwrap(), Some(f_max));
        // Feasibility is monotone in f and f* is resolved to 0.1 %.
        let below = RotaryQp {
            feedrate: 0.99 * f_max,
            ..qp
        };
        below.solve().unwrap();
        let above = RotaryQp {
            feedrate: 1.01 * f_max,
            ..qp
        };
        let (again, f_again) = infeasible(above.solve());
        assert_eq!(again, family);
        assert!(f_again.unwrap() <= 1.01 * f_max);
        // At f* itself the limit holds on the dense curve and is reached
        // within 2 % (the rest is the convex-hull margin of eq. 15).
        let (theta, _) = RotaryQp {
            feedrate: f_max,
            ..qp
        }
        .solve()
        .unwrap();
        let (p, _, _) = peaks(&BSpline::new(knots.clone(), theta).unwrap());
        let s = f_max / SIGMA;
        let value = p[r] * s.powi(r as i32 + 1);
        let limit = [limits.vel, limits.acc, limits.jerk][r];
        assert!(
            value <= limit * (1.0 + 1e-6),
            "{family:?}: {value} > {limit}"
        );
        assert!(value >= 0.98 * limit, "{family:?}: {value} << {limit}");
    }
    // The velocity bound by hand: no curve from 0 to 1 over [0, 1] has
    // |q_u| < 1 everywhere, so f* < σ · 1 rad/s = 0.8 m/s.
    let qp = problem(&knots, &factor, cases[0].0, SIGMA, 2.0, &MOVE);
    assert!(qp.max_feasible_feedrate().unwrap().unwrap() < 0.8);
    // All three together: infeasible, a kinematic family is named (no
    // single family's removal is enough here) with the feedrate at which
    // all three hold.
    let all = AxisLimits {
        vel: 1.0,
        acc: 2.0,
        jerk: 11.0,
        ..loose()
    };
    let qp = problem(&knots, &factor, all, SIGMA, 2.0, &MOVE);
    let (family, f_max) = infeasible(qp.solve());
    assert!(matches!(
        family,
        ConstraintFamily::Velocity | ConstraintFamily::Acceleration | ConstraintFamily::Jerk
    ));
    let f_max = f_max.unwrap();
    let (theta, _) = RotaryQp {
        feedrate: 0.99 * f_max,
        ..qp
    }
    .solve()
    .unwrap();
    let (p, _, _) = peaks(&BSpline::new(knots.clone(), theta).unwrap());
    let s = 0.99 * f_max / SIGMA;
    assert!(
        p[0] * s <= 1.0 + 1e-6 && p[1] * s * s <= 2.0 + 1e-6 && p[2] * s.powi(3) <= 11.0 + 1e-5
    );
    infeasible(
        RotaryQp {
            feedrate: 1.01 * f_max,
            ..qp
        }
        .solve(),
    );
}

#[test]
fn a_via_outside_the_position_range_is_a_position_or_rto_error() {
    let knots = KnotVector::clamped_uniform(K, 16).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let limits = AxisLimits {
        min: -1.0,
        max: 1.0,
        ..loose()
    };
    let via = [(0.0, 0.0), (0.5, 1.5), (1.0, 0.0)];
    let qp = problem(&knots, &factor, limits, SIGMA, FEED, &via);
    let (family, f_max) = infeasible(qp.solve());
    assert!(
        matches!(family, ConstraintFamily::Position | ConstraintFamily::Rto),
        "{family:?}"
    );
    assert_eq!(f_max, None);
    // Two vias at the same u with different values contradict each other:
    // the RTO family.
    let via = [(0.0, 0.0), (0.5, 0.2), (0.5, 0.3), (1.0, 0.0)];
    let qp = problem(&knots, &factor, loose(), SIGMA, FEED, &via);
    let (family, f_max) = infeasible(qp.solve());
    assert_eq!(family, ConstraintFamily::Rto);
    assert_eq!(f_max, None);
}

#[test]
fn paper_size_628_coefficients_with_the_table2_q5_limits() {
    let machine = LaserMachine::default_machine().unwrap();
    let q5 = machine.limits()[4];
    assert_eq!(
        (q5.min, q5.max),
        (-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2)
    );
    // 628 CL points 4 mm apart (σ = 2.508 m), as in seed 001 case 2; one
    // coefficient per point; RTOs through two 77° turns.
    let params: Vec<f64> = (0..628).map(|i| i as f64 / 627.0).collect();
    let knots = KnotVector::for_parameters(K, 628, &params).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let t77 = 77f64.to_radians();
    let via: Vec<(f64, f64)> = [
        (0, 0.0),
        (60, 0.0),
        (150, 0.4),
        (200, t77),
        (300, t77),
        (350, 0.5),
        (420, 0.0),
        (470, -0.6),
        (520, -t77),
        (627, -t77),
    ]
    .iter()
    .map(|&(i, q)| (params[i], q))
    .collect();
    let sigma = 2.508;
    let feed = 0.25;
    let qp = RotaryQp {
        axis_name: "q5",
        knots: &knots,
        factor: &factor,
        limits: q5,
        sigma,
        feedrate: feed,
        boundary: [0.0; 4],
        via: &via,
        via_box: &[],
        corridor: &[],
        free_end_slopes: false,
    };
    let (theta, _) = qp.solve().unwrap();
    assert_eq!(theta.len(), 628);
    let spline = BSpline::new(knots.clone(), theta.clone()).unwrap();
    for &(u, q) in &via {
        assert!((spline.eval(u)[0] - q).abs() < 1e-7, "u = {u}");
    }
    let s = feed / sigma;
    let mut peak = [0.0f64; 3];
    for i in 0..=20_000 {
        let d = spline.eval(i as f64 / 20_000.0);
        assert!(d[0] >= q5.min - 1e-9 && d[0] <= q5.max + 1e-9, "{}", d[0]);
        for r in 0..3 {
            peak[r] = peak[r].max(d[r + 1].abs() * s.powi(r as i32 + 1));
        }
    }
    assert!(peak[0] <= q5.vel * (1.0 + 1e-6), "{peak:?}");
    assert!(peak[1] <= q5.acc * (1.0 + 1e-6), "{peak:?}");
    assert!(peak[2] <= q5.jerk * (1.0 + 1e-6), "{peak:?}");
    // The RTOs at ±77° make the spline overshoot towards ±π/2: the
    // position bounds of eq. 15 keep it inside.
    assert!(peak_position(&spline) > 1.57, "{}", peak_position(&spline));
    // At 1 m/s (f/σ = 0.399) the Table 2 jerk of 200 rad/s³ binds and holds
    // on the dense curve; at 4 m/s no spline meets it: the largest
    // feasible feedrate lies between.
    let fast = RotaryQp {
        feedrate: 1.0,
        ..qp
    };
    let (theta, _) = fast.solve().unwrap();
    let spline = BSpline::new(knots.clone(), theta).unwrap();
    let s = 1.0 / sigma;
    let mut jerk = 0.0f64;
    for i in 0..=20_000 {
        let d = spline.eval(i as f64 / 20_000.0);
        assert!(d[0] >= q5.min - 1e-9 && d[0] <= q5.max + 1e-9);
        assert!(d[1].abs() * s <= q5.vel * (1.0 + 1e-6));
        assert!(d[2].abs() * s * s <= q5.acc * (1.0 + 1e-6));
        jerk = jerk.max(d[3].abs() * s * s * s);
    }
    assert!(jerk <= q5.jerk * (1.0 + 1e-6), "{jerk}");
    assert!(jerk >= 0.99 * q5.jerk, "{jerk}");
    let too_fast = RotaryQp {
        feedrate: 4.0,
        ..qp
    };
    match too_fast.solve() {
        Err(PlanError::Infeasible {
            family,
            max_feasible_feedrate: Some(f),
            ..
        }) => {
            assert!(matches!(
                family,
                ConstraintFamily::Velocity
                    | ConstraintFamily::Acceleration
                    | ConstraintFamily::Jerk
            ));
            assert!(f > 1.0 && f < 4.0, "{f}");
        }
        other => panic!("{other:?}"),
    }
}

fn peak_position(spline: &BSpline) -> f64 {
    (0..=20_000)
        .map(|i| spline.eval(i as f64 / 20_000.0)[0].abs())
        .fold(0.0, f64::max)
}

#[test]
fn invalid_inputs_are_errors_not_panics() {
    let knots = KnotVector::clamped_uniform(K, 12).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let base = problem(&knots, &factor, loose(), SIGMA, FEED, &MOVE);
    assert!(base.solve().is_ok());
    for (sigma, feed) in [
        (SIGMA, 0.0),
        (SIGMA, -0.1),
        (SIGMA, f64::NAN),
        (SIGMA, f64::INFINITY),
        (f64::NAN, FEED),
        (0.0, FEED),
        (-1.0, FEED),
        (f64::INFINITY, FEED),
    ] {
        let qp = RotaryQp {
            sigma,
            feedrate: feed,
            ..base
        };
        match qp.solve() {
            Err(PlanError::InvalidRequest { field, .. }) => assert_eq!(field, "q5"),
            other => panic!("σ = {sigma}, f = {feed}: {other:?}"),
        }
    }
    // A NaN or out-of-range via parameter, a NaN via value or boundary
    // value: an error.
    for via in [
        [(0.0, 0.0), (f64::NAN, 1.0)],
        [(0.0, 0.0), (1.5, 1.0)],
        [(0.0, 0.0), (1.0, f64::NAN)],
    ] {
        let qp = RotaryQp { via: &via, ..base };
        assert!(qp.solve().is_err(), "{via:?}");
    }
    let qp = RotaryQp {
        boundary: [0.0, f64::NAN, 0.0, 0.0],
        ..base
    };
    assert!(qp.solve().is_err());
    // NaN limits.
    let qp = RotaryQp {
        limits: AxisLimits {
            jerk: f64::NAN,
            ..loose()
        },
        ..base
    };
    assert!(qp.solve().is_err());
    // A factor built for other knots.
    let other = KnotVector::clamped_uniform(K, 13).unwrap();
    let wrong = JerkFactor::new(&other).unwrap();
    let qp = RotaryQp {
        factor: &wrong,
        ..base
    };
    assert!(matches!(qp.solve(), Err(PlanError::Solver { .. })));
    // Knots below degree 3 cannot carry a jerk Hessian.
    let quadratic = KnotVector::clamped_uniform(2, 8).unwrap();
    assert!(JerkFactor::new(&quadratic).is_err());
}

/// Table 2's q5 with a sine of amplitude `a` over u ∈ [0, 1] to follow (the tilt of a closed
/// saddle that starts where the tool axis passes the vertical): the knots, factor and the
/// corridor `a sin(2πu) ± w` at `m` interior points.
fn sine_corridor(a: f64, w: f64, m: usize) -> Vec<(f64, f64, f64)> {
    (1..m)
        .map(|i| {
            let u = i as f64 / m as f64;
            let c = a * (std::f64::consts::TAU * u).sin();
            (u, c - w, c + w)
        })
        .collect()
}

#[test]
fn corridor_rows_hold_at_their_points_and_zero_end_slopes_cost_jerk() {
    let knots = KnotVector::clamped_uniform(K, 40).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    let q5 = LaserMachine::default_machine().unwrap().limits()[4];
    let corridor = sine_corridor(0.4, 0.17, 100);
    let qp = RotaryQp {
        axis_name: "q5",
        knots: &knots,
        factor: &factor,
        limits: q5,
        sigma: 0.127,
        feedrate: 0.05,
        boundary: [0.0; 4],
        via: &[(0.0, 0.0), (1.0, 0.0)],
        via_box: &[],
        corridor: &corridor,
        free_end_slopes: false,
    };
    let peak_jerk = |theta: Vec<f64>, qp: &RotaryQp| {
        let spline = BSpline::new(knots.clone(), theta).unwrap();
        for &(u, lo, hi) in &corridor {
            let q = spline.eval(u)[0];
            assert!(
                q >= lo - 1e-7 && q <= hi + 1e-7,
                "q({u}) = {q} outside [{lo}, {hi}]"
            );
        }
        let d0 = spline.eval(0.0);
        let d1 = spline.eval(1.0);
        // q_uu(0) = q_uu(1) = 0 always (eq. 45); q_u only with fixed end slopes.
        assert!(d0[2].abs() < 1e-6 && d1[2].abs() < 1e-6, "{d0:?} {d1:?}");
        if !qp.free_end_slopes {
            assert!(d0[1].abs() < 1e-6 && d1[1].abs() < 1e-6, "{d0:?} {d1:?}");
        }
        let s = qp.feedrate / qp.sigma;
        (0..=4000)
            .map(|i| spline.eval(i as f64 / 4000.0)[3].abs() * s.powi(3))
            .fold(0.0, f64::max)
    };
    let fixed = peak_jerk(qp.solve().unwrap().0, &qp);
    let free_qp = RotaryQp {
        free_end_slopes: true,
        ..qp
    };
    let free = peak_jerk(free_qp.solve().unwrap().0, &free_qp);
    println!("peak q5 jerk at 3 m/min: zero end slopes {fixed:.1}, free {free:.1} rad/s³");
    assert!(free < 0.8 * fixed, "free end slopes {free} vs zero {fixed}");
    // At 10 m/min: infeasible with zero end slopes (try_solve says so without diagnosing),
    // feasible with free ones.
    let fast = RotaryQp {
        feedrate: 10.0 / 60.0,
        ..qp
    };
    assert!(fast.try_solve().unwrap().is_none());
    let fast_free = RotaryQp {
        free_end_slopes: true,
        ..fast
    };
    let theta = fast_free
        .try_solve()
        .unwrap()
        .expect("feasible with free end slopes");
    assert!(peak_jerk(theta, &fast_free) <= q5.jerk * (1.0 + 1e-6));
}

#[test]
fn a_corridor_that_cannot_be_followed_is_reported_as_the_allowance() {
    let knots = KnotVector::clamped_uniform(K, 16).unwrap();
    let factor = JerkFactor::new(&knots).unwrap();
    // q must be near 1 at u = 0.5 and near −1 just after: no spline of 16 coefficients does it.
    let corridor = [(0.5, 1.0, 1.1), (0.5001, -1.1, -1.0)];
    let qp = RotaryQp {
        corridor: &corridor,
        ..problem(&knots, &factor, loose(), SIGMA, FEED, &[])
    };
    assert!(qp.try_solve().unwrap().is_none());
    match qp.solve() {
        Err(PlanError::Infeasible { family, .. }) => {
            assert_eq!(family, ConstraintFamily::Allowance)
        }
        other => panic!("{other:?}"),
    }
    // An empty or non-finite interval is refused by name.
    for bad in [[(0.5, 1.0, 0.9)], [(0.5, f64::NAN, 1.0)]] {
        let qp = RotaryQp {
            corridor: &bad,
            ..problem(&knots, &factor, loose(), SIGMA, FEED, &[])
        };
        assert!(matches!(qp.solve(), Err(PlanError::InvalidRequest { .. })));
    }
}
