//! The velocity-limit curve a near time-optimal feed plan tracks
//! ([`crate::feed_optimal`]): one limit over each interval between two
//! nodes, valid at every arc length of the interval, not only at its ends.
//!
//! **Nodes.** The samples, plus two nodes on every straight interval longer
//! than 2w, w = F T (the longest step of one interpolation period), at w
//! from its ends: [`crate::sample_path`] samples a line at its ends only, and
//! the chord-error window below must not carry a corner's curvature along a
//! whole line.
//!
//! **The limit over interval k** is the least of
//! * F and the programmed feeds of its two ends;
//! * seed 003 eqs. 17, 19 and 21 (contour error, normal acceleration and
//!   jerk laws of [`crate::CurvatureLimits::speed`]) at κ̂, a bound of the
//!   curvature over the interval: the larger curvature of its ends plus half
//!   the largest change between two neighbouring nodes of the same piece
//!   (k − 1 .. k + 2), the whole change where the interval holds the largest
//!   of those nodes (a peak between two samples exceeds both: on a corner of
//!   five 10 µm steps the peak was 36 % above the samples on both sides of
//!   it), and at least the mean curvature of the interval (its tangent's
//!   turning angle over its length); about 0 on a straight interval. Where
//!   the samples hold every extremum of the curvature
//!   ([`crate::sample_path_adaptive`], [`PathSample::monotone`]), the
//!   curvature is monotone over the interval and κ̂ is the larger of its
//!   ends times 1 + [`MONOTONE_SLACK`] (and at least the mean);
//! * seed 003 eq. 16 (chord error) at the largest curvature within w of the
//!   interval: a step of one period that reaches the interval is at most w
//!   long, so its own speed bound covers its whole chord (eq. 15 with the
//!   step's arc length, which is at least its chord);
//! * the per-axis bound [`crate::AxisLimits::speed`] with |x′| the largest
//!   tangent component at the ends plus κ̂ Δs / 2 (the tangent turns at rate
//!   κ), |x″| ≤ κ̂ on every axis and |x‴| the largest second difference of
//!   the tangents over nodes k − 1 .. k + 2, times 1.5; on a monotone
//!   interval of adaptive samples |x‴| ≤ |κ′| + κ̂² (x‴ = κ′ n − κ² t,
//!   Frenet–Serret on a planar corner), |κ′| the larger of its ends'
//!   [`PathSample::curvature_slope`] (every maximum of |κ′| is sampled)
//!   times 1 + [`SLOPE_SLACK`].
//!
//! * with [`FeedConstraints::whole_normal_jerk`], the whole jerk of the
//!   normal acceleration vector at constant speed, v³ √(κ′² + κ̂⁴) ≤ J_n
//!   (Frenet–Serret, [`crate::corner_jerk`]; seed 003's eq. 21 is its κ⁴
//!   term alone), with |κ′| the largest difference quotient of the node
//!   curvatures over nodes k − 1 .. k + 2 of the same piece, times 1.5 (as
//!   |x‴| above: an estimate from the samples, not a bound).
//!
//! The limit of a node is the lower of its two intervals'.

use crate::adaptive::{MONOTONE_SLACK, SLOPE_SLACK};
use crate::constraints::FeedConstraints;
use crate::samples::PathSample;
use crate::speed_limit::CurvatureLimits;
use crate::vec3::{dot, norm, sub};

/// Safety factor on the finite-difference estimate of |x‴|.
const THIRD_DERIVATIVE_FACTOR: f64 = 1.5;

/// The velocity-limit curve on its nodes (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct LimitCurve {
    /// Arc length of every node \[m\].
    pub s: Vec<f64>,
    /// The limit at every node \[m/s\] (the lower of its intervals').
    pub node: Vec<f64>,
    /// The limit over every interval between two nodes \[m/s\].
    pub interval: Vec<f64>,
}

/// One node: arc length, curvature, tangent and programmed feed.
#[derive(Debug, Clone, Copy)]
struct Node {
    s: f64,
    kappa: f64,
    tangent: [f64; 3],
    cap: f64,
    /// The piece of the interval from this node to the next.
    piece: usize,
    /// The curvature is monotone from this node to the next
    /// ([`PathSample::monotone`]).
    monotone: bool,
    /// |dκ/ds| at the node ([`PathSample::curvature_slope`]).
    slope: f64,
}

