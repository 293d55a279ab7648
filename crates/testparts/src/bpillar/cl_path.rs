//! CL paths on the part, sampled like a G-code interpolator: the flange
//! trim path and the path across the section.

use nalgebra::Vector3;

use super::part::BPillar;
use super::section::LEFT_FLANGE_FILLET_START;
use super::surface::SurfaceVertex;
use crate::rounding::{round_axis, round_point};
use crate::TestPartError;

/// A CL path: points on the outer surface and their nominal tool axes.
#[derive(Debug, Clone, PartialEq)]
pub struct ClPath {
    /// CL points in the workpiece frame (m), rounded to 1 nm.
    pub points: Vec<[f64; 3]>,
    /// Unit outward surface normals (nominal tool axes), rounded to 1e-12.
    pub axes: Vec<[f64; 3]>,
    /// Spacing along the path, `f Δt` (m).
    pub spacing: f64,
}

impl BPillar {
    /// A trim path along the left flange, parallel to the spine, at a
    /// constant distance from the flange fillet.
    ///
    /// # Arguments
    /// * `offset` - distance of the trim line from the tangent point where
    ///   the left flange meets its fillet in the section at `start`,
    ///   measured on the flange (m).
    /// * `start` - spine arc length of the first CL point (m).
    /// * `spacing` - distance between CL points along the path, `f Δt` (m).
    /// * `count` - number of CL points (≥ 2).
    ///
    /// # Returns
    /// CL points on the flange (exactly on the mesh: the flange strips are
    /// planar) with the flange normal `u(s)` as nominal axis.
    ///
    /// # Errors
    /// [`TestPartError::Invalid`] when an argument is not finite or out
    /// of range, the path leaves the part, or the trim line is not on the
    /// flange of every station it crosses.
    pub fn flange_trim_path(
        &self,
        offset: f64,
        start: f64,
        spacing: f64,
        count: usize,
    ) -> Result<ClPath, TestPartError> {
        check_path_args(spacing, count)?;
        if !(offset.is_finite() && offset > 0.0) {
            return Err(TestPartError::invalid(
                "trim offset",
                format!("{offset} must be finite and > 0"),
            ));
        }
        if !start.is_finite() {
            return Err(TestPartError::invalid("trim start", "not finite"));
        }
        let section = self.params.section_at(start);
        let y = section.flange_tangent_y() - offset;
        let vertices: Vec<SurfaceVertex> = self
            .stations
            .iter()
            .map(|&s| {
                let sp = self.spine.eval(s);
                SurfaceVertex {
                    point: sp.map(y, 0.0),
                    normal: sp.up(),
                }
            })
            .collect();
        let line = Polyline::new(vertices)?;
        // Position of `start` on the polyline: on the chord of its station
        // interval, at the same fraction as along the spine.
        let i = self
            .stations
            .windows(2)
            .position(|w| w[0] <= start && start <= w[1])
            .ok_or_else(|| {
                TestPartError::invalid(
                    "trim start",
                    format!(
                        "{start} m is outside the spine [0, {:.4}] m",
                        self.params.spine_length()
                    ),
                )
            })?;
        let (s_a, s_b) = (self.stations[i], self.stations[i + 1]);
        let l0 = line.cum[i] + (start - s_a) / (s_b - s_a) * (line.cum[i + 1] - line.cum[i]);
        let l_end = l0 + spacing * (count - 1) as f64;
        // The trim line must lie on the flange strip of every station whose
        // chords the path uses (the strip between two stations is planar:
        // both its long edges run along ŷ, so the line lies on the mesh).
        for (k, &s) in self.stations.iter().enumerate() {
            let chord_used = |a: usize| match (line.cum.get(a), line.cum.get(a + 1)) {
                (Some(&la), Some(&lb)) => la < l_end && lb > l0,
                _ => false,
            };
            let used = (k > 0 && chord_used(k - 1)) || chord_used(k);
            if !used {
                continue;
            }
            let sec = self.params.section_at(s);
            if !(y > sec.flange_edge_y() && y < sec.flange_tangent_y()) {
                return Err(TestPartError::invalid(
                    "trim offset",
                    format!("y = {y:.4} m is not on the flange at station s = {s:.4} m"),
                ));
            }
        }
        line.sample(l0, spacing, count)
    }

