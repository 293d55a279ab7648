//! [`LaserSheet`]: the laser cutter over a flat sheet.

use kerf_mjto::kinematics::forward;
use kerf_mjto::LaserMachine;
use kerf_robot::RobotModel;

use super::{bounds_of, check_finite, JointBounds, Machine, DOF};
use crate::error::GcodePlanError;

/// Where the program's zero lies in the machine frame by default \[m\]: 0.3 m
/// in from the table's corner in x and y, on a sheet surface 0.5 m up
/// (kerf's choice: q1 ∈ [0, 1.6], q2 ∈ [0, 1.4] leave a program −0.3..1.3 m
/// by −0.3..1.1 m).
pub const DEFAULT_SHEET_ORIGIN: [f64; 3] = [0.3, 0.3, 0.5];

/// The standoff axis q6 by default \[m\]: the CL point 80 mm below the rotary
/// centre M, so that the tilt housing (radius 45 mm about M) clears the
/// sheet by 35 mm (`urdf/laser_cutter.urdf`: for q6 > −0.045 the housing
/// touches a part the tip cuts).
pub const DEFAULT_STANDOFF_AXIS: f64 = -0.08;

/// The laser cutter (seed 001) cutting a flat sheet with a vertical beam.
///
/// Seed 001 eq. 2: C = M + q6 O, M = (q1, q2, q3), O = Rz(q4) Ry(q5) ẑ. With
/// q4 = q5 = 0, O = ẑ and the CL point C = origin + p of a program point p is
/// reached by (q1, q2, q3) = C − q6 ẑ: the gantry axes trace the path.
#[derive(Debug, Clone)]
pub struct LaserSheet {
    machine: LaserMachine,
    origin: [f64; 3],
    standoff_axis: f64,
    bounds: [JointBounds; DOF],
}

impl LaserSheet {
    /// The shipped machine with [`DEFAULT_SHEET_ORIGIN`] and
    /// [`DEFAULT_STANDOFF_AXIS`].
    ///
    /// # Errors
    /// As [`LaserMachine::default_machine`] and [`LaserSheet::new`].
    pub fn default_sheet() -> Result<Self, GcodePlanError> {
        let machine =
            LaserMachine::default_machine().map_err(|e| GcodePlanError::InvalidRequest {
                field: "machine".to_string(),
                reason: e.to_string(),
            })?;
        Self::new(machine, DEFAULT_SHEET_ORIGIN, DEFAULT_STANDOFF_AXIS)
    }

    /// A sheet whose program zero is `origin` (machine frame, on the sheet
    /// surface) cut with the standoff axis at `standoff_axis`.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] for a non-finite origin, a
    /// standoff outside q6's stroke, or limits the model lacks.
    pub fn new(
        machine: LaserMachine,
        origin: [f64; 3],
        standoff_axis: f64,
    ) -> Result<Self, GcodePlanError> {
        check_finite("sheet origin [m]", &origin)?;
        check_finite("standoff axis q6 [m]", &[standoff_axis])?;
        let q6 = machine.limits()[5];
        if standoff_axis < q6.min || standoff_axis > q6.max {
            return Err(GcodePlanError::InvalidSetting {
                name: "standoff axis q6 [m]".to_string(),
                value: standoff_axis,
                reason: format!("outside its stroke [{}, {}] m", q6.min, q6.max),
            });
        }
        let bounds = bounds_of(machine.robot())?;
        Ok(Self {
            machine,
            origin,
            standoff_axis,
            bounds,
        })
    }

    /// The program zero in the machine frame \[m\].
    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }
}

impl Machine for LaserSheet {
    fn name(&self) -> &str {
        "laser-cutter"
    }

    fn robot(&self) -> &RobotModel {
        self.machine.robot()
    }

    fn bounds(&self) -> &[JointBounds; DOF] {
        &self.bounds
    }

    fn joints(&self, point: [f64; 3], _: Option<&[f64; DOF]>) -> Result<[f64; DOF], String> {
        let limits = self.machine.limits();
        let mut q = [0.0, 0.0, 0.0, 0.0, 0.0, self.standoff_axis];
        for k in 0..3 {
            let v = self.origin[k] + point[k] - if k == 2 { self.standoff_axis } else { 0.0 };
            if !v.is_finite() {
                return Err(format!("q{} = {v} is not finite", k + 1));
            }
            let l = &limits[k];
            if v < l.min || v > l.max {
                return Err(format!(
                    "q{} = {v:.6} m is outside its stroke [{}, {}] m",
                    k + 1,
                    l.min,
                    l.max
                ));
            }
            q[k] = v;
        }
        Ok(q)
    }

    /// q1, q2, q3 are the program's X, Y, Z (a translation apart).
    fn axis_limits(&self) -> Option<kerf_toolpath::AxisLimits> {
        let b = &self.bounds;
        Some(kerf_toolpath::AxisLimits {
            velocity: [b[0].velocity, b[1].velocity, b[2].velocity],
            acceleration: [b[0].acceleration, b[1].acceleration, b[2].acceleration],
            jerk: [b[0].jerk, b[1].jerk, b[2].jerk],
        })
    }

    fn tip(&self, q: &[f64; DOF]) -> Result<[f64; 3], String> {
        if q.iter().any(|v| !v.is_finite()) {
            return Err(format!("joint vector {q:?} is not finite"));
        }
        let (c, _) = forward(q);
        Ok([
            c.x - self.origin[0],
            c.y - self.origin[1],
            c.z - self.origin[2],
        ])
    }
}
