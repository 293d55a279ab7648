//! From file sections to models: the TCP from its axes, the chatter
//! indicator settings and the milling process with its state limits.

use kerf_chatter::indicator::{DelayModel, IndicatorSettings};
use kerf_chatter::MillingProcess;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::file::{ChatterSection, ProcessSection, TcpSection};
use super::StateLimits;
use crate::error::{check_finite, check_positive, MillError};

/// The TCP isometry from a position and the tool's z and x axes in `tool0`.
pub(super) fn tcp_from_axes(t: &TcpSection) -> Result<Isometry3<f64>, MillError> {
    for (name, v) in [
        ("tcp.position", t.position),
        ("tcp.z_axis", t.z_axis),
        ("tcp.x_axis", t.x_axis),
    ] {
        for (i, c) in v.iter().enumerate() {
            check_finite(&format!("{name}[{i}]"), *c)?;
        }
    }
    let z = Vector3::from(t.z_axis);
    let x = Vector3::from(t.x_axis);
    for (name, v) in [("tcp.z_axis", &z), ("tcp.x_axis", &x)] {
        if (v.norm() - 1.0).abs() > 1e-9 {
            return Err(MillError::InvalidParameter {
                name: format!("{name} (norm)"),
                value: v.norm(),
                reason: "must be a unit vector".to_string(),
            });
        }
    }
    if x.dot(&z).abs() > 1e-9 {
        return Err(MillError::InvalidParameter {
            name: "tcp.x_axis . tcp.z_axis".to_string(),
            value: x.dot(&z),
            reason: "the axes must be perpendicular".to_string(),
        });
    }
    let r = Matrix3::from_columns(&[x, z.cross(&x), z]);
    Ok(Isometry3::from_parts(
        Translation3::from(Vector3::from(t.position)),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
    ))
}

/// The indicator settings of the `chatter` section (module documentation
/// of `kerf_chatter::indicator`); the paper's model when it is absent.
pub(super) fn indicator_from(c: Option<&ChatterSection>) -> Result<IndicatorSettings, MillError> {
    let Some(c) = c else {
        return Ok(IndicatorSettings::default());
    };
    let model = match c.model.as_str() {
        "state_dependent" => DelayModel::StateDependent,
        "constant" => DelayModel::Constant,
        other => {
            return Err(MillError::InvalidConfig {
                name: "chatter.model".to_string(),
                reason: format!("`{other}`: must be `state_dependent` or `constant`"),
            })
        }
    };
    if !(c.force_exponent.is_finite() && c.force_exponent > 0.0 && c.force_exponent <= 1.0) {
        return Err(MillError::InvalidParameter {
            name: "chatter.force_exponent [-]".to_string(),
            value: c.force_exponent,
            reason: "must be in (0, 1]".to_string(),
        });
    }
    check_positive("chatter.reference_chip [m]", c.reference_chip)?;
    let settings = IndicatorSettings::default()
        .model(model)
        .steps(c.steps)
        .force_law(c.force_exponent, c.reference_chip)
        .wall_term(c.wall_term);
    settings.validate()?;
    Ok(settings)
}

pub(super) fn process_from(p: &ProcessSection) -> Result<(MillingProcess, StateLimits), MillError> {
    use std::f64::consts::PI;
    for (i, v) in p.engagement_over_pi.iter().enumerate() {
        if !(v.is_finite() && (0.0..=1.0).contains(v)) {
            return Err(MillError::InvalidParameter {
                name: format!("process.engagement_over_pi[{i}]"),
                value: *v,
                reason: "must be in [0, 1] (fraction of pi)".to_string(),
            });
        }
    }
    let process = MillingProcess {
        teeth: p.teeth,
        radius: p.tool_radius,
        axial_depth: p.axial_depth,
        kt: p.kt,
        kn: p.kn,
        entry_angle: p.engagement_over_pi[0] * PI,
        exit_angle: p.engagement_over_pi[1] * PI,
    };
    process.validate()?;
    let range = |name: &str, r: [f64; 2], min: f64| -> Result<[f64; 2], MillError> {
        for (i, v) in r.iter().enumerate() {
            check_finite(&format!("{name}[{i}]"), *v)?;
        }
        if r[0] < min || r[1] <= r[0] {
            return Err(MillError::InvalidParameter {
                name: format!("{name}[1]"),
                value: r[1],
                reason: format!(
                    "the range must satisfy {min} <= [0] < [1] (got [0] = {})",
                    r[0]
                ),
            });
        }
        Ok(r)
    };
    let spindle_rpm = range("process.spindle_rpm", p.spindle_rpm, 0.0)?;
    check_positive("process.spindle_rpm[0] [rpm]", spindle_rpm[0])?;
    let feed = range("process.feed", p.feed, 0.0)?;
    let redundancy_angle = range("process.redundancy_angle", p.redundancy_angle, -PI - 1e-12)?;
    if redundancy_angle[1] > PI + 1e-12 {
        return Err(MillError::InvalidParameter {
            name: "process.redundancy_angle[1]".to_string(),
            value: redundancy_angle[1],
            reason: "must be <= pi".to_string(),
        });
    }
    let limits = StateLimits {
        spindle_rpm,
        feed,
        redundancy_angle,
        max_feed_step: check_positive("process.step_bounds.feed [m/s]", p.step_bounds.feed)?,
        max_spindle_step_rpm: check_positive(
            "process.step_bounds.spindle_rpm [rpm]",
            p.step_bounds.spindle_rpm,
        )?,
        max_redundancy_step: check_positive(
            "process.step_bounds.redundancy_angle [rad]",
            p.step_bounds.redundancy_angle,
        )?,
    };
    Ok((process, limits))
}
