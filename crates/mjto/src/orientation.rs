//! Local path frames and the lead/tilt angles of a tool axis against the
//! nominal (requested) axis (seed 001 section 2.4, Figure 4; Table 1 limits
//! φ_max, ϕ_max).
//!
//! At every CL point `C_i` with nominal unit axis `n_i` the frame
//! `(t, n, b)` is built as:
//! * `n` - the nominal tool axis;
//! * `t` - the path tangent: the central difference `C_{i+1} - C_{i-1}`
//!   (one-sided `C_1 - C_0`, `C_{N-1} - C_{N-2}` at the ends), projected
//!   orthogonally to `n` and normalised;
//! * `b = n × t` - across the feed.
//!
//! `(t, b, n)` is right-handed. Angles of a tool axis `O`:
//! * lead angle `φ = atan2(O·t, O·n)`: rotation of `O` in the feed plane
//!   (t, n); positive when `O` leans toward the feed direction, i.e. the
//!   head runs ahead of the CL point (O points from C toward the head);
//! * tilt angle `ϕ = atan2(O·b, O·n)`: rotation across the feed, in the
//!   plane (b, n); positive when `O` leans toward `b`, to the left of the
//!   feed direction as seen from the head.
//!
//! Both are 0 for `O = n`; [`axis_from_lead_tilt`] is the inverse for
//! |φ|, |ϕ| < π/2.
//!
//! Degenerate tangent: when the projected tangent vanishes (the path runs
//! along the nominal axis at that point), the tangent of the nearest CL
//! point with a valid one is used (projected onto the plane ⊥ `n`); if
//! there is none, or it is parallel to `n` as well, any unit vector
//! perpendicular to `n` ([`any_perpendicular`]).

use nalgebra::Vector3;

use crate::request::AXIS_NORM_TOLERANCE;
use crate::PlanError;

/// Relative length below which a projected tangent counts as degenerate.
const DEGENERATE_TANGENT: f64 = 1e-9;

/// Angle below which two unit vectors are slerped as a normalised lerp.
const SLERP_SMALL_ANGLE: f64 = 1e-12;

/// The CL path with its nominal axes, arc-length parameters and local
/// frames at every CL point.
#[derive(Debug, Clone, PartialEq)]
pub struct PathFrames {
    points: Vec<Vector3<f64>>,
    axes: Vec<Vector3<f64>>,
    u: Vec<f64>,
    tangents: Vec<Vector3<f64>>,
}

impl PathFrames {
    /// Frames of a path whose arrays come from a validated request
    /// (`ValidatedRequest::{points, axes, u}`): equal lengths, at least
    /// two points, unit axes, strictly increasing `u`.
    ///
    /// Never panics: arrays of different lengths are cut to the shortest,
    /// non-zero axes are normalised. An empty path gives a `PathFrames`
    /// whose queries return NaN. Use [`PathFrames::try_new`] for inputs
    /// that were not validated.
    ///
    /// # Performance
    /// O(N) time and memory.
    pub fn new(points: &[Vector3<f64>], axes: &[Vector3<f64>], u: &[f64]) -> Self {
        let n = points.len().min(axes.len()).min(u.len());
        let points: Vec<Vector3<f64>> = points.iter().take(n).copied().collect();
        let axes: Vec<Vector3<f64>> = axes
            .iter()
            .take(n)
            .map(|a| a.try_normalize(0.0).unwrap_or(*a))
            .collect();
        let u: Vec<f64> = u.iter().take(n).copied().collect();
        let tangents = tangents(&points, &axes);
        Self {
            points,
            axes,
            u,
            tangents,
        }
    }

