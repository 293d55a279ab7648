//! Setting up one plan: the path frames, feed profile and sample times, the
//! nominal orientation, the initial RTOs and their GFDs.

use kerf_budget::Budget;
use nalgebra::Vector3;

use super::Context;
use crate::gfd::Gfd;
use crate::kinematics::rotary_ikt;
use crate::machine::JOINT_NAMES;
use crate::orientation::PathFrames;
use crate::request::ValidatedRequest;
use crate::timelaw::{TimeLaw, MAX_SAMPLES};
use crate::{CutRequest, LaserMachine, PlanError};

impl<'a> Context<'a> {
    pub(super) fn new(
        machine: &'a LaserMachine,
        request: &'a CutRequest,
        v: &'a ValidatedRequest,
        budget: Budget,
    ) -> Result<Self, PlanError> {
        let frames = PathFrames::new(&v.points, &v.axes, &v.u);
        let law = TimeLaw::new(
            v.sigma,
            request.feedrate,
            request.feed_acceleration,
            request.feed_jerk,
        )?
        .on_grid(request.sample_period)?;
        let sample_times = law.checked_sample_times(request.sample_period, MAX_SAMPLES)?;
        let limits = machine.limits();
        let standoff = request.options.reference_standoff;
        if standoff < limits[5].min || standoff > limits[5].max {
            return Err(PlanError::invalid(
                "options.reference_standoff",
                format!(
                    "{standoff} m is outside the q6 stroke [{}, {}] m",
                    limits[5].min, limits[5].max
                ),
            ));
        }
        let mut nominal = Vec::with_capacity(v.points.len());
        let mut previous = None;
        for (i, (c, o)) in v.points.iter().zip(&v.axes).enumerate() {
            let (q4, q5) = rotary_ikt(
                o,
                previous,
                (limits[3].min, limits[3].max),
                (limits[4].min, limits[4].max),
            )
            .map_err(|e| PlanError::Unreachable {
                index: i,
                reason: e.to_string(),
            })?;
            previous = Some(q4);
            // The M point of the nominal orientation at the reference
            // standoff must be inside the stroke of q1..q3 (eq. 3).
            let m = c - standoff * o;
            for (a, joint) in limits.iter().take(3).enumerate() {
                let x = m[a];
                if x < joint.min || x > joint.max {
                    let by = if x < joint.min {
                        joint.min - x
                    } else {
                        x - joint.max
                    };
                    return Err(PlanError::Unreachable {
                        index: i,
                        reason: format!(
                            "{} = {x:.4} m is outside [{}, {}] m by {by:.4} m (nominal axis, standoff {standoff} m)",
                            JOINT_NAMES[a], joint.min, joint.max
                        ),
                    });
                }
            }
            nominal.push((q4, q5));
        }
        Ok(Self {
            machine,
            request,
            v,
            frames,
            law,
            sample_times,
            nominal,
            budget,
        })
    }

    pub(super) fn limits(&self) -> &[crate::AxisLimits; 6] {
        self.machine.limits()
    }

    /// Initial RTO indices: the request's, or automatic ones.
    ///
    /// Automatic: the first and last CL point, plus a point wherever the
    /// path length since the previous RTO reaches `rto_spacing` or the
    /// nominal axis has turned by `rto_angle` since it.
    pub(super) fn initial_rto_indices(&self) -> Vec<usize> {
        let o = &self.request.options;
        if !o.rto_indices.is_empty() {
            return o.rto_indices.clone();
        }
        let n = self.v.points.len();
        let mut idx = vec![0];
        for i in 1..n - 1 {
            let last = idx[idx.len() - 1];
            let ds = self.v.arc_length[i] - self.v.arc_length[last];
            let angle = self.v.axes[i].angle(&self.v.axes[last]);
            if ds >= o.rto_spacing || angle >= o.rto_angle {
                idx.push(i);
            }
        }
        // Do not crowd the end: a last automatic RTO closer than a quarter
        // spacing to the end is replaced by the end point.
        if idx.len() > 1 {
            let last = idx[idx.len() - 1];
            if self.v.arc_length[n - 1] - self.v.arc_length[last] < 0.25 * o.rto_spacing {
                idx.pop();
            }
        }
        idx.push(n - 1);
        idx
    }

    pub(super) fn reference(&self, i: usize) -> [f64; 3] {
        let (q4, q5) = self.nominal[i];
        [q4, q5, self.request.options.reference_standoff]
    }

    pub(super) fn build_gfd(&self, i: usize, reference: [f64; 3]) -> Gfd {
        let r = self.request;
        let frames = &self.frames;
        Gfd::build(
            i,
            self.v.u[i],
            &self.v.points[i],
            reference,
            &r.options.gfd,
            &r.options.weights,
            r.max_lead_angle,
            r.max_tilt_angle,
            &|o: &Vector3<f64>| frames.lead_tilt_at(i, o),
            self.limits(),
        )
    }
}
