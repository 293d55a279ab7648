//! What the approach and retract of a G-code plan keep clear of, per machine (issue 27).
//!
//! | machine | surroundings |
//! |---|---|
//! | `laser-cutter` | the cutting head against the sheet under the program ([`crate::sheet`]) |
//! | `irb6660` | the robot and its spindle against the objects of a kerf_cell cell file, by default the shipped `urdf/cells/irb6660_plate.yaml` (stock and fixture plate under the milling plane; [`kerf_cell::CellSurroundings`], the milling planner's) |

use std::path::Path;

use kerf_approach::{JointLimit, Surroundings};
use kerf_cell::CellSurroundings;
use kerf_gcodeplan::{GcodePlanError, GcodeRequest, MachineBase};
use kerf_mjto::collision::HeadModel;

use crate::sheet::SheetSurroundings;

/// The surroundings of one machine, loaded at start-up.
#[derive(Debug)]
pub enum MachineSurroundings {
    /// The laser cutter's head (the sheet is each request's).
    Laser(HeadModel),
    /// The IRB 6660 in its collision cell (the same for every request).
    Irb(CellSurroundings),
}

impl MachineSurroundings {
    /// The surroundings of `machine`; `cell_file` is the IRB 6660's collision cell (`None`:
    /// the shipped one).
    ///
    /// # Errors
    /// A sentence naming what does not load: the head model of the laser cutter's URDF, the
    /// collision cell; a `cell_file` given for the laser cutter.
    pub fn load(machine: &MachineBase, cell_file: Option<&Path>) -> Result<Self, String> {
        match machine {
            MachineBase::Laser(m) => {
                if let Some(path) = cell_file {
                    return Err(format!(
                        "{} is for machine irb6660: the laser cutter's surroundings are the \
                         sheet under each request's program",
                        path.display()
                    ));
                }
                HeadModel::from_urdf(m.robot().urdf())
                    .map(MachineSurroundings::Laser)
                    .map_err(|e| e.to_string())
            }
            MachineBase::Irb(cell) => kerf_cell::milling_surroundings(cell, cell_file)
                .map(MachineSurroundings::Irb)
                .map_err(|e| e.to_string()),
        }
    }

    /// Where it came from, for the start-up log.
    pub fn source(&self) -> String {
        match self {
            MachineSurroundings::Laser(_) => "the head over each program's sheet".into(),
            MachineSurroundings::Irb(c) => format!("collision cell {}", c.source()),
        }
    }

    /// The surroundings of `request`.
    ///
    /// # Errors
    /// For the laser cutter, as [`SheetSurroundings::new`].
    pub fn for_request(
        &self,
        limits: &[JointLimit],
        request: &GcodeRequest,
    ) -> Result<Box<dyn Surroundings>, GcodePlanError> {
        match self {
            MachineSurroundings::Laser(head) => Ok(Box::new(SheetSurroundings::new(
                head.clone(),
                limits.to_vec(),
                request,
            )?)),
            MachineSurroundings::Irb(cell) => Ok(Box::new(cell.clone())),
        }
    }
}
