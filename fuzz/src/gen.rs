//! Messages built from fuzzer bytes with [`arbitrary::Unstructured`].
//!
//! Every byte string gives a message (missing bytes read as zeros), so no input is wasted on
//! a decoding error, and the values are drawn where the conversions and validations have
//! their edges: NaN, ±∞, ±0, the largest and smallest floats, raw bit patterns, small "sane"
//! numbers, near-unit axes, arrays whose lengths match the joint count or not, joint names of
//! the real robots or not, times at and past the `nanosec` limit.
//!
//! The numbers generators ([`cut_request_numbers`], [`mill_request_numbers`],
//! [`gcode_request`]; issue 33) draw each numeric field against its declared rule
//! ([`kerf_msgs::numbers`]): a bound, the float just inside or just outside it, a special
//! value, a value between the bounds, or (how often is drawn once per message) a hostile
//! value: NaN, ±∞, ±0, ±5e-324, ±1e308, the largest float, raw bits, and for integers 0, 1,
//! 2³¹ and `u32::MAX`. A field whose `has_*` flag is off is hostile half the time.

use std::marker::PhantomData;

use arbitrary::{Result, Unstructured};
use kerf_msgs::{
    builtin_interfaces::{Duration, Time},
    geometry_msgs::{Point, Pose, Quaternion, Vector3},
    msg,
    numbers::{probe, Bound, NumberRules, Rule},
    std_msgs::Header,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};

/// A float: an edge value, raw bits, or (most often) a small number in a plausible range.
pub fn float(u: &mut Unstructured) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=15)? {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => f64::NEG_INFINITY,
        3 => 0.0,
        4 => -0.0,
        5 => f64::MAX,
        6 => f64::MIN_POSITIVE,
        7 => 5e-324,
        8 => f64::from_bits(u.arbitrary()?),
        9 => 1e308 * if u.arbitrary()? { 1.0 } else { -1.0 },
        _ => f64::from(u.arbitrary::<i16>()?) / 1000.0,
    })
}

/// A float that is usually a valid positive parameter (feedrate, period, angle limit).
fn positive(u: &mut Unstructured, typical: f64) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=3)? {
        0 => float(u)?,
        _ => typical * (0.5 + f64::from(u.arbitrary::<u8>()?) / 255.0),
    })
}

/// A count: 0 (the message's "default"), small, or any `u32`.
fn count(u: &mut Unstructured, small: u32) -> Result<u32> {
    Ok(match u.int_in_range(0u8..=3)? {
        0 => 0,
        1 => u.arbitrary()?,
        _ => u.int_in_range(0..=small)?,
    })
}

/// A string: empty, one of `known`, or arbitrary text.
fn string(u: &mut Unstructured, known: &[&str]) -> Result<String> {
    let pick = u.int_in_range(0..=known.len() + 1)?;
    Ok(match pick {
        0 => String::new(),
        i if i <= known.len() => known[i - 1].to_string(),
        _ => u.arbitrary::<&str>()?.to_string(),
    })
}

/// `n` points along a line (with the odd wild coordinate), coplanar when `planar`.
fn points(u: &mut Unstructured, n: usize, planar: bool) -> Result<Vec<Point>> {
    let origin = [float(u)?, float(u)?, float(u)?];
    let step = [
        f64::from(u.arbitrary::<i8>()?) / 1000.0,
        f64::from(u.arbitrary::<i8>()?) / 1000.0,
        if planar {
            0.0
        } else {
            f64::from(u.arbitrary::<i8>()?) / 1000.0
        },
    ];
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let wild = u.ratio(1u8, 16)?;
        let c = |i: usize| origin[i] + step[i] * k as f64;
        out.push(if wild {
            Point {
                x: float(u)?,
                y: float(u)?,
                z: float(u)?,
            }
        } else {
            Point {
                x: c(0),
                y: c(1),
                z: c(2),
            }
        });
    }
    Ok(out)
}

