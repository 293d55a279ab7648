//! The planar milling path: a cubic B-spline interpolating coplanar points,
//! split into segments of equal arc length, with the tool axis normal to the
//! plane and the cutting frame of each segment.
//!
//! # Curve (seed 004 section 4: "a cubic B-spline curve interpolating four
//! coplanar control points")
//!
//! With n points, the degree is k = min(3, n − 1) (2 points: a straight
//! line), the parameters are chord-length `u_i = Σ_{l≤i} |p_l − p_{l−1}| / Σ |…|`
//! (Piegl & Tiller, *The NURBS Book*, eq. 9.5), the knots are de Boor's
//! averages of them ([`KnotVector::for_parameters`], eq. 9.8), and each
//! coordinate is the interpolating fit of [`kerf_bspline::fit()`]. For the
//! four points of seed 004 Table 1 this is the cubic Bézier through them.
//! The spline is an affine combination of the points, so it stays in their
//! plane.
//!
//! # Arc length
//!
//! `s(u) = ∫_0^u |P'(v)| dv` by composite 10-point Gauss–Legendre
//! quadrature on each knot span cut into P panels; P is doubled until the
//! total changes by less than 1e-14 relative. `u(s)` is found by Newton's
//! method (`du = (s(u) − s) / |P'(u)|`) safeguarded by bisection inside
//! the panel holding s, to 1e-13 × total length (iteration cap 100).
//!
//! # Tool axis and cutting frame
//!
//! The plane normal `n` (least-squares plane of the points, i.e. the
//! eigenvector of their scatter matrix with the smallest eigenvalue) is
//! oriented to have a positive component along the configurable `up`
//! direction (+z by default). With `approach_from_above` (default) the
//! tool approaches along `a = −n` (`tool0` z, out of the flange, into the
//! workpiece); otherwise along `a = +n`.
//!
//! The cutting frame of a segment (used by `kerf_chatter`) is
//! * `x_c = −t`, t the unit tangent at the segment's arc-length midpoint:
//!   seed 004 Fig. 2 has the tool feed along −x;
//! * `z_c = −a`: the tool axis from the tip towards the spindle;
//! * `y_c = z_c × x_c`.
//!
//! Why this matches the tooth rotation of `kerf_chatter::model`: there tooth
//! j sits at `−R (sin φ, cos φ)` in (x_c, y_c); as φ grows it moves from
//! −y_c (φ = 0) through −x_c (φ = π/2) to +y_c (φ = π), a clockwise turn
//! when seen from +z_c, i.e. by an observer on the spindle side looking
//! along −z_c towards the tip: the sense of a standard right-hand (M03)
//! spindle seen from the spindle. The tooth velocity `du/dφ ∝ (−cos φ, sin φ)`
//! is +x_c at φ = π: at the exit on +y_c the tooth moves against the tool's
//! feed (−x_c) and the chip `f_z sin φ` thins to zero, so the engagement
//! [0.75π, π] of seed 004 Table 1 is down (climb) milling on the +y_c side.

use kerf_bspline::{fit, gauss_legendre, BSpline, KnotVector};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::error::{check_finite, MillError};

/// Gauss–Legendre order per panel.
const GL_ORDER: usize = 10;

/// The Gauss–Legendre nodes and weights of order [`GL_ORDER`], computed once
/// (every arc-length integral and its inversion uses them).
fn gl_nodes() -> &'static (Vec<f64>, Vec<f64>) {
    static NODES: std::sync::OnceLock<(Vec<f64>, Vec<f64>)> = std::sync::OnceLock::new();
    NODES.get_or_init(|| gauss_legendre(GL_ORDER))
}
/// Panel doubling cap (P from 4 up to 4 · 2^13 panels per knot span).
const MAX_DOUBLINGS: usize = 14;
/// Newton/bisection cap of the arc-length inversion.
const INVERT_MAX_ITER: usize = 100;
/// Coplanarity tolerance \[m\].
pub const COPLANAR_TOL: f64 = 1e-6;
/// Two consecutive points closer than this \[m\] are "repeated".
pub const REPEAT_TOL: f64 = 1e-9;

/// What the path is built from (every field configurable in the cell YAML).
#[derive(Debug, Clone, PartialEq)]
pub struct PathSpec {
    /// The coplanar points the spline interpolates, in the base frame \[m\].
    pub points: Vec<[f64; 3]>,
    /// Number of equal-arc-length segments N.
    pub segments: usize,
    /// The tool approaches the plane against its normal (from the `up`
    /// side) when true.
    pub approach_from_above: bool,
    /// The direction the plane normal is oriented towards (need not be
    /// unit).
    pub up: [f64; 3],
}

