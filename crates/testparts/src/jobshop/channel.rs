//! Press-brake parts with walls next to the cuts: a U channel with top flanges and an angle
//! with one tall wall. Both are profiles in the (y, z) plane extruded along x from 0.

use nalgebra::Vector2;

use super::part::{sag, Part};
use super::profile::{bent_profile, extrude};
use super::sheet::thick_sheet;
use crate::TestPartError;

/// Chords per bend of the profiles.
const BEND_SEGMENTS: usize = 8;

/// Stations along the extrusion.
const STATIONS: usize = 3;

/// A U channel: floor (head side z = 0) between walls whose inner faces are y = ±width/2,
/// walls up to the top surface of the outward flanges at z = height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelParams {
    /// Inner width between the walls (m). Default 0.3.
    pub width: f64,
    /// Height of the flanges' top surface above the floor (m). Default 0.12.
    pub height: f64,
    /// Flange width from the wall's inner face (m). Default 0.06.
    pub flange: f64,
    /// Sheet thickness (m). Default 3 mm.
    pub thickness: f64,
    /// Head-side bend radius (m). Default 6 mm (2 t).
    pub bend_radius: f64,
    /// Length along x (m). Default 0.5.
    pub length: f64,
}

impl Default for ChannelParams {
    fn default() -> Self {
        Self {
            width: 0.3,
            height: 0.12,
            flange: 0.06,
            thickness: 0.003,
            bend_radius: 0.006,
            length: 0.5,
        }
    }
}

impl ChannelParams {
    /// The channel.
    ///
    /// # Errors
    /// [`TestPartError::Invalid`] from the profile (pieces too short for the bends, radius
    /// not above the thickness) or the mesh size.
    pub fn part(&self) -> Result<Part, TestPartError> {
        let (w, h, f) = (self.width / 2.0, self.height, self.flange);
        let corners = [
            Vector2::new(-w - f, h),
            Vector2::new(-w, h),
            Vector2::new(-w, 0.0),
            Vector2::new(w, 0.0),
            Vector2::new(w, h),
            Vector2::new(w + f, h),
        ];
        profile_part(
            "channel",
            &corners,
            self.bend_radius,
            self.thickness,
            self.length,
        )
    }
}

/// An angle: floor (head side z = 0) for y in [−floor, 0] and a wall whose inner face is
/// y = 0, up to z = height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleParams {
    /// Floor width from the wall's inner face (m). Default 0.3.
    pub floor: f64,
    /// Wall height above the floor (m). Default 0.3.
    pub height: f64,
    /// Thickness (m). Default 4 mm.
    pub thickness: f64,
    /// Head-side bend radius (m). Default 8 mm (2 t).
    pub bend_radius: f64,
    /// Length along x (m). Default 1.2.
    pub length: f64,
}

impl Default for AngleParams {
    fn default() -> Self {
        Self {
            floor: 0.3,
            height: 0.3,
            thickness: 0.004,
            bend_radius: 0.008,
            length: 1.2,
        }
    }
}

impl AngleParams {
    /// The angle.
    ///
    /// # Errors
    /// As [`ChannelParams::part`].
    pub fn part(&self) -> Result<Part, TestPartError> {
        let corners = [
            Vector2::new(-self.floor, 0.0),
            Vector2::new(0.0, 0.0),
            Vector2::new(0.0, self.height),
        ];
        profile_part(
            "angle",
            &corners,
            self.bend_radius,
            self.thickness,
            self.length,
        )
    }
}

/// A bent profile extruded into a closed thin solid. CL paths stay on the flat pieces, so the
/// mesh is exact there (tolerances of rounding only).
fn profile_part(
    name: &'static str,
    corners: &[Vector2<f64>],
    radius: f64,
    thickness: f64,
    length: f64,
) -> Result<Part, TestPartError> {
    if !(length.is_finite() && length > 0.0) {
        return Err(TestPartError::invalid(name, format!("length {length}")));
    }
    let profile = bent_profile(corners, radius, thickness, BEND_SEGMENTS)?;
    let grid = extrude(&profile, length, STATIONS);
    Ok(Part {
        name,
        mesh: thick_sheet(&grid, thickness)?,
        thickness,
        surface_tolerance: sag(0.0, 0.0),
        axis_tolerance: 1e-9,
    })
}