/// A tool axis: a unit vector of a few kinds, or arbitrary components.
fn axis(u: &mut Unstructured) -> Result<Vector3> {
    let v = |x, y, z| Vector3 { x, y, z };
    Ok(match u.int_in_range(0u8..=5)? {
        0 => v(0.0, 0.0, 1.0),
        1 => v(0.0, 0.6, 0.8),
        2 => v(float(u)?, float(u)?, float(u)?),
        3 => v(0.0, 0.0, 1.0 + 1e-6 * f64::from(u.arbitrary::<i8>()?)),
        _ => {
            let (a, b) = (
                f64::from(u.arbitrary::<i8>()?) / 128.0,
                f64::from(u.arbitrary::<i8>()?) / 128.0,
            );
            let n = (a * a + b * b + 1.0).sqrt();
            v(a / n, b / n, 1.0 / n)
        }
    })
}

fn pose(u: &mut Unstructured) -> Result<Pose> {
    let orientation = match u.int_in_range(0u8..=3)? {
        0 => Quaternion {
            x: float(u)?,
            y: float(u)?,
            z: float(u)?,
            w: float(u)?,
        },
        1 => Quaternion::default(),
        _ => Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        },
    };
    Ok(Pose {
        position: Point {
            x: float(u)?,
            y: float(u)?,
            z: float(u)?,
        },
        orientation,
    })
}

/// A request's `start` and `start_positions` (issue 27): the known words, a wrong one, and
/// 0 to 7 positions of any value.
fn start(u: &mut Unstructured) -> Result<(String, Vec<f64>)> {
    let word = string(u, &["", "current", "given", "none"])?;
    let n = u.int_in_range(0..=7)?;
    let positions = (0..n).map(|_| float(u)).collect::<Result<Vec<_>>>()?;
    Ok((word, positions))
}

/// A `kerf_msgs/msg/CutRequest`.
pub fn cut_request(u: &mut Unstructured) -> Result<msg::CutRequest> {
    let n = u.int_in_range(0..=12)?;
    let points = points(u, n, false)?;
    let n_axes = if u.ratio(1u8, 8)? {
        u.int_in_range(0..=12)?
    } else {
        n
    };
    let axes = (0..n_axes).map(|_| axis(u)).collect::<Result<Vec<_>>>()?;
    let rto_indices = match u.int_in_range(0u8..=2)? {
        0 => Vec::new(),
        1 => vec![0, u32::try_from(n.saturating_sub(1)).unwrap_or(u32::MAX)],
        _ => u.arbitrary()?,
    };
    let (start_word, start_positions) = start(u)?;
    Ok(msg::CutRequest {
        request_id: string(u, &["slot-3", "bpillar-case1-side-trim"])?,
        points,
        axes,
        feedrate: positive(u, 0.3)?,
        feed_acceleration: if u.arbitrary()? { 0.0 } else { float(u)? },
        feed_jerk: if u.arbitrary()? { 0.0 } else { float(u)? },
        sample_period: positive(u, 0.004)?,
        max_lead_angle: positive(u, 0.087)?,
        max_tilt_angle: positive(u, 0.087)?,
        mesh: string(u, &["package://kerf/urdf/meshes/bpillar.obj", " "])?,
        workpiece_pose: pose(u)?,
        control_points: count(u, 40)?,
        max_iterations: count(u, 20)?,
        gfd_q4_steps: count(u, 103)?,
        gfd_q5_steps: count(u, 103)?,
        gfd_q6_steps: count(u, 103)?,
        gfd_q4_half_range: if u.arbitrary()? { 0.0 } else { float(u)? },
        gfd_q5_half_range: if u.arbitrary()? { 0.0 } else { float(u)? },
        rto_indices,
        rto_spacing: if u.arbitrary()? { 0.0 } else { float(u)? },
        rto_angle: if u.arbitrary()? { 0.0 } else { float(u)? },
        has_reference_standoff: u.arbitrary()?,
        reference_standoff: float(u)?,
        clearance: if u.arbitrary()? { 0.0 } else { float(u)? },
        cl_tolerance: if u.arbitrary()? { 0.0 } else { float(u)? },
        feed_law: string(u, &["", "time_optimal", "constant", "variable"])?,
        rto_constraint: string(u, &["box", "equality"])?,
        orientation_corridor: string(u, &["", "allowance", "none", "off"])?,
        time_budget: if u.arbitrary()? { 0.0 } else { float(u)? },
        start: start_word,
        start_positions,
    })
}