impl Default for PathSpec {
    /// Seed 004 Table 1: the four points at z = 1.7 m, N = 100, tool from
    /// above (+z).
    fn default() -> Self {
        Self {
            points: vec![
                [1.4, -0.3, 1.7],
                [1.6, -0.1, 1.7],
                [1.8, 0.1, 1.7],
                [2.1, 0.3, 1.7],
            ],
            segments: 100,
            approach_from_above: true,
            up: [0.0, 0.0, 1.0],
        }
    }
}

/// The cutting frame (x_c, y_c, z_c) of a segment, in the base frame
/// (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuttingFrame {
    /// x_c = −tangent (the tool feeds along −x_c).
    pub x: Vector3<f64>,
    /// y_c = z_c × x_c.
    pub y: Vector3<f64>,
    /// z_c: the tool axis from the tip towards the spindle.
    pub z: Vector3<f64>,
}

/// One equal-arc-length segment of the path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Index, 0-based.
    pub index: usize,
    /// Start point \[m\].
    pub start: Vector3<f64>,
    /// End point \[m\].
    pub end: Vector3<f64>,
    /// Arc-length midpoint \[m\] (where the tool is placed for this segment).
    pub mid: Vector3<f64>,
    /// Arc length \[m\].
    pub length: f64,
    /// Unit tangent (feed direction) at the midpoint.
    pub tangent: Vector3<f64>,
    /// Spline parameters of start, midpoint and end.
    pub u: [f64; 3],
    /// The cutting frame at the midpoint.
    pub cutting_frame: CuttingFrame,
}

/// The milling path (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct MillingPath {
    curve: [BSpline; 3],
    breaks: Vec<f64>,
    cumulative: Vec<f64>,
    normal: Vector3<f64>,
    approach: Vector3<f64>,
    plane_deviation: f64,
    segments: Vec<Segment>,
}

