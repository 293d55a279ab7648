//! Press-brake profiles: a polyline of straight pieces in the (y, z) section plane whose
//! corners are bent with a radius, and its extrusion along x into a sheet.

use nalgebra::{Rotation2, Vector2, Vector3};

use super::sheet::SheetGrid;
use crate::TestPartError;

/// Shortest straight piece left between two bends (m).
const MIN_STRAIGHT: f64 = 1e-3;

/// One vertex of a bent profile: position and unit head-side normal in the (y, z) plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileVertex {
    /// Position (y, z) (m).
    pub p: Vector2<f64>,
    /// Unit head-side normal: the left normal of the direction of travel.
    pub n: Vector2<f64>,
}

/// The left normal `(-d_z, d_y)` of a direction.
fn left(d: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(-d.y, d.x)
}

/// A bent profile: the polyline `corners` with every interior corner replaced by a circular
/// arc of head-side radius `radius` tangent to both pieces, `segments` chords per arc.
///
/// The head side is to the left of the direction of travel. A left turn is concave seen from
/// the head (its centre on the head side, the far side of the sheet bends with radius
/// `radius + t`); a right turn is convex (the far side bends with `radius − t`, so `radius`
/// must exceed the thickness). Fillet construction: the tangent points lie `r tan(β/2)` from
/// the corner for a deflection β.
///
/// # Errors
/// [`TestPartError::Invalid`] for fewer than two corners, a zero-length piece, a radius not
/// above `thickness`, or a piece too short for its bends.
pub fn bent_profile(
    corners: &[Vector2<f64>],
    radius: f64,
    thickness: f64,
    segments: usize,
) -> Result<Vec<ProfileVertex>, TestPartError> {
    if corners.len() < 2 || segments == 0 {
        return Err(TestPartError::invalid(
            "profile",
            "at least two corners and one chord per bend are needed",
        ));
    }
    if !(radius.is_finite() && radius > thickness && thickness > 0.0) {
        return Err(TestPartError::invalid(
            "profile bend radius",
            format!("{radius} m must exceed the thickness {thickness} m"),
        ));
    }
    let dirs: Vec<Vector2<f64>> = corners
        .windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let len = d.norm();
            if len > 0.0 && len.is_finite() {
                Ok(d / len)
            } else {
                Err(TestPartError::invalid("profile", "zero-length piece"))
            }
        })
        .collect::<Result<_, _>>()?;
    // Tangent length at each interior corner.
    let turn = |k: usize| {
        let (a, b) = (dirs[k - 1], dirs[k]);
        (a.x * b.y - a.y * b.x).atan2(a.dot(&b))
    };
    let tangent = |k: usize| radius * (turn(k).abs() / 2.0).tan();
    for (k, w) in corners.windows(2).enumerate() {
        let used = if k > 0 { tangent(k) } else { 0.0 }
            + if k + 2 < corners.len() {
                tangent(k + 1)
            } else {
                0.0
            };
        if (w[1] - w[0]).norm() - used < MIN_STRAIGHT {
            return Err(TestPartError::invalid(
                "profile",
                format!("piece {k} is too short for its bends"),
            ));
        }
    }
    let mut out = vec![ProfileVertex {
        p: corners[0],
        n: left(&dirs[0]),
    }];
    for k in 1..corners.len() - 1 {
        let beta = turn(k);
        let d1 = dirs[k - 1];
        let a = corners[k] - d1 * tangent(k);
        let side = if beta > 0.0 { 1.0 } else { -1.0 };
        let centre = a + left(&d1) * (radius * side);
        for s in 0..=segments {
            let rot = Rotation2::new(beta * s as f64 / segments as f64);
            out.push(ProfileVertex {
                p: centre + rot * (a - centre),
                n: rot * left(&d1),
            });
        }
    }
    let last = corners.len() - 1;
    out.push(ProfileVertex {
        p: corners[last],
        n: left(&dirs[last - 1]),
    });
    Ok(out)
}

/// The sheet of a profile extruded along x over `[0, length]` with `stations` samples.
pub fn extrude(profile: &[ProfileVertex], length: f64, stations: usize) -> SheetGrid {
    let mut points = Vec::with_capacity(profile.len() * stations);
    let mut normals = Vec::with_capacity(profile.len() * stations);
    for v in profile {
        for j in 0..stations {
            let x = length * j as f64 / (stations - 1).max(1) as f64;
            points.push(Vector3::new(x, v.p.x, v.p.y));
            normals.push(Vector3::new(0.0, v.n.x, v.n.y));
        }
    }
    SheetGrid {
        nu: profile.len(),
        nv: stations,
        periodic_u: false,
        points,
        normals,
    }
}