/// A `kerf_msgs/msg/MillRequest`.
pub fn mill_request(u: &mut Unstructured) -> Result<msg::MillRequest> {
    let n = u.int_in_range(0..=10)?;
    let planar = !u.ratio(1u8, 8)?;
    let (start_word, start_positions) = start(u)?;
    Ok(msg::MillRequest {
        request_id: string(u, &["job-17"])?,
        points: points(u, n, planar)?,
        segments: count(u, 200)?,
        has_process: u.arbitrary()?,
        teeth: count(u, 120)?,
        tool_radius: positive(u, 0.01)?,
        axial_depth: positive(u, 0.002)?,
        kt: positive(u, 6e8)?,
        kn: positive(u, 2e8)?,
        entry_angle: float(u)?,
        exit_angle: positive(u, 3.0)?,
        has_limits: u.arbitrary()?,
        spindle_min_rpm: positive(u, 1000.0)?,
        spindle_max_rpm: positive(u, 10000.0)?,
        feed_min: positive(u, 0.01)?,
        feed_max: positive(u, 0.1)?,
        g_min: float(u)?,
        g_max: float(u)?,
        max_spindle_step_rpm: positive(u, 500.0)?,
        max_feed_step: positive(u, 0.01)?,
        max_g_step: positive(u, 0.1)?,
        has_initial_state: u.arbitrary()?,
        initial_spindle_rpm: positive(u, 2000.0)?,
        initial_feed: positive(u, 0.04)?,
        initial_g: float(u)?,
        planner: string(u, &["ddpg", "fixed_g", "dp", "naive"])?,
        policy_file: string(u, &["crates/millplan/policies/ddpg.json"])?,
        time_budget: if u.arbitrary()? { 0.0 } else { float(u)? },
        has_tolerances: u.arbitrary()?,
        path_tolerance: positive(u, 5e-5)?,
        min_condition_indicator: float(u)?,
        start: start_word,
        start_positions,
        allow_chatter: u.arbitrary()?,
        entry: string(u, &["", "run_in", "in_material"])?,
    })
}

/// Joint names of the laser cutter and of the IRB 6660 (kerf's two robots).
pub const JOINT_NAMES: [&str; 12] = [
    "q1", "q2", "q3", "q4", "q5", "q6", "joint_1", "joint_2", "joint_3", "joint_4", "joint_5",
    "joint_6",
];

fn duration(u: &mut Unstructured, t: f64) -> Result<Duration> {
    Ok(match u.int_in_range(0u8..=7)? {
        0 => Duration {
            sec: u.arbitrary()?,
            nanosec: u.arbitrary()?,
        },
        1 => Duration {
            sec: u.arbitrary()?,
            nanosec: 999_999_999 + u32::from(u.arbitrary::<u8>()? & 1),
        },
        _ => Duration::from_secs_f64(t).unwrap_or_default(),
    })
}

/// An array of `n` joint values (or of a wrong length), values mostly small.
fn joint_values(u: &mut Unstructured, n: usize) -> Result<Vec<f64>> {
    let len = match u.int_in_range(0u8..=7)? {
        0 => 0,
        1 => u.int_in_range(0..=8)?,
        _ => n,
    };
    (0..len)
        .map(|_| {
            Ok(if u.ratio(1u8, 8)? {
                float(u)?
            } else {
                f64::from(u.arbitrary::<i8>()?) / 100.0
            })
        })
        .collect()
}