impl MillingPath {
    /// Builds the spline, checks the plane and splits it.
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] / [`MillError::InvalidConfig`] for
    /// fewer than 2 points, a non-finite coordinate, repeated consecutive
    /// points, N = 0, a zero `up`, or a plane whose normal is perpendicular
    /// to `up`; [`MillError::NotCoplanar`] with the worst point;
    /// [`MillError::NotConverged`] if the quadrature or the inversion hits
    /// its cap; [`MillError::Bspline`] if the fit fails.
    pub fn new(spec: &PathSpec) -> Result<Self, MillError> {
        let pts = validate_points(spec)?;
        if spec.segments == 0 || spec.segments > 1_000_000 {
            return Err(MillError::InvalidParameter {
                name: "path.segments".to_string(),
                value: spec.segments as f64,
                reason: "must be in 1..=1000000".to_string(),
            });
        }
        let up = Vector3::from(spec.up);
        for (i, v) in up.iter().enumerate() {
            check_finite(&format!("path.up[{i}]"), *v)?;
        }
        if up.norm() < 1e-12 {
            return Err(MillError::InvalidConfig {
                name: "path.up".to_string(),
                reason: "must be a non-zero vector".to_string(),
            });
        }
        let (normal, plane_deviation) = plane_normal(&pts, &up.normalize())?;
        let approach = if spec.approach_from_above {
            -normal
        } else {
            normal
        };
        let curve = fit_curve(&pts)?;
        let mut path = Self {
            curve,
            breaks: Vec::new(),
            cumulative: Vec::new(),
            normal,
            approach,
            plane_deviation,
            segments: Vec::new(),
        };
        path.build_arc_length()?;
        path.split(spec.segments)?;
        Ok(path)
    }

    /// The unit plane normal (oriented towards `up`).
    pub fn normal(&self) -> Vector3<f64> {
        self.normal
    }

    /// The unit tool approach direction (`tool0` z, into the workpiece).
    pub fn approach(&self) -> Vector3<f64> {
        self.approach
    }

    /// Largest distance of an input point from the best-fit plane \[m\].
    pub fn plane_deviation(&self) -> f64 {
        self.plane_deviation
    }

    /// Total arc length \[m\].
    pub fn total_length(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// The segments, in path order.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Segment `index`.
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] when out of range.
    pub fn segment(&self, index: usize) -> Result<&Segment, MillError> {
        self.segments
            .get(index)
            .ok_or_else(|| MillError::InvalidParameter {
                name: "segment index".to_string(),
                value: index as f64,
                reason: format!("must be < {}", self.segments.len()),
            })
    }

    /// Point P(u) \[m\].
    ///
    /// # Errors
    /// [`MillError::Bspline`] for u outside [0, 1] or NaN.
    pub fn point(&self, u: f64) -> Result<Vector3<f64>, MillError> {
        let c = self.coordinates(u)?;
        Ok(Vector3::new(c[0][0], c[1][0], c[2][0]))
    }

    /// Value and first three derivatives of the three coordinates at u, from one basis
    /// evaluation (the coordinates share their knot vector: [`fit_curve`]).
    fn coordinates(&self, u: f64) -> Result<[[f64; 4]; 3], MillError> {
        let [x, y, z] = &self.curve;
        Ok(x.eval_shared([x.coeffs(), y.coeffs(), z.coeffs()], u)?)
    }

    /// Derivative P'(u) [m per unit u].
    ///
    /// # Errors
    /// [`MillError::Bspline`] for u outside [0, 1] or NaN.
    pub fn derivative(&self, u: f64) -> Result<Vector3<f64>, MillError> {
        let c = self.coordinates(u)?;
        Ok(Vector3::new(c[0][1], c[1][1], c[2][1]))
    }

    /// P(u) and P'(u) from one basis evaluation.
    ///
    /// # Errors
    /// [`MillError::Bspline`] for u outside [0, 1] or NaN.
    pub fn point_and_derivative(&self, u: f64) -> Result<(Vector3<f64>, Vector3<f64>), MillError> {
        let c = self.coordinates(u)?;
        Ok((
            Vector3::new(c[0][0], c[1][0], c[2][0]),
            Vector3::new(c[0][1], c[1][1], c[2][1]),
        ))
    }

    /// Arc length s(u) from u = 0 \[m\].
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] for u outside [0, 1] or NaN.
    pub fn arc_length_at(&self, u: f64) -> Result<f64, MillError> {
        if !(0.0..=1.0).contains(&u) {
            return Err(MillError::InvalidParameter {
                name: "spline parameter u".to_string(),
                value: u,
                reason: "must be in [0, 1]".to_string(),
            });
        }
        let k = self.panel_of_u(u);
        Ok(self.cumulative[k] + self.panel_integral(self.breaks[k], u))
    }

    /// The parameter u at arc length s (module documentation).
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] for s outside [0, total] (1e-12
    /// relative slack) or NaN; [`MillError::NotConverged`] at the cap.
    pub fn parameter_at(&self, s: f64) -> Result<f64, MillError> {
        let total = self.total_length();
        let slack = 1e-12 * total;
        if !(s >= -slack && s <= total + slack) {
            return Err(MillError::InvalidParameter {
                name: "arc length s [m]".to_string(),
                value: s,
                reason: format!("must be in [0, {total}]"),
            });
        }
        let s = s.clamp(0.0, total);
        // Panel k with cumulative[k] <= s <= cumulative[k + 1].
        let k = match self.cumulative.binary_search_by(|c| c.total_cmp(&s)) {
            Ok(i) => return Ok(self.breaks[i]),
            Err(i) => i.saturating_sub(1).min(self.breaks.len().saturating_sub(2)),
        };
        let (mut lo, mut hi) = (self.breaks[k], self.breaks[k + 1]);
        let target = s - self.cumulative[k];
        let tol = 1e-13 * total.max(f64::MIN_POSITIVE);
        let mut u = lo
            + (hi - lo) * target
                / (self.cumulative[k + 1] - self.cumulative[k]).max(f64::MIN_POSITIVE);
        let mut f = f64::NAN;
        for _ in 0..INVERT_MAX_ITER {
            f = self.panel_integral(self.breaks[k], u) - target;
            if f.abs() <= tol {
                return Ok(u);
            }
            if f > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            let speed = self.derivative(u)?.norm();
            let newton = u - f / speed;
            u = if speed > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
        }
        Err(MillError::NotConverged {
            what: "arc-length inversion u(s)".to_string(),
            iterations: INVERT_MAX_ITER,
            residual: f,
        })
    }

    /// The tool-tip (TCP) pose for segment `index` and redundancy angle g:
    /// `T_tcp(g) = [R0 · RotZ(g), p]` (seed 004 eq. 13), p the segment's
    /// midpoint and `R0 = [t, a × t, a]` with t the unit tangent (feed
    /// direction) and a the approach direction: at g = 0 the tool x axis is
    /// the feed direction and its z axis points into the workpiece; g turns
    /// the tool frame about its own z axis (right-hand rule).
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] for a bad index or a non-finite g.
    pub fn tool_pose(&self, index: usize, g: f64) -> Result<Isometry3<f64>, MillError> {
        let g = check_finite("redundancy angle g [rad]", g)?;
        let seg = self.segment(index)?;
        Ok(tool_pose(&seg.mid, &seg.tangent, &self.approach, g))
    }

    fn panel_of_u(&self, u: f64) -> usize {
        let n = self.breaks.len().saturating_sub(2);
        match self.breaks.binary_search_by(|b| b.total_cmp(&u)) {
            Ok(i) => i.min(n),
            Err(i) => i.saturating_sub(1).min(n),
        }
    }

    /// ∫_a^b |P'(v)| dv by one GL rule.
    fn panel_integral(&self, a: f64, b: f64) -> f64 {
        let (x, w) = gl_nodes();
        let h = 0.5 * (b - a);
        let m = 0.5 * (a + b);
        x.iter()
            .zip(w)
            .map(|(xi, wi)| {
                let u = (m + h * xi).clamp(0.0, 1.0);
                let c = self.coordinates(u).unwrap_or([[f64::NAN; 4]; 3]);
                wi * Vector3::new(c[0][1], c[1][1], c[2][1]).norm()
            })
            .sum::<f64>()
            * h
    }

    fn build_arc_length(&mut self) -> Result<(), MillError> {
        let mut spans: Vec<f64> = vec![0.0];
        spans.extend_from_slice(self.curve[0].knots().interior());
        spans.push(1.0);
        let mut panels = 4usize;
        let mut prev_total = f64::NAN;
        for _ in 0..MAX_DOUBLINGS {
            let mut breaks = Vec::with_capacity(spans.len() * panels);
            for w in spans.windows(2) {
                for p in 0..panels {
                    breaks.push(w[0] + (w[1] - w[0]) * p as f64 / panels as f64);
                }
            }
            breaks.push(1.0);
            let mut cumulative = Vec::with_capacity(breaks.len());
            let mut acc = 0.0;
            cumulative.push(0.0);
            for w in breaks.windows(2) {
                acc += self.panel_integral(w[0], w[1]);
                cumulative.push(acc);
            }
            if !acc.is_finite() {
                return Err(MillError::NonFinite {
                    what: "path arc length".to_string(),
                });
            }
            let converged = (acc - prev_total).abs() <= 1e-14 * acc;
            self.breaks = breaks;
            self.cumulative = cumulative;
            if converged {
                return Ok(());
            }
            prev_total = acc;
            panels *= 2;
        }
        Err(MillError::NotConverged {
            what: "arc-length quadrature (panel doubling)".to_string(),
            iterations: MAX_DOUBLINGS,
            residual: f64::NAN,
        })
    }

    fn split(&mut self, n: usize) -> Result<(), MillError> {
        let total = self.total_length();
        let mut segments = Vec::with_capacity(n);
        let mut u_start = 0.0;
        for i in 0..n {
            let u_end = if i + 1 == n {
                1.0
            } else {
                self.parameter_at(total * (i + 1) as f64 / n as f64)?
            };
            let u_mid = self.parameter_at(total * (i as f64 + 0.5) / n as f64)?;
            let d = self.derivative(u_mid)?;
            let d = d - d.dot(&self.normal) * self.normal;
            let norm = d.norm();
            if norm.is_nan() || norm <= 0.0 {
                return Err(MillError::Singular {
                    what: format!("path tangent of segment {i} (zero speed)"),
                });
            }
            let tangent = d / norm;
            let z = -self.approach;
            let x = -tangent;
            let cutting_frame = CuttingFrame {
                x,
                y: z.cross(&x),
                z,
            };
            segments.push(Segment {
                index: i,
                start: self.point(u_start)?,
                end: self.point(u_end)?,
                mid: self.point(u_mid)?,
                length: self.arc_length_at(u_end)? - self.arc_length_at(u_start)?,
                tangent,
                u: [u_start, u_mid, u_end],
                cutting_frame,
            });
            u_start = u_end;
        }
        self.segments = segments;
        Ok(())
    }
}

