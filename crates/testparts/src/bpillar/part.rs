//! The generated part: parameters, stations, outer surface and mesh.

use kerf_mjto::mesh::MeshData;

use super::params::BPillarParams;
use super::spine::Spine;
use super::surface::{build_mesh, station_list, surface_vertices, SurfaceVertex};
use crate::TestPartError;

/// The generated workpiece: parameters, stations and the closed mesh.
#[derive(Debug, Clone)]
pub struct BPillar {
    pub(super) params: BPillarParams,
    pub(super) spine: Spine,
    pub(super) stations: Vec<f64>,
    pub(super) profile_len: usize,
    pub(super) outer: Vec<SurfaceVertex>,
    pub(super) mesh: MeshData,
}

impl BPillar {
    /// Generates the workpiece.
    ///
    /// # Arguments
    /// * `params` - the part's dimensions ([`BPillarParams::default`] for
    ///   the committed mesh).
    ///
    /// # Returns
    /// The part with its closed, outward-oriented thin-solid mesh: the
    /// outer surface (stations × profile vertices), the inner surface (each
    /// outer vertex moved by the thickness against the surface normal) and
    /// the strips closing the free edges.
    ///
    /// # Errors
    /// [`TestPartError::Invalid`] from [`BPillarParams::validate`], or
    /// when the mesh would exceed the u32 vertex indices.
    ///
    /// # Performance
    /// O(stations × profile vertices); well under a millisecond for the
    /// defaults.
    pub fn new(params: BPillarParams) -> Result<Self, TestPartError> {
        params.validate()?;
        let spine = Spine::new(&params);
        let stations = station_list(&params);
        let n1 = params.flange_fillet_segments;
        let n2 = params.top_fillet_segments;
        let profile_len = 2 * (n1 + n2 + 3);
        let mut outer = Vec::with_capacity(stations.len() * profile_len);
        for &s in &stations {
            outer.extend(surface_vertices(&params, &spine, s)?);
        }
        let mesh = build_mesh(&outer, stations.len(), profile_len, params.thickness)?;
        Ok(Self {
            params,
            spine,
            stations,
            profile_len,
            outer,
            mesh,
        })
    }

    /// The parameters the part was generated from.
    pub fn params(&self) -> &BPillarParams {
        &self.params
    }

    /// The closed thin-solid mesh (workpiece frame, m).
    pub fn mesh(&self) -> &MeshData {
        &self.mesh
    }

    /// Spine arc lengths of the mesh stations (m), increasing from 0 to
    /// [`BPillarParams::spine_length`].
    pub fn stations(&self) -> &[f64] {
        &self.stations
    }

    /// Number of profile vertices per station.
    pub fn profile_len(&self) -> usize {
        self.profile_len
    }

    /// The outer-surface vertices (station-major: vertex `j` of station
    /// `i` is element `i * profile_len + j`; it is also mesh vertex
    /// `i * profile_len + j`, and its inner counterpart is mesh vertex
    /// `(stations + i) * profile_len + j`).
    pub fn outer_vertices(&self) -> &[SurfaceVertex] {
        &self.outer
    }
}
