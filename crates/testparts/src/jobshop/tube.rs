//! The main tube of the saddle cuts: a round tube along the workpiece x axis.

use nalgebra::Vector3;

use super::part::{sag, Part};
use super::sheet::{thick_sheet, SheetGrid};
use crate::TestPartError;

/// A round tube along x, centred on the origin: outer radius, wall, length, facets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TubeParams {
    /// Outer radius R (m). Default 0.05 (a Ø100 mm tube).
    pub radius: f64,
    /// Wall thickness (m). Default 3 mm.
    pub wall: f64,
    /// Length along x (m), from −length/2 to length/2. Default 0.5.
    pub length: f64,
    /// Facets around the circumference. Default 256 (sag 3.8 µm).
    pub facets: usize,
    /// Stations along x (≥ 2). Default 3.
    pub stations: usize,
}

impl Default for TubeParams {
    fn default() -> Self {
        Self {
            radius: 0.05,
            wall: 0.003,
            length: 0.5,
            facets: 256,
            stations: 3,
        }
    }
}

impl TubeParams {
    /// The outer surface point and outward normal at angle θ from +z towards +y and axial
    /// position x: `(x, R sin θ, R cos θ)`, `(0, sin θ, cos θ)`.
    pub fn surface(&self, theta: f64, x: f64) -> (Vector3<f64>, Vector3<f64>) {
        let (s, c) = theta.sin_cos();
        (
            Vector3::new(x, self.radius * s, self.radius * c),
            Vector3::new(0.0, s, c),
        )
    }

    /// The tube.
    ///
    /// # Errors
    /// [`TestPartError::Invalid`] for a wall not thinner than the radius, fewer than 16
    /// facets, or a mesh over the triangle limit.
    pub fn part(&self) -> Result<Part, TestPartError> {
        if !(self.radius > self.wall && self.wall > 0.0 && self.length > 0.0)
            || self.facets < 16
            || self.stations < 2
        {
            return Err(TestPartError::invalid("tube", format!("{self:?}")));
        }
        let mut points = Vec::new();
        let mut normals = Vec::new();
        for i in 0..self.facets {
            let theta = std::f64::consts::TAU * i as f64 / self.facets as f64;
            for j in 0..self.stations {
                let x = self.length * (j as f64 / (self.stations - 1) as f64 - 0.5);
                let (p, n) = self.surface(theta, x);
                points.push(p);
                normals.push(n);
            }
        }
        let grid = SheetGrid {
            nu: self.facets,
            nv: self.stations,
            periodic_u: true,
            points,
            normals,
        };
        let step = std::f64::consts::TAU / self.facets as f64;
        Ok(Part {
            name: "tube",
            mesh: thick_sheet(&grid, self.wall)?,
            thickness: self.wall,
            surface_tolerance: sag(self.radius, step),
            axis_tolerance: step + 1e-9,
        })
    }
}
