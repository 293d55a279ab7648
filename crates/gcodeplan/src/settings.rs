//! [`PlanSettings`]: the tolerance, its split, the path limits and the
//! trajectory's density (builder, validated).

use kerf_gcode::ReaderSettings;
use kerf_toolpath::{CornerMethod, CurvatureLimits, FeedLimits, FeedMethod, Sampling, Servo};

use crate::error::{check_positive, setting, GcodePlanError};

/// Settings of [`crate::plan_program`]. SI units.
///
/// # The tolerance and its split
/// The executed tool tip stays within [`PlanSettings::tolerance`] δ of the
/// programmed geometry (lines and arcs). δ is spent in three places, each
/// bounded on its own, so their sum bounds the whole (triangle inequality):
///
/// * δ_a = `approximation_share` · δ: arcs become chords whose sagitta is ≤
///   δ_a / 2 and nearly collinear micro-segments merge within δ_a / 2
///   ([`kerf_toolpath::merge_collinear`]);
/// * δ_i = `interpolation_share` · δ: the executor's quintic Hermite between
///   the trajectory's points, measured by forward kinematics at the control
///   period against the planned point at the same time;
/// * δ_c = δ − δ_a − δ_i: the corner transitions
///   ([`kerf_toolpath::smooth_polyline`], exact deviation), or the program's
///   `G64 P` where that is smaller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// δ: largest distance of the executed tool tip from the programmed
    /// path \[m\].
    pub tolerance: f64,
    /// Share of δ for arcs and merging, in [0, 1).
    pub approximation_share: f64,
    /// Share of δ for the executor's interpolation, in (0, 1).
    pub interpolation_share: f64,
    /// The path's limits for cutting moves; `limits.curvature.feed` is the
    /// machine's largest cutting feed (a programmed F above it is planned at
    /// it, and the plan says so).
    pub limits: FeedLimits,
    /// Speed of G0 moves \[m/s\].
    pub rapid_feed: f64,
    /// How each run's smoothed path is sampled for its feed plan: fixed
    /// 10 µm steps by default. [`Sampling::adaptive`] plans closer to T_lb
    /// on the path, but as executed it is slower on most shipped programs
    /// (the joints' jerk binds more: BENCHMARKS.md, "Sampling the path").
    pub sampling: Sampling,
    /// The executor's control period \[s\] (the trajectory is checked at it).
    pub control_period: f64,
    /// Time between trajectory points before refinement \[s\].
    pub knot_spacing: f64,
    /// Most trajectory points.
    pub max_points: usize,
    /// Most program lines read: a longer program is refused as soon as the line after the
    /// last allowed is read (the planner keeps every run's path in memory, about 1.6 kB per
    /// G01 line of a dense program; BENCHMARKS.md).
    pub max_lines: usize,
    /// How the program is read.
    pub reader: ReaderSettings,
    /// How corners are smoothed (default kerf's quintic); unused when
    /// [`PlanSettings::learned_corners`] is set.
    pub corner_method: CornerMethod,
    /// The `drls-net` method (issue 30, item 3): every corner predicted by seed 003's DRLS
    /// network, verified, and built by its NURBS swarm where the prediction falls back
    /// ([`crate::network`]; default `false`). The plan reads the committed network
    /// ([`crate::network::committed_network`]) unless one is given
    /// ([`crate::plan::plan_program_with`]).
    pub learned_corners: bool,
    /// How the feed is planned (default the near time-optimal planner).
    pub feed_method: FeedMethod,
    /// Whether the feed plan also bounds the machine's Cartesian axes (the laser cutter's
    /// gantry, [`crate::Machine::axis_limits`]) by the chain rule on the exact path (default
    /// `false`). Either way every joint's velocity, acceleration and jerk is held on what the
    /// executor runs (exact peaks of its quintics, a run slowed where needed): the exact path's
    /// axis jerk has spikes of v³ dκ/ds at the small corners that the executed quintics, within
    /// δ_i of the path, do not have, and bounding them costs 4x the time (W-shape 15.8 s
    /// against 3.8 s with the slowdown; BENCHMARKS.md).
    pub feed_axis_limits: bool,
    /// Whether the feed plan bounds the whole jerk of the normal acceleration vector,
    /// v³ √(κ′² + κ⁴), by the normal jerk limit instead of seed 003 eq. 21's v³ κ² alone
    /// ([`kerf_toolpath::FeedConstraints::whole_normal_jerk`]; default `false`). T_lb stays the
    /// bound under seed 003's limits, so T_m/T_lb shows what the extra bound costs.
    pub feed_whole_normal_jerk: bool,
}

impl PlanSettings {
    /// Defaults for the laser cutter (seed 001): δ = 0.1 mm; cutting feed at
    /// most 10 m/min, tangential and normal acceleration 8 m/s² and jerk
    /// 80 m/s³ (seed 001 Table 1's path acceleration and jerk maxima, kerf's
    /// reading); chord error at the 4 ms control period 10 µm; the servo of
    /// seed 003 Table 1 (ω_n 60 rad/s, ζ 0.76) with a contour error of
    /// 0.05 mm; rapids at 0.5 m/s.
    pub fn laser_cutter() -> Self {
        Self::with_limits(
            FeedLimits {
                curvature: CurvatureLimits {
                    feed: 10.0 / 60.0,
                    interpolation_period: 0.004,
                    chord_error: 1e-5,
                    normal_acceleration: 8.0,
                    normal_jerk: 80.0,
                    servo: Some(Servo {
                        natural_frequency: 60.0,
                        damping: 0.76,
                        contour_error: 5e-5,
                    }),
                },
                tangential_acceleration: 8.0,
                tangential_jerk: 80.0,
            },
            0.5,
        )
    }