/// The velocity-limit curve of `samples` under `constraints` (module
/// documentation). `constraints` must be valid for `samples`
/// ([`FeedConstraints::validate`]).
pub fn limit_curve(samples: &[PathSample], constraints: &FeedConstraints<'_>) -> LimitCurve {
    let lim = &constraints.limits.curvature;
    let w = lim.feed * lim.interpolation_period;
    let cap_of = |k: usize| constraints.caps.map_or(f64::INFINITY, |c| c[k]);
    let mut nodes: Vec<Node> = Vec::with_capacity(samples.len() + 16);
    for (i, p) in samples.iter().enumerate() {
        let next = samples.get(i + 1);
        let piece = next.map_or(p.piece, |q| q.piece);
        nodes.push(Node {
            s: p.s,
            kappa: p.curvature,
            tangent: p.tangent,
            cap: cap_of(i),
            piece,
            monotone: p.monotone,
            slope: p.curvature_slope,
        });
        // A line: the only interval of its piece (a piece's samples after its
        // first belong to it; the path's first sample to the first piece),
        // its tangent unchanged.
        if let Some(q) = next {
            let only = (i == 0 || p.piece != q.piece)
                && samples.get(i + 2).is_none_or(|r| r.piece != q.piece);
            let line = only && dot(p.tangent, q.tangent) >= 1.0 - 1e-12;
            if line && q.s - p.s > 2.0 * w * (1.0 + 1e-9) {
                let cap = constraints.cap_between(i);
                for s in [p.s + w, q.s - w] {
                    nodes.push(Node {
                        s,
                        kappa: 0.0,
                        tangent: p.tangent,
                        cap,
                        piece,
                        monotone: true,
                        slope: 0.0,
                    });
                }
            }
        }
    }
    let n = nodes.len();
    let third = if constraints.axes.is_some() {
        third_derivatives(&nodes)
    } else {
        Vec::new()
    };
    let chord_kappa = window_max(&nodes, w);
    let critical = lim.contour_critical_radius();
    let free = feed_curvature(lim, critical);
    let (a_eff, j_eff) = constraints.tangential();
    let mut interval = Vec::with_capacity(n - 1);
    for k in 0..n - 1 {
        let (p, q) = (&nodes[k], &nodes[k + 1]);
        let ds = q.s - p.s;
        // Intervals k − 1 ..= k + 1 of the same piece as interval k.
        let lo = if k > 0 && nodes[k - 1].piece == p.piece {
            k - 1
        } else {
            k
        };
        let hi = if k + 2 < n && nodes[k + 1].piece == p.piece {
            k + 1
        } else {
            k
        };
        let change = (lo..=hi)
            .map(|r| (nodes[r + 1].kappa - nodes[r].kappa).abs())
            .fold(0.0, f64::max);
        // The chord of the tangents' turn, 2 sin(θ/2) ≤ θ: a lower bound of
        // the mean curvature times ds.
        let turn = norm(sub(q.tangent, p.tangent));
        // Near a peak of the sampled curvature (the interval holds the
        // largest of its four nodes) the curve's own peak may lie between
        // two samples: there the full change, else half of it.
        let ends = p.kappa.max(q.kappa);
        let outer = nodes[lo].kappa.max(nodes[hi + 1].kappa);
        let slack = if p.monotone {
            MONOTONE_SLACK * ends
        } else if ends >= outer && change > 0.5 * ends {
            change
        } else {
            0.5 * change
        };
        let kappa = (ends + slack).max(turn / ds);
        // The least curvature over the interval, for the contour law, which
        // rises with κ above 1/ρ* (CurvatureLimits::contour_critical_radius).
        let kappa_lo = (p.kappa.min(q.kappa) - slack).max(0.0);
        let mut v = lim.feed.min(p.cap).min(q.cap);
        if kappa > free {
            v = v.min(curvature_speed(lim, kappa_lo, kappa, v, critical));
        }
        if constraints.whole_normal_jerk {
            // |κ′| over the interval: the samples' slopes where every maximum
            // of |κ′| is sampled (adaptive samples), else the largest
            // difference quotient of the neighbouring intervals times 1.5.
            let rate = if p.monotone {
                p.slope.max(q.slope) * (1.0 + SLOPE_SLACK)
            } else {
                THIRD_DERIVATIVE_FACTOR
                    * (lo..=hi)
                        .map(|r| {
                            (nodes[r + 1].kappa - nodes[r].kappa).abs()
                                / (nodes[r + 1].s - nodes[r].s)
                        })
                        .fold(0.0, f64::max)
            };
            v = v.min(rate_jerk_speed(lim.normal_jerk, kappa, rate));
        }
        let kc = chord_kappa[k].max(kappa);
        if kc > free {
            v = v.min(lim.chord_speed(1.0 / kc));
        }
        if let Some(axes) = &constraints.axes {
            let d1: [f64; 3] = std::array::from_fn(|a| {
                (p.tangent[a].abs().max(q.tangent[a].abs()) + 0.5 * kappa * ds).min(1.0)
            });
            let mut d3 = [0.0f64; 3];
            if p.monotone {
                // x‴ = κ′ n − κ² t on a planar corner (Frenet–Serret), so every
                // axis's |x‴| ≤ |κ′| + κ², |κ′| bounded by its sampled maxima.
                let bound = p.slope.max(q.slope) * (1.0 + SLOPE_SLACK) + kappa * kappa;
                d3 = [bound; 3];
            } else {
                for t in &third[lo..=hi + 1] {
                    for a in 0..3 {
                        d3[a] = d3[a].max(THIRD_DERIVATIVE_FACTOR * t[a]);
                    }
                }
            }
            v = v.min(axes.speed(d1, [kappa; 3], d3, a_eff, j_eff));
        }
        interval.push(v);
    }
    let node = (0..n)
        .map(|k| {
            let left = if k > 0 {
                interval[k - 1]
            } else {
                f64::INFINITY
            };
            left.min(*interval.get(k).unwrap_or(&f64::INFINITY))
        })
        .collect();
    LimitCurve {
        s: nodes.iter().map(|p| p.s).collect(),
        node,
        interval,
    }
}