    /// A cut across the section at spine arc length `station`, from the
    /// left flange over the flange fillet, the wall and the top fillet onto
    /// the top.
    ///
    /// # Arguments
    /// * `station` - spine arc length of the cut plane (m), inside the
    ///   uniform foot (`[0, foot_length]`, where the mesh strips are planar,
    ///   so the profile polyline lies on the mesh).
    /// * `flange_run` - path length on the flange before its fillet (m).
    /// * `spacing`, `count` - as for [`BPillar::flange_trim_path`].
    ///
    /// # Returns
    /// The path and the path lengths (m, from its first point) of the
    /// flange fillet's start and end and the top fillet's start and end.
    ///
    /// # Errors
    /// [`TestPartError::Invalid`] for arguments out of range, or when
    /// the path would not end on the top between the fillets.
    pub fn section_path(
        &self,
        station: f64,
        flange_run: f64,
        spacing: f64,
        count: usize,
    ) -> Result<(ClPath, [f64; 4]), TestPartError> {
        check_path_args(spacing, count)?;
        if !(station.is_finite() && (0.0..=self.params.foot_length).contains(&station)) {
            return Err(TestPartError::invalid(
                "section station",
                format!(
                    "{station} m must lie in the uniform foot [0, {}] m",
                    self.params.foot_length
                ),
            ));
        }
        let section = self.params.section_at(station);
        if !(flange_run.is_finite()
            && flange_run > 0.0
            && flange_run < section.flange_width - section.flange_fillet_tangent())
        {
            return Err(TestPartError::invalid(
                "flange run",
                format!("{flange_run} m must be in (0, flange straight length)"),
            ));
        }
        let sp = self.spine.eval(station);
        let n1 = self.params.flange_fillet_segments;
        let n2 = self.params.top_fillet_segments;
        let vertices: Vec<SurfaceVertex> = section
            .profile(n1, n2)
            .iter()
            .map(|v| SurfaceVertex {
                point: sp.map(v.y, v.z),
                normal: sp.map_dir(v.ny, v.nz),
            })
            .collect();
        let line = Polyline::new(vertices)?;
        let fillet1_start = LEFT_FLANGE_FILLET_START;
        let fillet1_end = fillet1_start + n1;
        let fillet2_start = fillet1_end + 1;
        let fillet2_end = fillet2_start + n2;
        let top_end = fillet2_end + 1;
        let at = |k: usize| line.cum.get(k).copied().unwrap_or(f64::NAN);
        let l0 = at(fillet1_start) - flange_run;
        let l_end = l0 + spacing * (count - 1) as f64;
        if !(l_end > at(fillet2_end) && l_end < at(top_end)) {
            return Err(TestPartError::invalid(
                "section path",
                format!(
                    "{count} points at {spacing} m end {:.4} m along the profile, not on the \
                     top ({:.4} to {:.4} m)",
                    l_end - l0,
                    at(fillet2_end) - l0,
                    at(top_end) - l0
                ),
            ));
        }
        let marks = [
            at(fillet1_start) - l0,
            at(fillet1_end) - l0,
            at(fillet2_start) - l0,
            at(fillet2_end) - l0,
        ];
        Ok((line.sample(l0, spacing, count)?, marks))
    }
}