/// A `trajectory_msgs/JointTrajectory` for one of kerf's robots (`robot` 0: the laser cutter,
/// else the IRB 6660), mostly with the robot's joint names.
pub fn joint_trajectory(u: &mut Unstructured, robot: usize) -> Result<JointTrajectory> {
    let base = if robot == 0 { 0 } else { 6 };
    let mut joint_names: Vec<String> = (0..6).map(|j| JOINT_NAMES[base + j].into()).collect();
    match u.int_in_range(0u8..=7)? {
        0 => joint_names = u.arbitrary()?,
        1 => {
            let i = u.choose_index(6)?;
            let j = u.choose_index(6)?;
            joint_names.swap(i, j);
        }
        2 => {
            joint_names.pop();
        }
        3 => joint_names.push(JOINT_NAMES[u.choose_index(JOINT_NAMES.len())?].into()),
        _ => {}
    }
    let n = joint_names.len();
    let count = u.int_in_range(0..=8)?;
    let mut t = 0.0;
    let mut points = Vec::with_capacity(count);
    for _ in 0..count {
        let time_from_start = duration(u, t)?;
        t += f64::from(u.arbitrary::<u8>()?) / 100.0;
        points.push(JointTrajectoryPoint {
            positions: joint_values(u, n)?,
            velocities: joint_values(u, n)?,
            accelerations: joint_values(u, n)?,
            effort: if u.ratio(1u8, 8)? {
                joint_values(u, n)?
            } else {
                Vec::new()
            },
            time_from_start,
        });
    }
    let stamp = if u.arbitrary()? {
        Time::default()
    } else {
        Time {
            sec: u.arbitrary()?,
            nanosec: u.arbitrary()?,
        }
    };
    Ok(JointTrajectory {
        header: Header {
            stamp,
            frame_id: String::new(),
        },
        joint_names,
        points,
    })
}

// ---------------------------------------------------------------------------------------------
// Hostile numbers (issue 33): each field drawn against its declared rule
// ---------------------------------------------------------------------------------------------

/// A hostile float: one of `kerf_msgs`' probes (NaN, ±∞, 0, −0, 5e-324, ±1e308), −5e-324, the
/// smallest normal float, the largest float, or raw bits.
pub fn hostile_float(u: &mut Unstructured) -> Result<f64> {
    let probes = probe::FLOAT_PROBES;
    let i = u.int_in_range(0..=probes.len() + 3)?;
    Ok(match probes.get(i) {
        Some(v) => *v,
        None => match i - probes.len() {
            0 => -5e-324,
            1 => f64::MIN_POSITIVE,
            2 => f64::MAX,
            _ => f64::from_bits(u.arbitrary()?),
        },
    })
}

/// A hostile count: 0, 1, 2³¹ (a negative `int32` read as `uint32`), `i32::MAX`, `u32::MAX`,
/// or any `u32`.
pub fn hostile_count(u: &mut Unstructured) -> Result<u32> {
    Ok(match u.int_in_range(0u8..=5)? {
        0 => 0,
        1 => 1,
        2 => 1 << 31,
        3 => 0x7fff_ffff,
        4 => u32::MAX,
        _ => u.arbitrary()?,
    })
}

/// The value of a rule's bound.
fn bound_value(b: Bound) -> f64 {
    match b {
        Bound::Closed(v) | Bound::Open(v) => v,
    }
}

/// A float at the edge of `rule` or inside it: a bound, the float just inside or just outside
/// a bound, a special value, −0, or a value between the bounds. Any float without a rule.
fn near_rule(u: &mut Unstructured, rule: Option<&Rule>) -> Result<f64> {
    let Some(rule) = rule else { return float(u) };
    let (lo, hi) = (bound_value(rule.lo), bound_value(rule.hi));
    Ok(match u.int_in_range(0u8..=11)? {
        0 => lo,
        1 => hi,
        2 => lo.next_up(),
        3 => hi.next_down(),
        4 => lo.next_down(),
        5 => hi.next_up(),
        6 => rule.special.first().map_or(0.0, |(v, _)| *v),
        7 => -0.0,
        _ => lo + (hi - lo) * (f64::from(u.arbitrary::<u8>()?) / 255.0),
    })
}