/// For every interval k, the largest curvature of the nodes within `w` of
/// it (arc length in [s_k − w, s_{k+1} + w]), by a monotone deque.
fn window_max(nodes: &[Node], w: f64) -> Vec<f64> {
    let n = nodes.len();
    let mut out = Vec::with_capacity(n - 1);
    let mut deque: std::collections::VecDeque<usize> = std::collections::VecDeque::new();
    let mut next = 0usize;
    for k in 0..n - 1 {
        let (lo, hi) = (nodes[k].s - w, nodes[k + 1].s + w);
        while next < n && nodes[next].s <= hi {
            while deque
                .back()
                .is_some_and(|&b| nodes[b].kappa <= nodes[next].kappa)
            {
                deque.pop_back();
            }
            deque.push_back(next);
            next += 1;
        }
        while deque.front().is_some_and(|&f| nodes[f].s < lo) {
            deque.pop_front();
        }
        out.push(deque.front().map_or(0.0, |&f| nodes[f].kappa));
    }
    out
}

/// The largest curvature below which no curvature limit is below the feed,
/// by bisection on log κ, rounded down: below it the limit is F without
/// evaluating them. The laws of eqs. 19 and 21 fall with κ; eq. 17 falls up
/// to 1/ρ* and rises beyond ([`CurvatureLimits::contour_critical_radius`]),
/// so the bisection runs on the least speed over [0, κ], which falls with κ.
fn feed_curvature(lim: &CurvatureLimits, critical: Option<f64>) -> f64 {
    let below = |kappa: f64| {
        curvature_speed(lim, 0.0, kappa, f64::INFINITY, critical) >= lim.feed
            && lim.chord_speed(1.0 / kappa) >= lim.feed
    };
    let (mut lo, mut hi) = (1e-12f64, 1e12f64);
    if !below(lo) {
        return 0.0;
    }
    for _ in 0..100 {
        let mid = (lo * hi).sqrt();
        if below(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo * (1.0 - 1e-9)
}

/// min(`v`, eqs. 19 and 21 at `kappa`, eq. 17 at its least over
/// [`kappa_lo`, `kappa`]) as [`CurvatureLimits::speed`] without its chord
/// term (the chord is bounded separately), the cube root only where it is
/// below `v` (ρ² j_n < v³).
fn curvature_speed(
    lim: &CurvatureLimits,
    kappa_lo: f64,
    kappa: f64,
    v: f64,
    critical: Option<f64>,
) -> f64 {
    let rho = 1.0 / kappa;
    let mut v = v.min((rho * lim.normal_acceleration).sqrt());
    let jerk = rho * rho * lim.normal_jerk;
    if jerk < v * v * v {
        v = jerk.cbrt();
    }
    v.min(lim.contour_speed_over(kappa_lo, kappa, critical))
}

/// The speed at which the normal acceleration vector's whole jerk at
/// constant speed, v³ √(κ′² + κ⁴), equals `normal_jerk` (infinite on a
/// straight interval).
pub fn rate_jerk_speed(normal_jerk: f64, kappa: f64, rate: f64) -> f64 {
    let g = (rate * rate + kappa.powi(4)).sqrt();
    if g > 0.0 {
        (normal_jerk / g).cbrt()
    } else {
        f64::INFINITY
    }
}

/// |x‴| at every node, per axis, from the tangents: m_k = Δt/Δs ≈ κ n over
/// interval k, and |m_k − m_{k−1}| over the mean spacing at node k (0 at the
/// ends).
fn third_derivatives(nodes: &[Node]) -> Vec<[f64; 3]> {
    let n = nodes.len();
    let m: Vec<[f64; 3]> = nodes
        .windows(2)
        .map(|w| {
            let ds = w[1].s - w[0].s;
            std::array::from_fn(|a| (w[1].tangent[a] - w[0].tangent[a]) / ds)
        })
        .collect();
    let mut third = vec![[0.0f64; 3]; n];
    for k in 1..n - 1 {
        let h = 0.5 * (nodes[k + 1].s - nodes[k - 1].s);
        third[k] = std::array::from_fn(|a| (m[k][a] - m[k - 1][a]).abs() / h);
    }
    third
}
