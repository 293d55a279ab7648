//! The time-optimal feed law (issue 16, item 1) on synthetic joint paths: the process limits
//! alone give the S-curve's time, a joint that needs it slows the feed where it binds and is
//! named, the law evaluated at controller samples is consistent (s, ṡ, s̈, s⃛ agree with finite
//! differences and keep every limit), and malformed problems are refused.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mjto::error::ConstraintFamily;
use kerf_mjto::machine::AxisLimits;
use kerf_mjto::optimal_feed::{steady_feed, FeedProblem, OptimalFeed};
use kerf_mjto::timelaw::TimeLaw;
use kerf_mjto::PlanError;

const FEED: f64 = 0.5;
const ACC: f64 = 8.0;
const JERK: f64 = 80.0;

fn wide() -> AxisLimits {
    AxisLimits {
        min: -10.0,
        max: 10.0,
        vel: 100.0,
        acc: 1e4,
        jerk: 1e6,
    }
}

/// Stations over [0, σ] and the derivatives of a path where q1 = s and q5 = `bump(s)`.
fn path(sigma: f64, n: usize, bump: &dyn Fn(f64) -> [f64; 4]) -> (Vec<f64>, Vec<[[f64; 6]; 4]>) {
    let stations: Vec<f64> = (0..=n).map(|k| sigma * k as f64 / n as f64).collect();
    let derivatives = stations
        .iter()
        .map(|&s| {
            let mut d = [[0.0; 6]; 4];
            d[0][0] = s;
            d[1][0] = 1.0;
            let b = bump(s);
            for (order, row) in d.iter_mut().enumerate() {
                row[4] = b[order];
            }
            d
        })
        .collect();
    (stations, derivatives)
}

fn problem<'a>(
    stations: &'a [f64],
    derivatives: &'a [[[f64; 6]; 4]],
    joints: &'a [AxisLimits; 6],
) -> FeedProblem<'a> {
    FeedProblem {
        stations,
        derivatives,
        joints,
        feed: FEED,
        acc: ACC,
        jerk: JERK,
        margin: 1.0,
        process_margin: 1.0,
        tip: &[],
    }
}

/// Samples every `dt` and at T, with `[s, ṡ, s̈, s⃛]`.
fn sampled(law: &OptimalFeed, dt: f64) -> (Vec<f64>, Vec<[f64; 4]>) {
    let total = law.duration();
    let mut times: Vec<f64> = (0..)
        .map(|i| i as f64 * dt)
        .take_while(|&t| t < total - 1e-9)
        .collect();
    times.push(total);
    let states = law.eval_many(&times).unwrap();
    (times, states)
}

/// The law at `dt` samples keeps the process limits (relative `tol`), moves forward from rest
/// to rest over [0, σ], and its derivatives agree with central differences of its positions.
fn check_consistent(law: &OptimalFeed, sigma: f64, tol: f64) {
    let dt = 1e-3;
    let (times, states) = sampled(law, dt);
    let n = times.len();
    assert_eq!(states[0][0], 0.0);
    assert!(
        (states[n - 1][0] - sigma).abs() < 1e-9,
        "{:?}",
        states[n - 1]
    );
    assert!(states[0][1].abs() < 1e-9 && states[n - 1][1].abs() < 1e-6);
    for (k, s) in states.iter().enumerate() {
        assert!(
            s[1] >= 0.0 && s[1] <= FEED * (1.0 + tol),
            "ṡ {} at {k}",
            s[1]
        );
        assert!(s[2].abs() <= ACC * (1.0 + tol), "s̈ {} at {k}", s[2]);
        assert!(s[3].abs() <= JERK * (1.0 + tol), "s⃛ {} at {k}", s[3]);
        if k > 0 {
            assert!(s[0] >= states[k - 1][0], "s decreases at {k}");
        }
    }
    // Central differences over interior samples of the uniform grid.
    for k in 1..n - 2 {
        let (a, b, c) = (&states[k - 1], &states[k], &states[k + 1]);
        let v = (c[0] - a[0]) / (2.0 * dt);
        assert!(
            (v - b[1]).abs() <= 0.5 * ACC * dt + 1e-9,
            "ṡ {} vs difference {v} at t = {}",
            b[1],
            times[k]
        );
        let acc = (c[1] - a[1]) / (2.0 * dt);
        assert!(
            (acc - b[2]).abs() <= JERK * dt + 1e-6,
            "s̈ {} vs difference {acc} at t = {}",
            b[2],
            times[k]
        );
    }
}