    /// [`PathFrames::new`] after checking its inputs.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (fields `points`, `axes`, `u`) for
    /// different lengths, fewer than two points, non-finite values,
    /// non-unit axes (beyond [`AXIS_NORM_TOLERANCE`]) or `u` not strictly
    /// increasing.
    pub fn try_new(
        points: &[Vector3<f64>],
        axes: &[Vector3<f64>],
        u: &[f64],
    ) -> Result<Self, PlanError> {
        if points.len() != axes.len() || points.len() != u.len() {
            return Err(PlanError::invalid(
                "points",
                format!(
                    "{} points, {} axes and {} parameters: the lengths must agree",
                    points.len(),
                    axes.len(),
                    u.len()
                ),
            ));
        }
        if points.len() < 2 {
            return Err(PlanError::invalid(
                "points",
                format!("{} point(s): at least 2 are required", points.len()),
            ));
        }
        for (i, (p, a)) in points.iter().zip(axes).enumerate() {
            if p.iter().any(|v| !v.is_finite()) {
                return Err(PlanError::invalid(format!("points[{i}]"), "is not finite"));
            }
            let norm = a.norm();
            if !norm.is_finite() || (norm - 1.0).abs() > AXIS_NORM_TOLERANCE {
                return Err(PlanError::invalid(
                    format!("axes[{i}]"),
                    format!("norm {norm} is not 1"),
                ));
            }
        }
        if u.iter().any(|v| !v.is_finite()) || u.windows(2).any(|w| w[1] <= w[0]) {
            return Err(PlanError::invalid(
                "u",
                "arc-length parameters must be finite and strictly increasing",
            ));
        }
        Ok(Self::new(points, axes, u))
    }

    /// Number of CL points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True for a path without points (only from [`PathFrames::new`] on
    /// empty input).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The CL points (m).
    pub fn points(&self) -> &[Vector3<f64>] {
        &self.points
    }

    /// The nominal unit tool axes.
    pub fn axes(&self) -> &[Vector3<f64>] {
        &self.axes
    }

    /// The normalised arc-length parameter of every CL point.
    pub fn u_values(&self) -> &[f64] {
        &self.u
    }

    /// Segment of `u`: the index `i` and the fraction in [0, 1] with
    /// `u = u_i + fraction (u_{i+1} - u_i)`.
    ///
    /// `u` outside `[u_0, u_{N-1}]` is clamped (`(0, 0)` or
    /// `(N-2, 1)`); a single point gives `(0, 0)`. A NaN `u` (or an empty
    /// path) gives a NaN fraction, which makes every interpolated query
    /// NaN: it is never hidden.
    ///
    /// # Performance
    /// O(log N) (binary search).
    pub fn locate(&self, u: f64) -> (usize, f64) {
        let n = self.u.len();
        if u.is_nan() || n == 0 {
            return (0, f64::NAN);
        }
        if n == 1 {
            return (0, 0.0);
        }
        let first = self.u.first().copied().unwrap_or(0.0);
        let last = self.u.last().copied().unwrap_or(1.0);
        if u <= first {
            return (0, 0.0);
        }
        if u >= last {
            return (n - 2, 1.0);
        }
        let i = self
            .u
            .partition_point(|&x| x <= u)
            .saturating_sub(1)
            .min(n - 2);
        let (a, b) = (self.u[i], self.u[i + 1]);
        let f = if b > a { (u - a) / (b - a) } else { 0.0 };
        (i, f.clamp(0.0, 1.0))
    }

    /// Index of the CL point whose parameter is nearest to `u` (0 for a
    /// NaN `u` or an empty path).
    pub fn nearest_index(&self, u: f64) -> usize {
        let (i, f) = self.locate(u);
        if f > 0.5 {
            (i + 1).min(self.len().saturating_sub(1))
        } else {
            i
        }
    }

    /// The reference CL path at `u`: the polyline through the CL points
    /// (the G-code segments), linear in `u` on each segment (m).
    pub fn cl_point(&self, u: f64) -> Vector3<f64> {
        let (i, f) = self.locate(u);
        match (self.points.get(i), self.points.get(i + 1)) {
            _ if f.is_nan() => Vector3::repeat(f64::NAN),
            (Some(a), Some(b)) => a + f * (b - a),
            (Some(a), None) => *a,
            (None, _) => Vector3::repeat(f64::NAN),
        }
    }

    /// The nominal tool axis at `u`: great-circle interpolation
    /// ([`slerp_unit`]) between the nominal axes of the neighbouring CL
    /// points.
    pub fn nominal_axis(&self, u: f64) -> Vector3<f64> {
        let (i, f) = self.locate(u);
        match (self.axes.get(i), self.axes.get(i + 1)) {
            _ if f.is_nan() => Vector3::repeat(f64::NAN),
            (Some(a), Some(b)) => slerp_unit(a, b, f),
            (Some(a), None) => *a,
            (None, _) => Vector3::repeat(f64::NAN),
        }
    }