/// A count at the edge of `rule` or inside it (as [`near_rule`], in whole numbers saturated
/// to `u32`). Any `u32` without a rule.
fn near_rule_count(u: &mut Unstructured, rule: Option<&Rule>) -> Result<u32> {
    let Some(rule) = rule else {
        return u.arbitrary();
    };
    let (lo, hi) = (bound_value(rule.lo), bound_value(rule.hi));
    // `as` saturates (and maps NaN to 0): the value stays a `u32`.
    let at = |v: f64| v.round() as u32;
    Ok(match u.int_in_range(0u8..=5)? {
        0 => at(lo),
        1 => at(hi),
        2 => at(lo - 1.0),
        3 => at(hi + 1.0),
        4 => at(rule.special.first().map_or(0.0, |(v, _)| *v)),
        _ => at(lo + (hi - lo) * (f64::from(u.arbitrary::<u8>()?) / 255.0)),
    })
}

/// Draws the numbers of one message of type `T` against `T`'s declared rules.
struct Numbers<T> {
    /// How often (out of 16) a field is hostile instead of near its rule.
    hostile: u8,
    message: PhantomData<T>,
}

impl<T: NumberRules> Numbers<T> {
    /// Draws how hostile this message is: never, 1, 3 or 12 fields in 16.
    fn new(u: &mut Unstructured) -> Result<Self> {
        Ok(Self {
            hostile: [0, 1, 3, 12][u.choose_index(4)?],
            message: PhantomData,
        })
    }

    /// Whether the next field is hostile, at `rate` in 16.
    fn draw_hostile(u: &mut Unstructured, rate: u8) -> Result<bool> {
        Ok(rate > 0 && u.ratio(rate, 16)?)
    }

    /// The float field `key` (normalized, e.g. `points[].x`).
    fn float(&self, u: &mut Unstructured, key: &str) -> Result<f64> {
        if Self::draw_hostile(u, self.hostile)? {
            hostile_float(u)
        } else {
            near_rule(u, probe::rule_of::<T>(key))
        }
    }

    /// The float field `key` of a group whose `has_*` flag is `on`: when it is off the field
    /// only has to be finite, and is hostile half the time.
    fn gated(&self, u: &mut Unstructured, key: &str, on: bool) -> Result<f64> {
        if !on && u.arbitrary()? {
            hostile_float(u)
        } else {
            self.float(u, key)
        }
    }

    /// The `uint32` field `key`.
    fn count(&self, u: &mut Unstructured, key: &str) -> Result<u32> {
        if Self::draw_hostile(u, self.hostile)? {
            hostile_count(u)
        } else {
            near_rule_count(u, probe::rule_of::<T>(key))
        }
    }

    /// The `uint32` field `key` of a group whose flag is `on` (off: hostile half the time).
    fn gated_count(&self, u: &mut Unstructured, key: &str, on: bool) -> Result<u32> {
        if !on && u.arbitrary()? {
            hostile_count(u)
        } else {
            self.count(u, key)
        }
    }

    /// Points of an array field (`points`): now and then one coordinate replaced by a value
    /// of the rule of `points[].*`.
    fn touch_points(&self, u: &mut Unstructured, points: &mut [Point]) -> Result<()> {
        if points.is_empty() || !u.ratio(1u8, 2)? {
            return Ok(());
        }
        let i = u.choose_index(points.len())?;
        let p = &mut points[i];
        match u.int_in_range(0u8..=2)? {
            0 => p.x = self.float(u, "points[].x")?,
            1 => p.y = self.float(u, "points[].y")?,
            _ => p.z = self.float(u, "points[].z")?,
        }
        Ok(())
    }
}

