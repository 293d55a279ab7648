//! Holes and slots on curved sheet: round holes and an obround slot on the rolled panel.

use nalgebra::Vector2;

use super::case::{Expectation, JobShopCase, Process};
use super::contour::Outline;
use super::panel::PanelParams;
use super::part::Part;
use crate::TestPartError;

/// The hole and slot cases on the panel (developed coordinates (x, s), s from the crown):
/// a Ø40 hole on the crown and a Ø30 hole 170 mm down the side (normal 19.5° from the
/// crown's) at 6 m/min, an 80 × 16 mm obround slot at 30° to the crown line, 120 mm down
/// the other side, at 8 m/min; Δt 4 ms, 10°/10°.
///
/// # Errors
/// Only for inconsistent defaults.
pub(super) fn hole_cases(
    panel: &PanelParams,
    part: &Part,
) -> Result<Vec<JobShopCase>, TestPartError> {
    let cases = [
        (
            "panel_hole_crown",
            "Ø40 mm round hole on the crown of the R500 rolled 2 mm panel; 6 m/min, 10°/10°",
            Outline::circle(Vector2::new(0.0, 0.0), 0.02),
            Process::shop(6.0, 4.0, 10.0, 10.0),
        ),
        (
            "panel_hole_side",
            "Ø30 mm round hole 170 mm down the side of the R500 rolled panel (normal 19.5° \
             off the crown's); 6 m/min, 10°/10°",
            Outline::circle(Vector2::new(0.08, 0.17), 0.015),
            Process::shop(6.0, 4.0, 10.0, 10.0),
        ),
        (
            "panel_slot",
            "80 × 16 mm obround slot at 30° to the crown line, 120 mm down the side of the R500 \
             rolled panel; 8 m/min, 10°/10°",
            Outline::obround(Vector2::new(-0.08, -0.12), 0.08, 0.016, 30f64.to_radians()),
            Process::shop(8.0, 4.0, 10.0, 10.0),
        ),
    ];
    cases
        .into_iter()
        .map(|(name, title, outline, process)| {
            let curve = |t: f64| panel.surface(outline.at(t));
            JobShopCase::cut(
                name,
                title.to_owned(),
                part,
                &curve,
                outline.closed,
                process,
                Expectation::Plan,
            )
        })
        .collect()
}
