//! The MJTO loop of seed 001 Figure 6 (being written).

use crate::{CutPlan, CutRequest, LaserMachine, PlanError};

/// A planner bound to one machine; keeps a cache of workpiece meshes.
pub struct Planner {
    machine: LaserMachine,
}

impl Planner {
    /// A planner for `machine`.
    pub fn new(machine: LaserMachine) -> Result<Self, PlanError> {
        Ok(Self { machine })
    }

    /// The machine this planner plans for.
    pub fn machine(&self) -> &LaserMachine {
        &self.machine
    }

    /// Plans one cut request.
    pub fn plan(&mut self, request: &CutRequest) -> Result<CutPlan, PlanError> {
        request.validate()?;
        Err(PlanError::Solver { problem: "planner".into(), detail: "the MJTO loop is being written".into() })
    }
}