    /// Defaults for the IRB 6660 milling cell: δ = 0.1 mm; cutting feed at
    /// most 0.06 m/s (seed 004's f_max); the tangential and normal limits of
    /// seed 003 Table 1 (a_t 0.8 m/s², j_t 20 m/s³, a_n 0.99 m/s², j_n
    /// 29 m/s³, servo ω_n 60 rad/s, ζ 0.76, ε 0.05 mm); chord error at the
    /// 4 ms control period 10 µm; rapids at 0.1 m/s.
    pub fn irb6660() -> Self {
        let table = CurvatureLimits::seed_003_table_1();
        Self::with_limits(
            FeedLimits {
                curvature: CurvatureLimits {
                    feed: 0.06,
                    interpolation_period: 0.004,
                    chord_error: 1e-5,
                    ..table
                },
                tangential_acceleration: 0.8,
                tangential_jerk: 20.0,
            },
            0.1,
        )
    }

    fn with_limits(limits: FeedLimits, rapid_feed: f64) -> Self {
        Self {
            tolerance: 1e-4,
            approximation_share: 0.2,
            interpolation_share: 0.1,
            limits,
            rapid_feed,
            sampling: Sampling::default(),
            control_period: 0.004,
            knot_spacing: 0.02,
            max_points: 2_000_000,
            max_lines: 1_000_000,
            reader: ReaderSettings::default(),
            corner_method: CornerMethod::Kerf,
            learned_corners: false,
            feed_method: FeedMethod::NearOptimal,
            feed_axis_limits: false,
            feed_whole_normal_jerk: false,
        }
    }

    /// With δ \[m\].
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// With the path limits.
    pub fn with_limits_of(mut self, limits: FeedLimits) -> Self {
        self.limits = limits;
        self
    }

    /// With the rapid speed \[m/s\].
    pub fn with_rapid_feed(mut self, feed: f64) -> Self {
        self.rapid_feed = feed;
        self
    }

    /// With the most trajectory points.
    pub fn with_max_points(mut self, points: usize) -> Self {
        self.max_points = points;
        self
    }

    /// With the corner method.
    pub fn with_corner_method(mut self, method: CornerMethod) -> Self {
        self.corner_method = method;
        self
    }

    /// With the `drls-net` corners ([`PlanSettings::learned_corners`]) or without.
    pub fn with_learned_corners(mut self, on: bool) -> Self {
        self.learned_corners = on;
        self
    }

    /// With the feed method.
    pub fn with_feed_method(mut self, method: FeedMethod) -> Self {
        self.feed_method = method;
        self
    }

    /// With the most program lines read.
    pub fn with_max_lines(mut self, lines: usize) -> Self {
        self.max_lines = lines;
        self
    }

    /// With the reader's settings.
    pub fn with_reader(mut self, reader: ReaderSettings) -> Self {
        self.reader = reader;
        self
    }

    /// δ_a \[m\] (type documentation).
    pub fn approximation_tolerance(&self) -> f64 {
        self.approximation_share * self.tolerance
    }

    /// δ_i \[m\] (type documentation).
    pub fn interpolation_tolerance(&self) -> f64 {
        self.interpolation_share * self.tolerance
    }

    /// δ_c \[m\] (type documentation).
    pub fn corner_tolerance(&self) -> f64 {
        self.tolerance * (1.0 - self.approximation_share - self.interpolation_share)
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] naming the setting.
    pub fn validate(&self) -> Result<(), GcodePlanError> {
        check_positive(&[
            ("tolerance [m]", self.tolerance),
            ("interpolation share [-]", self.interpolation_share),
            ("rapid feed [m/s]", self.rapid_feed),
            ("control period [s]", self.control_period),
            ("knot spacing [s]", self.knot_spacing),
        ])?;
        match self.sampling {
            Sampling::Fixed { step } => check_positive(&[("sample step [m]", step)])?,
            Sampling::Adaptive { max_step, max_turn } => {
                check_positive(&[("sample step [m]", max_step)])?;
                if !(max_turn > 0.0 && max_turn <= std::f64::consts::FRAC_PI_2) {
                    return Err(invalid(
                        "sample turn [rad]",
                        max_turn,
                        "must be in (0, pi/2]",
                    ));
                }
            }
        }
        if self.tolerance > 0.01 {
            return Err(invalid(
                "tolerance [m]",
                self.tolerance,
                "must be <= 0.01 m: a larger tolerance is not a machining tolerance",
            ));
        }
        if !(0.0..1.0).contains(&self.approximation_share) {
            return Err(invalid(
                "approximation share [-]",
                self.approximation_share,
                "must be in [0, 1)",
            ));
        }
        if self.approximation_share + self.interpolation_share >= 1.0 {
            return Err(invalid(
                "interpolation share [-]",
                self.interpolation_share,
                "the shares of arcs and interpolation must leave some of the tolerance to the \
                 corners (sum < 1)",
            ));
        }
        if self.max_points < 2 {
            return Err(invalid(
                "max points",
                self.max_points as f64,
                "a trajectory needs at least two",
            ));
        }
        if self.max_lines < 1 {
            return Err(invalid(
                "max lines",
                self.max_lines as f64,
                "a program needs at least one",
            ));
        }
        if self.knot_spacing < self.control_period {
            return Err(invalid(
                "knot spacing [s]",
                self.knot_spacing,
                "must be at least the control period",
            ));
        }
        self.limits.validate().map_err(setting)?;
        self.corner_method.check().map_err(setting)?;
        self.reader.validate()?;
        Ok(())
    }
}

fn invalid(name: &str, value: f64, reason: &str) -> GcodePlanError {
    GcodePlanError::InvalidSetting {
        name: name.to_string(),
        value,
        reason: reason.to_string(),
    }
}