/// A `kerf_msgs/msg/CutRequest` shaped as [`cut_request`] draws it, every number then drawn
/// against its rule (module documentation).
pub fn cut_request_numbers(u: &mut Unstructured) -> Result<msg::CutRequest> {
    let n = Numbers::<msg::CutRequest>::new(u)?;
    let mut m = cut_request(u)?;
    n.touch_points(u, &mut m.points)?;
    m.feedrate = n.float(u, "feedrate")?;
    m.feed_acceleration = n.float(u, "feed_acceleration")?;
    m.feed_jerk = n.float(u, "feed_jerk")?;
    m.sample_period = n.float(u, "sample_period")?;
    m.max_lead_angle = n.float(u, "max_lead_angle")?;
    m.max_tilt_angle = n.float(u, "max_tilt_angle")?;
    m.control_points = n.count(u, "control_points")?;
    m.max_iterations = n.count(u, "max_iterations")?;
    m.gfd_q4_steps = n.count(u, "gfd_q4_steps")?;
    m.gfd_q5_steps = n.count(u, "gfd_q5_steps")?;
    m.gfd_q6_steps = n.count(u, "gfd_q6_steps")?;
    m.gfd_q4_half_range = n.float(u, "gfd_q4_half_range")?;
    m.gfd_q5_half_range = n.float(u, "gfd_q5_half_range")?;
    for i in &mut m.rto_indices {
        *i = n.count(u, "rto_indices[]")?;
    }
    m.rto_spacing = n.float(u, "rto_spacing")?;
    m.rto_angle = n.float(u, "rto_angle")?;
    m.reference_standoff = n.gated(u, "reference_standoff", m.has_reference_standoff)?;
    m.clearance = n.float(u, "clearance")?;
    m.cl_tolerance = n.float(u, "cl_tolerance")?;
    m.time_budget = n.float(u, "time_budget")?;
    Ok(m)
}

/// A `kerf_msgs/msg/MillRequest` shaped as [`mill_request`] draws it, every number then drawn
/// against its rule (module documentation).
pub fn mill_request_numbers(u: &mut Unstructured) -> Result<msg::MillRequest> {
    let n = Numbers::<msg::MillRequest>::new(u)?;
    let mut m = mill_request(u)?;
    n.touch_points(u, &mut m.points)?;
    m.segments = n.count(u, "segments")?;
    let on = m.has_process;
    m.teeth = n.gated_count(u, "teeth", on)?;
    m.tool_radius = n.gated(u, "tool_radius", on)?;
    m.axial_depth = n.gated(u, "axial_depth", on)?;
    m.kt = n.gated(u, "kt", on)?;
    m.kn = n.gated(u, "kn", on)?;
    m.entry_angle = n.gated(u, "entry_angle", on)?;
    m.exit_angle = n.gated(u, "exit_angle", on)?;
    let on = m.has_limits;
    m.spindle_min_rpm = n.gated(u, "spindle_min_rpm", on)?;
    m.spindle_max_rpm = n.gated(u, "spindle_max_rpm", on)?;
    m.feed_min = n.gated(u, "feed_min", on)?;
    m.feed_max = n.gated(u, "feed_max", on)?;
    m.g_min = n.gated(u, "g_min", on)?;
    m.g_max = n.gated(u, "g_max", on)?;
    m.max_spindle_step_rpm = n.gated(u, "max_spindle_step_rpm", on)?;
    m.max_feed_step = n.gated(u, "max_feed_step", on)?;
    m.max_g_step = n.gated(u, "max_g_step", on)?;
    let on = m.has_initial_state;
    m.initial_spindle_rpm = n.gated(u, "initial_spindle_rpm", on)?;
    m.initial_feed = n.gated(u, "initial_feed", on)?;
    m.initial_g = n.gated(u, "initial_g", on)?;
    m.time_budget = n.float(u, "time_budget")?;
    let on = m.has_tolerances;
    m.path_tolerance = n.gated(u, "path_tolerance", on)?;
    m.min_condition_indicator = n.gated(u, "min_condition_indicator", on)?;
    Ok(m)
}

