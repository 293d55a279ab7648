//! A rolled sheet: a cylindrical panel, convex towards the head, crown along x.

use nalgebra::{Vector2, Vector3};

use super::part::{sag, Part};
use super::sheet::{thick_sheet, SheetGrid};
use crate::TestPartError;

/// A cylindrical panel of radius `radius` about the line y = 0, z = −radius: crown at z = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelParams {
    /// Bending radius of the head-side surface (m). Default 0.5.
    pub radius: f64,
    /// Sheet thickness (m). Default 2 mm.
    pub thickness: f64,
    /// Developed width across the crown (m), centred on it. Default 0.5.
    pub width: f64,
    /// Length along x (m), centred on 0. Default 0.4.
    pub length: f64,
    /// Facets across the width. Default 80.
    pub facets: usize,
}

impl Default for PanelParams {
    fn default() -> Self {
        Self {
            radius: 0.5,
            thickness: 0.002,
            width: 0.5,
            length: 0.4,
            facets: 80,
        }
    }
}

impl PanelParams {
    /// The surface point and head-side normal at developed coordinates (x, s), s the arc
    /// length from the crown: φ = s / R, `(x, R sin φ, R cos φ − R)`, `(0, sin φ, cos φ)`.
    /// Lengths on the panel equal lengths in (x, s) (a cylinder develops isometrically).
    pub fn surface(&self, d: Vector2<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let (s, c) = (d.y / self.radius).sin_cos();
        (
            Vector3::new(d.x, self.radius * s, self.radius * c - self.radius),
            Vector3::new(0.0, s, c),
        )
    }

    /// The panel.
    ///
    /// # Errors
    /// [`TestPartError::Invalid`] for a radius not above the thickness, a width over a half
    /// turn, fewer than 4 facets, or a mesh over the triangle limit.
    pub fn part(&self) -> Result<Part, TestPartError> {
        if !(self.radius > self.thickness
            && self.thickness > 0.0
            && self.width > 0.0
            && self.width < std::f64::consts::PI * self.radius
            && self.length > 0.0)
            || self.facets < 4
        {
            return Err(TestPartError::invalid("panel", format!("{self:?}")));
        }
        let mut points = Vec::new();
        let mut normals = Vec::new();
        for i in 0..=self.facets {
            let s = self.width * (i as f64 / self.facets as f64 - 0.5);
            for j in 0..3 {
                let x = self.length * (j as f64 / 2.0 - 0.5);
                let (p, n) = self.surface(Vector2::new(x, s));
                points.push(p);
                normals.push(n);
            }
        }
        let grid = SheetGrid {
            nu: self.facets + 1,
            nv: 3,
            periodic_u: false,
            points,
            normals,
        };
        let step = self.width / self.facets as f64 / self.radius;
        Ok(Part {
            name: "panel",
            mesh: thick_sheet(&grid, self.thickness)?,
            thickness: self.thickness,
            surface_tolerance: sag(self.radius, step),
            axis_tolerance: step + 1e-9,
        })
    }
}