    /// The frame `(t, n, b)` at CL point `i` (clamped to the last point;
    /// NaN for an empty path).
    pub fn frame_at(&self, i: usize) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let i = i.min(self.len().saturating_sub(1));
        match (self.tangents.get(i), self.axes.get(i)) {
            (Some(t), Some(n)) => (*t, *n, n.cross(t)),
            _ => {
                let nan = Vector3::repeat(f64::NAN);
                (nan, nan, nan)
            }
        }
    }

    /// The frame `(t, n, b)` at `u`: `n` from [`PathFrames::nominal_axis`],
    /// `t` the linear blend of the neighbouring tangents re-projected
    /// orthogonally to `n` and normalised (falling back to the nearer
    /// point's tangent, then [`any_perpendicular`], if that vanishes),
    /// `b = n × t`.
    pub fn frame(&self, u: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let (i, f) = self.locate(u);
        let n = self.nominal_axis(u);
        let (Some(ta), Some(tb)) = (
            self.tangents.get(i),
            self.tangents.get(i + 1).or(self.tangents.get(i)),
        ) else {
            let nan = Vector3::repeat(f64::NAN);
            return (nan, nan, nan);
        };
        if f.is_nan() || n.iter().any(|v| v.is_nan()) {
            let nan = Vector3::repeat(f64::NAN);
            return (nan, nan, nan);
        }
        let (near, far) = if f <= 0.5 { (ta, tb) } else { (tb, ta) };
        let t = [ta + f * (tb - ta), *near, *far]
            .iter()
            .find_map(|c| project_normalize(c, &n))
            .unwrap_or_else(|| any_perpendicular(&n));
        (t, n, n.cross(&t))
    }

    /// Lead and tilt angles `(φ, ϕ)` (rad) of the tool axis `o` in the
    /// frame at `u` ([`PathFrames::frame`]); see the module documentation
    /// for the convention.
    pub fn lead_tilt(&self, u: f64, o: &Vector3<f64>) -> (f64, f64) {
        let (t, n, b) = self.frame(u);
        angles(&t, &n, &b, o)
    }

    /// Lead and tilt angles `(φ, ϕ)` (rad) of `o` in the frame of CL point
    /// `i` ([`PathFrames::frame_at`]).
    pub fn lead_tilt_at(&self, i: usize, o: &Vector3<f64>) -> (f64, f64) {
        let (t, n, b) = self.frame_at(i);
        angles(&t, &n, &b, o)
    }
}

/// `(atan2(O·t, O·n), atan2(O·b, O·n))`.
fn angles(t: &Vector3<f64>, n: &Vector3<f64>, b: &Vector3<f64>, o: &Vector3<f64>) -> (f64, f64) {
    let on = o.dot(n);
    (o.dot(t).atan2(on), o.dot(b).atan2(on))
}

/// `v` projected onto the plane ⊥ unit `n` and normalised, or `None` when
/// the projection is shorter than [`DEGENERATE_TANGENT`] times |v| (or v
/// is zero or not finite).
fn project_normalize(v: &Vector3<f64>, n: &Vector3<f64>) -> Option<Vector3<f64>> {
    let len = v.norm();
    if !(len.is_finite() && len > 0.0) {
        return None;
    }
    let p = v - v.dot(n) * n;
    let pl = p.norm();
    if pl > DEGENERATE_TANGENT * len {
        Some(p / pl)
    } else {
        None
    }
}

