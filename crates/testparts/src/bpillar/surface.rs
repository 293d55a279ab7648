//! The outer surface of the part and its closed thin-solid mesh.

use kerf_mjto::mesh::MeshData;
use nalgebra::Vector3;

use super::params::BPillarParams;
use super::spine::Spine;
use super::SECTION_FD_STEP;
use crate::rounding::round_point;
use crate::TestPartError;

/// A point of the outer surface with its unit outward (head-side) normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceVertex {
    /// Position in the workpiece frame (m).
    pub point: Vector3<f64>,
    /// Unit outward normal of the outer surface.
    pub normal: Vector3<f64>,
}

/// Spine arc lengths of the mesh stations: the ends of the foot, the
/// transition in `transition_stations` steps, the curved part in steps of
/// at most `curved_station_spacing`, the kink in `kink_stations` steps, and
/// the end.
pub(super) fn station_list(p: &BPillarParams) -> Vec<f64> {
    let mut st = vec![0.0, p.foot_length];
    let run = |from: f64, len: f64, n: usize, st: &mut Vec<f64>| {
        for k in 1..=n {
            st.push(from + len * k as f64 / n as f64);
        }
    };
    run(
        p.foot_length,
        p.transition_length,
        p.transition_stations,
        &mut st,
    );
    let n_curved = (p.curved_length / p.curved_station_spacing).ceil().max(1.0) as usize;
    run(p.curved_start(), p.curved_length, n_curved, &mut st);
    run(
        p.kink_start(),
        p.kink_radius * p.kink_angle,
        p.kink_stations,
        &mut st,
    );
    st.push(p.spine_length());
    st
}

/// The outer-surface vertices of the station at spine arc length `s`.
///
/// Surface `P(s, τ) = S(s) + y(s, τ) ŷ + z(s, τ) u(s)` (a profile swept
/// along the spine, section blended along s). Its outward normal is
/// `∂P/∂s × ∂P/∂τ` normalised, with `∂P/∂s = (1 + κ z) t + ∂y/∂s ŷ +
/// ∂z/∂s u` (u' = κ t for a spine bending away from the head side) and
/// `∂P/∂τ` along the profile tangent `(nz, -ny)`. Where the section is
/// constant (`∂y/∂s = ∂z/∂s = 0`) this is exactly the profile normal
/// `ny ŷ + nz u`; in the transition the section derivative is a central
/// difference.
pub(super) fn surface_vertices(
    p: &BPillarParams,
    spine: &Spine,
    s: f64,
) -> Result<Vec<SurfaceVertex>, TestPartError> {
    let n1 = p.flange_fillet_segments;
    let n2 = p.top_fillet_segments;
    let sp = spine.eval(s);
    let here = p.section_at(s).profile(n1, n2);
    let h = SECTION_FD_STEP;
    let ahead = p.section_at(s + h).profile(n1, n2);
    let behind = p.section_at(s - h).profile(n1, n2);
    let t = sp.tangent();
    here.iter()
        .zip(ahead.iter().zip(&behind))
        .map(|(v, (a, b))| {
            let dy = (a.y - b.y) / (2.0 * h);
            let dz = (a.z - b.z) / (2.0 * h);
            let ds = t * (1.0 + sp.curvature * v.z) + sp.map_dir(dy, dz);
            let dtau = sp.map_dir(v.nz, -v.ny);
            let n = ds.cross(&dtau);
            let norm = n.norm();
            if !(norm.is_finite() && norm > 0.0) {
                return Err(TestPartError::invalid(
                    "bpillar",
                    format!("degenerate surface normal at s = {s} m"),
                ));
            }
            Ok(SurfaceVertex {
                point: sp.map(v.y, v.z),
                normal: n / norm,
            })
        })
        .collect()
}

/// The closed mesh: outer grid (normals outward = head side), inner grid
/// (reversed), and a strip on every boundary edge of the outer grid.
///
/// Outer quad (i, j): a = (i, j), b = (i+1, j), c = (i+1, j+1),
/// d = (i, j+1), triangles (a, b, c), (a, c, d): their normal is
/// `∂P/∂s × ∂P/∂τ`, the outward normal. A boundary edge a → b of the outer
/// grid (directed as in its triangle) gets the strip (b, a, a'), (b, a', b')
/// with a', b' the inner vertices: every edge of the closed surface is then
/// used once in each direction.
pub(super) fn build_mesh(
    outer: &[SurfaceVertex],
    n_stations: usize,
    n_profile: usize,
    thickness: f64,
) -> Result<MeshData, TestPartError> {
    let n_outer = n_stations * n_profile;
    if u32::try_from(2 * n_outer).is_err() {
        return Err(TestPartError::invalid(
            "bpillar",
            "too many vertices for u32 indices",
        ));
    }
    let mut vertices = Vec::with_capacity(2 * n_outer);
    vertices.extend(outer.iter().map(|v| round_point(&v.point)));
    vertices.extend(
        outer
            .iter()
            .map(|v| round_point(&(v.point - v.normal * thickness))),
    );
    let o = |i: usize, j: usize| (i * n_profile + j) as u32;
    let inn = |i: usize, j: usize| (n_outer + i * n_profile + j) as u32;
    let mut triangles = Vec::with_capacity(4 * n_outer + 4 * (n_stations + n_profile));
    for i in 0..n_stations.saturating_sub(1) {
        for j in 0..n_profile.saturating_sub(1) {
            let (a, b, c, d) = (o(i, j), o(i + 1, j), o(i + 1, j + 1), o(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
            let (a, b, c, d) = (inn(i, j), inn(i + 1, j), inn(i + 1, j + 1), inn(i, j + 1));
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    let last_i = n_stations.saturating_sub(1);
    let last_j = n_profile.saturating_sub(1);
    let mut boundary: Vec<((usize, usize), (usize, usize))> = Vec::new();
    for i in 0..last_i {
        boundary.push(((i, 0), (i + 1, 0)));
        boundary.push(((i + 1, last_j), (i, last_j)));
    }
    for j in 0..last_j {
        boundary.push(((last_i, j), (last_i, j + 1)));
        boundary.push(((0, j + 1), (0, j)));
    }
    for ((ai, aj), (bi, bj)) in boundary {
        let (a, b) = (o(ai, aj), o(bi, bj));
        let (a2, b2) = (inn(ai, aj), inn(bi, bj));
        triangles.push([b, a, a2]);
        triangles.push([b, a2, b2]);
    }
    Ok(MeshData {
        vertices,
        triangles,
    })
}