/// Short programs: one line, a square with an arc, a dwell, and an empty one.
const PROGRAMS: &[&str] = &[
    "G21 G90\nG1 X10 F600\n",
    "G21 G90\nG0 X0 Y0\nG1 X20 F1200\nG1 Y20\nG2 X0 Y20 I-10 J0\nG1 Y0\n",
    "G1 X1 F100\nG4 P0.5\nG1 X2\n",
    " \n",
];

/// Program files: shipped programs, files outside every root, a device, a relative escape, a
/// package escape, other schemes.
const PROGRAM_URIS: &[&str] = &[
    "package://kerf/crates/gcode/data/programs/arcs.ngc",
    "package://kerf/../Cargo.toml",
    "file:///dev/zero",
    "file://localhost/etc/passwd",
    "../../etc/passwd",
    "/proc/self/mem",
    "http://example.com/part.ngc",
    " ",
];

/// `program` and `program_uri` of a `GcodeRequest`: one of them (most often), both, or
/// neither.
fn program_source(u: &mut Unstructured) -> Result<(String, String)> {
    let which = u.int_in_range(0u8..=7)?;
    let program = if which == 0 {
        String::new()
    } else {
        string(u, PROGRAMS)?
    };
    let uri = if which == 0 || which == 1 {
        string(u, PROGRAM_URIS)?
    } else {
        String::new()
    };
    Ok((program, uri))
}

/// A `kerf_msgs/msg/GcodeRequest`: a short program (or a program file), the known machines,
/// methods and feed methods or others, and every number drawn against its rule (module
/// documentation), the `has_limits` and `has_placement` groups on or off.
pub fn gcode_request(u: &mut Unstructured) -> Result<msg::GcodeRequest> {
    let n = Numbers::<msg::GcodeRequest>::new(u)?;
    let (program, program_uri) = program_source(u)?;
    let has_limits: bool = u.arbitrary()?;
    let has_placement: bool = u.arbitrary()?;
    let (start_word, start_positions) = start(u)?;
    Ok(msg::GcodeRequest {
        request_id: string(u, &["part-7"])?,
        machine: string(
            u,
            &[
                msg::GcodeRequest::MACHINE_LASER_CUTTER,
                msg::GcodeRequest::MACHINE_IRB6660,
            ],
        )?,
        program,
        program_uri,
        tolerance: n.float(u, "tolerance")?,
        method: string(u, &["kerf", "kerf-curvature", "icr", "ccr", "nurbs"])?,
        feed_method: string(u, &["near-optimal", "constant-intervals"])?,
        has_limits,
        max_feed: n.gated(u, "max_feed", has_limits)?,
        tangential_acceleration: n.gated(u, "tangential_acceleration", has_limits)?,
        tangential_jerk: n.gated(u, "tangential_jerk", has_limits)?,
        normal_acceleration: n.gated(u, "normal_acceleration", has_limits)?,
        normal_jerk: n.gated(u, "normal_jerk", has_limits)?,
        chord_error: n.gated(u, "chord_error", has_limits)?,
        contour_error: n.gated(u, "contour_error", has_limits)?,
        rapid_feed: n.float(u, "rapid_feed")?,
        has_placement,
        origin: Point {
            x: n.gated(u, "origin.x", has_placement)?,
            y: n.gated(u, "origin.y", has_placement)?,
            z: n.gated(u, "origin.z", has_placement)?,
        },
        redundancy_angle: n.gated(u, "redundancy_angle", has_placement)?,
        standoff_axis: n.gated(u, "standoff_axis", has_placement)?,
        time_budget: n.float(u, "time_budget")?,
        start: start_word,
        start_positions,
    })
}