#[test]
fn process_limits_alone_give_the_s_curve_time() {
    let sigma = 0.5;
    let joints = [wide(); 6];
    let (stations, derivatives) = path(sigma, 200, &|_| [0.0; 4]);
    let law = OptimalFeed::solve(&problem(&stations, &derivatives, &joints)).unwrap();
    let s_curve = TimeLaw::new(sigma, FEED, ACC, JERK).unwrap().duration();
    println!(
        "process limits only: {:.5} s, S-curve {s_curve:.5} s",
        law.duration()
    );
    // The S-curve is the fastest law under the process limits alone; the discretized law
    // (constant s⃛/ṡ per interval, linearized jerk rows) is slower by little.
    assert!(
        law.duration() >= s_curve * (1.0 - 1e-6),
        "{} < {s_curve}",
        law.duration()
    );
    assert!(
        law.duration() <= s_curve * 1.02,
        "{} vs {s_curve}",
        law.duration()
    );
    assert!(
        (law.peak_feed() - FEED).abs() < 1e-3 * FEED,
        "{}",
        law.peak_feed()
    );
    check_consistent(&law, sigma, 1e-3);
    let p = problem(&stations, &derivatives, &joints);
    let by: Vec<String> = law.limits(&p).into_iter().map(|l| l.limited_by).collect();
    assert!(by.contains(&"feedrate".to_string()), "{by:?}");
    assert!(by.iter().all(|b| !b.starts_with('q')), "{by:?}");
}

#[test]
fn a_joint_slows_the_feed_where_it_binds_and_is_named() {
    let sigma = 0.6;
    // q5 swings by 0.3 rad over ±20 mm around the middle: q5'' up to ~750 rad/m², so its
    // acceleration limit alone holds the feed to ~√(80/750) ≈ 0.33 m/s there.
    let (h, w, mid) = (0.3, 0.02, sigma / 2.0);
    let bump = move |s: f64| {
        let x = (s - mid) / w;
        let g = (-x * x).exp();
        [
            h * g,
            h * g * (-2.0 * x) / w,
            h * g * (4.0 * x * x - 2.0) / (w * w),
            h * g * (-8.0 * x * x * x + 12.0 * x) / (w * w * w),
        ]
    };
    let mut joints = [wide(); 6];
    joints[4] = AxisLimits {
        min: -1.6,
        max: 1.6,
        vel: 10.0,
        acc: 80.0,
        jerk: 200.0,
    };
    let (stations, derivatives) = path(sigma, 300, &bump);
    let p = problem(&stations, &derivatives, &joints);
    let law = OptimalFeed::solve(&p).unwrap();
    check_consistent(&law, sigma, 1e-3);
    let s_curve = TimeLaw::new(sigma, FEED, ACC, JERK).unwrap().duration();
    assert!(
        law.duration() > s_curve * 1.02,
        "{} vs {s_curve}",
        law.duration()
    );
    // Slower at the bump than the feedrate, the feedrate reached away from it.
    let (times, states) = sampled(&law, 1e-3);
    let at_bump = states
        .iter()
        .filter(|s| (s[0] - mid).abs() < 0.25 * w)
        .map(|s| s[1])
        .fold(0.0f64, f64::max);
    println!(
        "q5 bump: {:.5} s (S-curve {s_curve:.5} s), {at_bump:.4} m/s at the bump",
        law.duration()
    );
    assert!(at_bump < 0.8 * FEED, "{at_bump} m/s at the bump");
    assert!(law.peak_feed() > 0.99 * FEED);
    // q5 at the samples, by the chain rule (seed 001 eq. 7), within its limits.
    for (t, s) in times.iter().zip(&states) {
        let d = bump(s[0]);
        let (v, a, j) = (s[1], s[2], s[3]);
        let q5 = [
            d[1] * v,
            d[2] * v * v + d[1] * a,
            d[3] * v * v * v + 3.0 * d[2] * v * a + d[1] * j,
        ];
        let l = &joints[4];
        for (x, lim, what) in [
            (q5[0], l.vel, "velocity"),
            (q5[1], l.acc, "acceleration"),
            (q5[2], l.jerk, "jerk"),
        ] {
            assert!(x.abs() <= lim * 1.02, "q5 {what} {x} at t = {t}");
        }
    }
    let limits = law.limits(&p);
    let near: Vec<&str> = limits
        .iter()
        .filter(|l| l.s_end >= mid - 2.0 * w && l.s_start <= mid + 2.0 * w)
        .map(|l| l.limited_by.as_str())
        .collect();
    assert!(near.iter().any(|b| b.starts_with("q5")), "{limits:?}");
}