/// Unit tangents ⊥ the nominal axes at every CL point (module docs).
fn tangents(points: &[Vector3<f64>], axes: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let n = points.len();
    let raw: Vec<Option<Vector3<f64>>> = (0..n)
        .map(|i| {
            let a = points.get(i.saturating_sub(1))?;
            let b = points.get((i + 1).min(n - 1))?;
            project_normalize(&(b - a), axes.get(i)?)
        })
        .collect();
    // Nearest valid neighbour for degenerate points: previous first.
    let mut prev = vec![None; n];
    let mut last = None;
    for i in 0..n {
        if raw[i].is_some() {
            last = Some(i);
        }
        prev[i] = last;
    }
    let mut next = vec![None; n];
    let mut last = None;
    for i in (0..n).rev() {
        if raw[i].is_some() {
            last = Some(i);
        }
        next[i] = last;
    }
    (0..n)
        .map(|i| {
            if let Some(t) = raw[i] {
                return t;
            }
            let axis = axes[i];
            let neighbour = match (prev[i], next[i]) {
                (Some(p), Some(q)) => Some(if i - p <= q - i { p } else { q }),
                (p, q) => p.or(q),
            };
            neighbour
                .and_then(|j| raw[j])
                .and_then(|t| project_normalize(&t, &axis))
                .unwrap_or_else(|| any_perpendicular(&axis))
        })
        .collect()
}

/// A unit vector perpendicular to the unit vector `n`: `n` crossed with
/// the coordinate axis least aligned with it, normalised.
pub fn any_perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let (ax, ay, az) = (n.x.abs(), n.y.abs(), n.z.abs());
    let e = if ax <= ay && ax <= az {
        Vector3::x()
    } else if ay <= az {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let p = n.cross(&e);
    let l = p.norm();
    if l > 0.0 {
        p / l
    } else {
        Vector3::repeat(f64::NAN)
    }
}

/// Great-circle (spherical linear) interpolation between unit vectors
/// `a` and `b`: `(sin((1-s)θ) a + sin(sθ) b) / sin θ` with
/// `θ = ∠(a, b)`; the rotation of `a` about `a × b` by `sθ`. This is the
/// quaternion interpolation of a tool axis of ref. \[3\] of seed 001 (Ho et
/// al.): the slerp of the minimal rotation taking `a` to `b`, applied to
/// `a`.
///
/// For θ below 1e-12 the normalised linear blend is returned; for
/// antipodal vectors (θ = π, the great circle is not unique) the rotation
/// is about [`any_perpendicular`]`(a)`.
///
/// # Arguments
/// * `a`, `b` - unit vectors.
/// * `s` - fraction, 0 gives `a`, 1 gives `b`.
pub fn slerp_unit(a: &Vector3<f64>, b: &Vector3<f64>, s: f64) -> Vector3<f64> {
    let cross = a.cross(b);
    let sin = cross.norm();
    let cos = a.dot(b);
    let theta = sin.atan2(cos);
    if sin < SLERP_SMALL_ANGLE {
        if cos > 0.0 {
            let v = a + s * (b - a);
            return v.try_normalize(0.0).unwrap_or(v);
        }
        // Antipodal: rotate a by sπ about a perpendicular axis k:
        // a cos + (k × a) sin.
        let k = any_perpendicular(a);
        let ang = s * theta;
        return a * ang.cos() + k.cross(a) * ang.sin();
    }
    let v = a * (((1.0 - s) * theta).sin() / sin) + b * ((s * theta).sin() / sin);
    v.try_normalize(0.0).unwrap_or(v)
}

/// The unit tool axis with lead `φ` and tilt `ϕ` in the frame `(t, n, b)`:
/// the inverse of [`PathFrames::lead_tilt`],
/// `O ∝ cos φ cos ϕ n + sin φ cos ϕ t + cos φ sin ϕ b`
/// (so `O·t / O·n = tan φ`, `O·b / O·n = tan ϕ`).
///
/// # Arguments
/// * `t`, `n`, `b` - an orthonormal frame as returned by
///   [`PathFrames::frame`].
/// * `lead`, `tilt` - angles (rad); exact inverse for |φ|, |ϕ| < π/2
///   (every orientation with `O·n > 0`).
pub fn axis_from_lead_tilt(
    t: &Vector3<f64>,
    n: &Vector3<f64>,
    b: &Vector3<f64>,
    lead: f64,
    tilt: f64,
) -> Vector3<f64> {
    let (sl, cl) = lead.sin_cos();
    let (st, ct) = tilt.sin_cos();
    let v = n * (cl * ct) + t * (sl * ct) + b * (cl * st);
    v.try_normalize(0.0).unwrap_or(v)
}