/// Checks the spacing (finite, > 0) and point count (≥ 2) of a path.
fn check_path_args(spacing: f64, count: usize) -> Result<(), TestPartError> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(TestPartError::invalid(
            "path spacing",
            format!("{spacing} must be finite and > 0"),
        ));
    }
    if count < 2 {
        return Err(TestPartError::invalid(
            "path points",
            format!("{count}: at least 2 are needed"),
        ));
    }
    Ok(())
}

/// A polyline on the outer surface with cumulative chord lengths.
struct Polyline {
    verts: Vec<SurfaceVertex>,
    cum: Vec<f64>,
}

impl Polyline {
    fn new(verts: Vec<SurfaceVertex>) -> Result<Self, TestPartError> {
        let mut cum = Vec::with_capacity(verts.len());
        let mut acc = 0.0;
        cum.push(0.0);
        for w in verts.windows(2) {
            let d = (w[1].point - w[0].point).norm();
            if !(d.is_finite() && d > 0.0) {
                return Err(TestPartError::invalid(
                    "bpillar path",
                    "zero-length or non-finite polyline segment",
                ));
            }
            acc += d;
            cum.push(acc);
        }
        if verts.len() < 2 {
            return Err(TestPartError::invalid(
                "bpillar path",
                "polyline with fewer than 2 vertices",
            ));
        }
        Ok(Self { verts, cum })
    }

    /// The point at length `l` and the slerp of the end normals of its
    /// segment (the G-code interpolator's QI between two blocks).
    fn at(&self, l: f64) -> Result<SurfaceVertex, TestPartError> {
        let total = self.cum.last().copied().unwrap_or(0.0);
        let tol = 1e-12 * total.max(1.0);
        if !(l >= -tol && l <= total + tol) {
            return Err(TestPartError::invalid(
                "bpillar path",
                format!("position {l} m is outside the polyline [0, {total}] m"),
            ));
        }
        let k = self
            .cum
            .windows(2)
            .position(|w| l <= w[1])
            .unwrap_or(self.cum.len().saturating_sub(2));
        let (Some(a), Some(b), Some(la), Some(lb)) = (
            self.verts.get(k),
            self.verts.get(k + 1),
            self.cum.get(k),
            self.cum.get(k + 1),
        ) else {
            return Err(TestPartError::invalid(
                "bpillar path",
                "polyline index out of range",
            ));
        };
        let lambda = ((l - la) / (lb - la)).clamp(0.0, 1.0);
        Ok(SurfaceVertex {
            point: a.point + (b.point - a.point) * lambda,
            normal: slerp(&a.normal, &b.normal, lambda),
        })
    }

    /// `count` points at `l0 + k spacing`.
    fn sample(&self, l0: f64, spacing: f64, count: usize) -> Result<ClPath, TestPartError> {
        // Check both ends before allocating (a huge count fails here).
        let last = l0 + spacing * count.saturating_sub(1) as f64;
        self.at(l0)?;
        self.at(last)?;
        let mut points = Vec::with_capacity(count);
        let mut axes = Vec::with_capacity(count);
        for k in 0..count {
            let v = self.at(l0 + spacing * k as f64)?;
            points.push(round_point(&v.point));
            axes.push(round_axis(&v.normal));
        }
        Ok(ClPath {
            points,
            axes,
            spacing,
        })
    }
}

/// Spherical linear interpolation between unit vectors `a` and `b`:
/// `(sin((1-λ)θ) a + sin(λθ) b) / sin θ`, θ = ∠(a, b) (Shoemake 1985, the
/// vector form of quaternion slerp); normalised linear interpolation when
/// θ is tiny.
fn slerp(a: &Vector3<f64>, b: &Vector3<f64>, lambda: f64) -> Vector3<f64> {
    let theta = a.cross(b).norm().atan2(a.dot(b));
    let v = if theta < 1e-9 {
        a * (1.0 - lambda) + b * lambda
    } else {
        let s = theta.sin();
        a * (((1.0 - lambda) * theta).sin() / s) + b * ((lambda * theta).sin() / s)
    };
    v.normalize()
}