#[test]
fn steady_feed_is_the_slowest_of_the_three_orders() {
    let mut joints = [wide(); 6];
    joints[1] = AxisLimits {
        min: -1.0,
        max: 1.0,
        vel: 2.0,
        acc: 12.0,
        jerk: 120.0,
    };
    let mut d = [[0.0; 6]; 4];
    // q2' = 0.5: velocity allows 4 m/s; q2'' = 3: acceleration allows 2 m/s; q2''' = 1000:
    // jerk allows 120^(1/3)/10 ≈ 0.493 m/s.
    d[1][1] = 0.5;
    d[2][1] = 3.0;
    d[3][1] = 1000.0;
    let (v, by) = steady_feed(&d, &joints);
    assert!((v - 0.12f64.cbrt()).abs() < 1e-12, "{v}");
    assert_eq!(by, Some((1, ConstraintFamily::Jerk)));
    d[3][1] = 0.0;
    let (v, by) = steady_feed(&d, &joints);
    assert!((v - 2.0).abs() < 1e-12, "{v}");
    assert_eq!(by, Some((1, ConstraintFamily::Acceleration)));
    let (v, by) = steady_feed(&[[0.0; 6]; 4], &joints);
    assert_eq!((v, by), (f64::INFINITY, None));
}

#[test]
fn malformed_problems_are_refused_by_name() {
    let joints = [wide(); 6];
    let (stations, derivatives) = path(0.5, 20, &|_| [0.0; 4]);
    let field = |p: FeedProblem| match OptimalFeed::solve(&p) {
        Err(PlanError::InvalidRequest { field, .. }) => field,
        other => panic!("expected InvalidRequest, got {other:?}"),
    };
    let base = problem(&stations, &derivatives, &joints);
    assert_eq!(
        field(FeedProblem {
            stations: &stations[..5],
            derivatives: &derivatives[..5],
            ..base
        }),
        "feed stations"
    );
    assert_eq!(
        field(FeedProblem {
            derivatives: &derivatives[1..],
            ..base
        }),
        "feed stations"
    );
    let mut reversed = stations.clone();
    reversed.swap(3, 4);
    assert_eq!(
        field(FeedProblem {
            stations: &reversed,
            ..base
        }),
        "feed stations"
    );
    let mut nan = derivatives.clone();
    nan[7][2][4] = f64::NAN;
    assert_eq!(
        field(FeedProblem {
            derivatives: &nan,
            ..base
        }),
        "feed stations"
    );
    assert_eq!(field(FeedProblem { feed: 0.0, ..base }), "feedrate");
    assert_eq!(
        field(FeedProblem {
            acc: f64::INFINITY,
            ..base
        }),
        "feed_acceleration"
    );
    assert_eq!(field(FeedProblem { jerk: -1.0, ..base }), "feed_jerk");
    assert_eq!(
        field(FeedProblem {
            margin: 0.0,
            ..base
        }),
        "feed margin"
    );
    assert_eq!(
        field(FeedProblem {
            process_margin: 1.5,
            ..base
        }),
        "feed margin"
    );
    // Outside the law: an error, not a panic.
    let law = OptimalFeed::solve(&base).unwrap();
    assert!(law.eval_many(&[0.0, law.duration() + 1.0]).is_err());
}
