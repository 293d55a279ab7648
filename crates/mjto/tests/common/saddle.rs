//! A tube saddle cut (issue 16): the hole for a branch tube of radius `r` in a
//! main tube of radius `R` along x, the tool axis the main tube's normal
//! (through the vertical twice per loop), with a rib standing on the main
//! tube beside the cut. With r/R = 0.5 the nominal axis tilts by up to 30°
//! from the vertical; at the reference standoff (−0.07 m) the head's fork
//! (link `c_axis`) touches the main tube on 82 of the 160 CL points (the
//! nominal orientation), so the planner must take other standoffs and
//! orientations within the 10° allowance.
#![allow(dead_code)] // each test file uses a subset

use std::f64::consts::PI;
use std::path::PathBuf;

use kerf_mjto::mesh::{write_obj, MeshData};
use kerf_mjto::request::CutOptions;
use kerf_mjto::CutRequest;

/// Geometry of the saddle.
#[derive(Debug, Clone, Copy)]
pub struct Saddle {
    /// Main tube radius R (m).
    pub main_radius: f64,
    /// Branch tube radius r (m), < R.
    pub branch_radius: f64,
    /// CL points of the loop.
    pub points: usize,
    /// The rib: a plate parallel to the tube axis at y = `rib_y` (m), `rib_thickness` thick,
    /// from the tube up to z = `rib_top` (m); `None`: no rib.
    pub rib: Option<(f64, f64, f64)>,
}

impl Default for Saddle {
    fn default() -> Self {
        Self {
            main_radius: 0.1,
            branch_radius: 0.05,
            points: 160,
            rib: Some((0.17, 0.01, 0.3)),
        }
    }
}

impl Saddle {
    /// CL points and unit tool axes (the main tube's outward normal), starting at θ = −90°
    /// (y = −r) and going once around (the last point one step before the first).
    pub fn path(&self) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let (rr, r) = (self.main_radius, self.branch_radius);
        let mut points = Vec::with_capacity(self.points);
        let mut axes = Vec::with_capacity(self.points);
        for k in 0..self.points {
            let theta = -0.5 * PI + 2.0 * PI * k as f64 / self.points as f64;
            let (x, y) = (r * theta.cos(), r * theta.sin());
            let z = (rr * rr - y * y).sqrt();
            points.push([x, y, z]);
            axes.push([0.0, y / rr, z / rr]);
        }
        (points, axes)
    }

    /// The workpiece: the main tube (open, 64 facets around, 0.8 m long) and the rib.
    pub fn mesh(&self) -> MeshData {
        let rr = self.main_radius;
        let (around, along, half) = (64usize, 16usize, 0.4);
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..=along {
            let x = -half + 2.0 * half * i as f64 / along as f64;
            for j in 0..around {
                let a = 2.0 * PI * j as f64 / around as f64;
                vertices.push([x, rr * a.cos(), rr * a.sin()]);
            }
        }
        let id = |i: usize, j: usize| (i * around + j % around) as u32;
        for i in 0..along {
            for j in 0..around {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mut mesh = MeshData {
            vertices,
            triangles,
        };
        if let Some((y, t, top)) = self.rib {
            let bottom = (rr * rr - (y + t).powi(2)).max(0.0).sqrt() - 0.005;
            mesh.append(&MeshData::cuboid([-half, y, bottom], [half, y + t, top]))
                .expect("the rib fits");
        }
        mesh
    }

    /// The cut request at `feedrate` (m/s) with lead and tilt allowances of 10°, the mesh at
    /// `mesh` (a path or URI), the workpiece centred at (0.8, 0.7, 0.5) m, automatic RTOs every
    /// 5 cm.
    pub fn request(&self, mesh: &str, feedrate: f64) -> CutRequest {
        let (points, axes) = self.path();
        CutRequest {
            start: Default::default(),
            request_id: "saddle".into(),
            points,
            axes,
            feedrate,
            feed_acceleration: 8.0,
            feed_jerk: 80.0,
            sample_period: 0.004,
            max_lead_angle: 10f64.to_radians(),
            max_tilt_angle: 10f64.to_radians(),
            mesh: mesh.into(),
            workpiece_pose: kerf_mjto::request::PoseSpec {
                position: [0.8, 0.7, 0.5],
                orientation: [0.0, 0.0, 0.0, 1.0],
            },
            options: CutOptions {
                max_iterations: 20,
                // An RTO every 5 cm (about 25 per loop): the nominal axis turns by 30° within a
                // quarter loop, more than the 10° allowance.
                rto_spacing: 0.05,
                ..CutOptions::default()
            },
            time_budget: 0.0,
        }
    }
}

/// A mesh file in the temporary directory, removed on drop.
pub struct TempMesh(pub PathBuf);

impl TempMesh {
    /// Writes `mesh` as OBJ under a name unique to this process and `tag`.
    pub fn new(tag: &str, mesh: &MeshData) -> Self {
        let path =
            std::env::temp_dir().join(format!("kerf_mjto_saddle_{}_{tag}.obj", std::process::id()));
        write_obj(&path, mesh).expect("write the saddle mesh");
        Self(path)
    }

    /// The path as a request's mesh reference.
    pub fn reference(&self) -> String {
        self.0.to_string_lossy().into_owned()
    }
}

impl Drop for TempMesh {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}