/// `T_tcp(g) = [R0 · RotZ(g), p]`, `R0 = [t, a × t, a]` (see
/// [`MillingPath::tool_pose`]); t and a must be orthonormal.
pub fn tool_pose(
    p: &Vector3<f64>,
    tangent: &Vector3<f64>,
    approach: &Vector3<f64>,
    g: f64,
) -> Isometry3<f64> {
    let r0 = Matrix3::from_columns(&[*tangent, approach.cross(tangent), *approach]);
    let r =
        Rotation3::from_matrix_unchecked(r0) * Rotation3::from_axis_angle(&Vector3::z_axis(), g);
    Isometry3::from_parts(
        Translation3::from(*p),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

fn validate_points(spec: &PathSpec) -> Result<Vec<Vector3<f64>>, MillError> {
    if spec.points.len() < 2 {
        return Err(MillError::InvalidParameter {
            name: "path.points (count)".to_string(),
            value: spec.points.len() as f64,
            reason: "at least 2 points are needed".to_string(),
        });
    }
    let mut pts: Vec<Vector3<f64>> = Vec::with_capacity(spec.points.len());
    for (i, p) in spec.points.iter().enumerate() {
        for (c, v) in p.iter().enumerate() {
            check_finite(&format!("path.points[{i}][{c}] [m]"), *v)?;
        }
        let v = Vector3::from(*p);
        if let Some(prev) = pts.last() {
            let d = (v - prev).norm();
            if d <= REPEAT_TOL {
                return Err(MillError::InvalidParameter {
                    name: format!("path.points[{i}]"),
                    value: d,
                    reason: format!(
                        "repeats point {} (distance shown, must exceed {REPEAT_TOL} m)",
                        i - 1
                    ),
                });
            }
        }
        pts.push(v);
    }
    Ok(pts)
}

/// Unit normal of the least-squares plane, oriented along `up`, and the
/// largest point distance from it.
fn plane_normal(pts: &[Vector3<f64>], up: &Vector3<f64>) -> Result<(Vector3<f64>, f64), MillError> {
    let c = pts.iter().sum::<Vector3<f64>>() / pts.len() as f64;
    let mut s = Matrix3::zeros();
    for p in pts {
        let d = p - c;
        s += d * d.transpose();
    }
    let eig = s
        .try_symmetric_eigen(f64::EPSILON, 1000)
        .ok_or_else(|| MillError::NotConverged {
            what: "scatter matrix of the path points".to_string(),
            iterations: 1000,
            residual: f64::NAN,
        })?;
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let line = eig.eigenvectors.column(order[2]).into_owned();
    let off_line = pts
        .iter()
        .map(|p| {
            let d = p - c;
            (d - d.dot(&line) * line).norm()
        })
        .fold(0.0, f64::max);
    let mut normal = if off_line < REPEAT_TOL {
        // Collinear (e.g. two points): the plane through the line whose
        // normal is closest to `up`.
        let n = up - up.dot(&line) * line;
        if n.norm() < 1e-9 {
            return Err(MillError::InvalidConfig {
                name: "path.points".to_string(),
                reason: "the points lie on a line parallel to `up`: the tool axis is undefined"
                    .to_string(),
            });
        }
        n.normalize()
    } else {
        eig.eigenvectors.column(order[0]).into_owned().normalize()
    };
    let (worst, dev) = pts
        .iter()
        .enumerate()
        .map(|(i, p)| (i, (p - c).dot(&normal).abs()))
        .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    if dev > COPLANAR_TOL {
        return Err(MillError::NotCoplanar {
            worst_point: worst,
            distance: dev,
            tolerance: COPLANAR_TOL,
        });
    }
    let along = normal.dot(up);
    if along.abs() < 1e-9 {
        return Err(MillError::InvalidConfig {
            name: "path.up".to_string(),
            reason: "is parallel to the path plane: the side of approach is ambiguous".to_string(),
        });
    }
    if along < 0.0 {
        normal = -normal;
    }
    Ok((normal, dev))
}

fn fit_curve(pts: &[Vector3<f64>]) -> Result<[BSpline; 3], MillError> {
    let n = pts.len();
    let degree = 3.min(n - 1);
    let chords: Vec<f64> = pts.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let total: f64 = chords.iter().sum();
    let mut params = Vec::with_capacity(n);
    let mut acc = 0.0;
    params.push(0.0);
    for c in &chords {
        acc += c;
        params.push(acc / total);
    }
    if let Some(last) = params.last_mut() {
        *last = 1.0;
    }
    let kv = KnotVector::for_parameters(degree, n, &params)?;
    let coord = |k: usize| -> Result<BSpline, MillError> {
        let values: Vec<f64> = pts.iter().map(|p| p[k]).collect();
        Ok(BSpline::new(kv.clone(), fit(&kv, &params, &values)?)?)
    };
    Ok([coord(0)?, coord(1)?, coord(2)?])
}
