//! Everything a feed plan must respect (issue 14, item 3): the feed and
//! curvature limits of seed 003 with the tangential acceleration and jerk
//! ([`FeedLimits`]), optional per-axis limits ([`AxisLimits`]) and optional
//! per-sample programmed feeds (G-code changing F along the path).

use crate::axis::AxisLimits;
use crate::feed::FeedLimits;
use crate::samples::{check_samples, PathSample};
use crate::ToolpathError;

/// The constraints of one feed plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeedConstraints<'a> {
    /// F, the curvature limits and the tangential acceleration and jerk.
    pub limits: FeedLimits,
    /// Per-axis speed, acceleration and jerk (`None`: not limited).
    pub axes: Option<AxisLimits>,
    /// The programmed feed of every sample \[m/s\], one per sample; between
    /// two samples the lower of their two feeds holds (`None`: F only).
    pub caps: Option<&'a [f64]>,
    /// Bound the whole jerk of the normal acceleration vector at constant
    /// speed, v³ √(κ′² + κ⁴) (κ′ = dκ/ds, [`crate::corner_jerk`]), by the
    /// normal jerk limit instead of seed 003 eq. 21's v³ κ² alone
    /// ([`crate::limit_curve`](mod@crate::limit_curve)); `false`: eq. 21.
    pub whole_normal_jerk: bool,
}

impl<'a> FeedConstraints<'a> {
    /// The limits alone: no axis limits, no per-sample feeds.
    pub fn new(limits: FeedLimits) -> Self {
        Self {
            limits,
            axes: None,
            caps: None,
            whole_normal_jerk: false,
        }
    }

    /// Checks the limits, the axes and the caps against `samples`.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming a limit that is not finite
    /// and > 0, caps of another count than the samples, fewer than two
    /// samples or an arc length that does not increase.
    pub fn validate(&self, samples: &[PathSample]) -> Result<(), ToolpathError> {
        self.limits.validate()?;
        if let Some(axes) = &self.axes {
            axes.validate()?;
        }
        check_samples(samples)?;
        if let Some(caps) = self.caps {
            if caps.len() != samples.len() {
                return Err(ToolpathError::InvalidParameter {
                    name: "feed caps".to_string(),
                    value: caps.len() as f64,
                    reason: format!("one per sample ({})", samples.len()),
                });
            }
            if let Some((k, v)) = caps
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v > 0.0))
            {
                return Err(ToolpathError::InvalidParameter {
                    name: format!("feed cap of sample {k} [m/s]"),
                    value: *v,
                    reason: "must be finite and > 0".to_string(),
                });
            }
        }
        if let Some((k, p)) = samples
            .iter()
            .enumerate()
            .find(|(_, p)| !(p.curvature.is_finite() && p.curvature >= 0.0))
        {
            return Err(ToolpathError::InvalidParameter {
                name: format!("curvature of sample {k} [1/m]"),
                value: p.curvature,
                reason: "must be finite and >= 0".to_string(),
            });
        }
        Ok(())
    }

    /// The tangential acceleration and jerk a plan may use: A_t and J_t,
    /// or less under axis limits ([`AxisLimits::tangential`]).
    pub fn tangential(&self) -> (f64, f64) {
        let (a, j) = (
            self.limits.tangential_acceleration,
            self.limits.tangential_jerk,
        );
        match &self.axes {
            Some(axes) => axes.tangential(a, j),
            None => (a, j),
        }
    }

    /// The feed cap between samples `k` and `k + 1` (the lower of the two),
    /// or at sample `k` when `k + 1` is out of range; infinite without caps.
    pub fn cap_between(&self, k: usize) -> f64 {
        match self.caps {
            Some(c) => c[k].min(*c.get(k + 1).unwrap_or(&c[k])),
            None => f64::INFINITY,
        }
    }
}
