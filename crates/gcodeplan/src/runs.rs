//! A program split into runs: the stretches the machine moves through
//! without stopping, each a polyline in the program's frame (arcs as
//! chords), and the stops between them.
//!
//! A run ends (the machine comes to rest) where:
//! * the kind of move changes: a cut (G1/G2/G3 with the beam or spindle on),
//!   a feed move with it off, a rapid (G0);
//! * the path control mode (G61, G64 P) changes;
//! * the tool is switched (M3/M4/M5), a dwell (G4) or the end (M2/M30);
//! * the path reverses (turns by more than π − [`REVERSAL_MARGIN`]): no
//!   curvature-continuous transition fits a tolerance there;
//! * under G61 (exact path), at every programmed vertex.

use std::io::BufRead;

use kerf_budget::{bytes_of, Budget};
use kerf_gcode::{ArcMove, Motion, PathControl, Program};
use kerf_toolpath::corner::REVERSAL_MARGIN;

use crate::error::GcodePlanError;
use crate::memory::Held;
use crate::settings::PlanSettings;

/// What a run does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunKind {
    /// Feed move with the beam or spindle on.
    Cut,
    /// Feed move (G1/G2/G3) with it off.
    Travel,
    /// G0.
    Rapid,
}

impl RunKind {
    /// Lower-case name for messages.
    pub fn name(self) -> &'static str {
        match self {
            RunKind::Cut => "cut",
            RunKind::Travel => "travel",
            RunKind::Rapid => "rapid",
        }
    }
}

/// A stretch moved through without stopping.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// What it does.
    pub kind: RunKind,
    /// The polyline \[m\], program frame; no two consecutive points equal.
    pub points: Vec<[f64; 3]>,
    /// Source line of each point (the motion that ends there; the first
    /// point's is the run's first motion).
    pub lines: Vec<usize>,
    /// Programmed feed of each segment \[m/s\] (G0: the rapid speed): `feeds[k]` of the
    /// segment from point k to k + 1. A change of F does not stop the machine: the feed
    /// plan holds each segment to its own.
    pub feeds: Vec<f64>,
    /// The corner tolerance δ_c of this run \[m\] (a G64 P below δ_c
    /// replaces it).
    pub corner_tolerance: f64,
}

/// One step of a program.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A run.
    Run(Run),
    /// G4: stand still.
    Dwell {
        /// Seconds.
        seconds: f64,
        /// Source line.
        line: usize,
    },
    /// M3/M4 (on) or M5 (off), at rest.
    Tool {
        /// On after this.
        on: bool,
        /// Source line.
        line: usize,
    },
}

/// A program read into steps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Reading {
    /// The steps in order.
    pub steps: Vec<Step>,
    /// Lines read.
    pub lines: usize,
    /// Motions of zero length (start = end), which move nothing and are
    /// counted here.
    pub zero_length_moves: usize,
    /// Blocks skipped by the block delete switch.
    pub skipped_blocks: usize,
    /// Arcs read.
    pub arcs: usize,
    /// Where the program starts \[m\], program frame.
    pub start: [f64; 3],
}

/// The run being built.
struct Open {
    run: Run,
    exact: bool,
}

/// Reads `source` into steps (module documentation).
///
/// # Errors
/// The reader's first error ([`GcodePlanError::Program`], with line and
/// column; a program longer than [`PlanSettings::max_lines`] is
/// [`kerf_gcode::GcodeError::TooManyLines`] naming its first line beyond the
/// limit); [`GcodePlanError::InvalidSetting`] for bad settings;
/// [`GcodePlanError::Arc`] for an arc in a program planned with no
/// approximation share, or one needing more chords than points allowed.
pub fn read_steps<R: BufRead>(
    source: R,
    settings: &PlanSettings,
) -> Result<Reading, GcodePlanError> {
    read_steps_within(source, settings, &Budget::unlimited())
}

/// Bytes one point of a run holds: its position, source line and feed.
pub const BYTES_PER_POINT: u64 = 24 + 8 + 8;

/// Bytes of points read between two accountings of the reading.
const ACCOUNT_EVERY: u64 = 1 << 20;

/// [`read_steps`] under a budget: the deadline checked at every motion and every few thousand
/// chords of an arc, an arc's chords estimated before they are made (a helix of 10⁴ turns
/// within a tolerance of 10 µm is refused by the estimate when it does not fit), and the runs'
/// points accounted as they are read (given back when this returns).
///
/// # Errors
/// As [`read_steps`]; [`GcodePlanError::Interrupted`] when the budget runs out.
pub fn read_steps_within<R: BufRead>(
    source: R,
    settings: &PlanSettings,
    budget: &Budget,
) -> Result<Reading, GcodePlanError> {
    let mut held = Held::new(budget);
    read_into(source, settings, &mut held)
}

/// [`read_steps_within`], the points accounted on `held` (kept by the caller).
pub(crate) fn read_into<R: BufRead>(
    source: R,
    settings: &PlanSettings,
    held: &mut Held<'_>,
) -> Result<Reading, GcodePlanError> {
    settings.validate()?;
    let budget = held.budget();
    let mut pending: u64 = 0;
    // The deadline is checked at every line the reader takes (comments and blank lines make
    // no motion), the interruption kept to be told from a read error.
    let stopped = std::cell::RefCell::new(None);
    let source = Checked {
        inner: source,
        budget,
        stopped: &stopped,
    };
    // The line limit is the reader's: a program is refused at its first line beyond it
    // (whatever that line holds), naming it, before the rest is read.
    let mut program = Program::new(source, settings.reader)?.with_max_lines(settings.max_lines);
    let mut reading = Reading {
        start: settings.reader.start,
        ..Reading::default()
    };
    let mut open: Option<Open> = None;
    while let Some(motion) = program.next() {
        budget.check("reading the program")?;
        let motion = motion.map_err(|e| match stopped.borrow_mut().take() {
            Some(interrupt) => GcodePlanError::Interrupted(interrupt),
            None => GcodePlanError::Program(e),
        })?;
        let control = program.interpreter().path_control();
        let (exact, corner_tolerance) = match control {
            PathControl::Exact => (true, settings.corner_tolerance()),
            PathControl::Blend {
                tolerance: Some(p), ..
            } if p > 0.0 => (false, settings.corner_tolerance().min(p)),
            PathControl::Blend { .. } => (false, settings.corner_tolerance()),
        };
        let (kind, feed, start, end, line) = match motion {
            Motion::Rapid { start, end, line } => {
                (RunKind::Rapid, settings.rapid_feed, start, end, line)
            }
            Motion::Line {
                start,
                end,
                feed,
                tool_on,
                line,
            } => (kind_of(tool_on), feed, start, end, line),
            Motion::Arc {
                arc,
                feed,
                tool_on,
                line,
            } => (kind_of(tool_on), feed, arc.start, arc.end, line),
            Motion::Dwell { seconds, line } => {
                close(&mut open, &mut reading, settings, budget)?;
                reading.steps.push(Step::Dwell { seconds, line });
                continue;
            }
            Motion::Tool { on, line, .. } => {
                close(&mut open, &mut reading, settings, budget)?;
                reading.steps.push(Step::Tool { on, line });
                continue;
            }
            Motion::End { .. } => {
                close(&mut open, &mut reading, settings, budget)?;
                // Read on to the end, so that the reader refuses text after M2/M30 (it allows
                // only blanks and comments there) instead of the plan ignoring it.
                for rest in program.by_ref() {
                    rest.map_err(|e| match stopped.borrow_mut().take() {
                        Some(interrupt) => GcodePlanError::Interrupted(interrupt),
                        None => GcodePlanError::Program(e),
                    })?;
                }
                break;
            }
        };
        let points = match motion {
            Motion::Arc { arc, .. } => {
                reading.arcs += 1;
                chords(&arc, settings, line, held, pending)?
            }
            _ if start == end => Vec::new(),
            _ => vec![end],
        };
        if points.is_empty() {
            reading.zero_length_moves += 1;
            continue;
        }
        let continues = open.as_ref().is_some_and(|o| {
            o.run.kind == kind
                && (o.run.kind != RunKind::Rapid || o.run.feeds[0] == feed)
                && o.run.corner_tolerance == corner_tolerance
                && !o.exact
                && !exact
        });
        if !continues {
            close(&mut open, &mut reading, settings, budget)?;
            open = Some(Open {
                run: Run {
                    kind,
                    points: vec![start],
                    lines: vec![line],
                    feeds: Vec::new(),
                    corner_tolerance,
                },
                exact,
            });
        }
        pending += BYTES_PER_POINT * points.len() as u64;
        for p in points {
            push_point(&mut open, &mut reading, settings, p, line, feed, budget)?;
        }
        if pending >= ACCOUNT_EVERY {
            let points = pending / BYTES_PER_POINT;
            held.add(pending, || {
                format!(
                    "program runs: {} lines read, {points} more points",
                    program.lines_read()
                )
            })?;
            pending = 0;
        }
    }
    held.add(pending, || {
        format!(
            "program runs: {} lines read, {} more points",
            program.lines_read(),
            pending / BYTES_PER_POINT
        )
    })?;
    close(&mut open, &mut reading, settings, budget)?;
    reading.lines = program.lines_read();
    reading.skipped_blocks = program.skipped_blocks();
    Ok(reading)
}

/// A program source whose every `fill_buf` (each line the reader takes) checks the deadline:
/// a program of 10⁷ comment lines is stopped like one of motions.
struct Checked<'a, R> {
    inner: R,
    budget: &'a Budget,
    stopped: &'a std::cell::RefCell<Option<kerf_budget::Interrupt>>,
}

impl<R: BufRead> std::io::Read for Checked<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Checked<'_, R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if let Err(interrupt) = self.budget.check("reading the program") {
            let message = interrupt.to_string();
            *self.stopped.borrow_mut() = Some(interrupt);
            return Err(std::io::Error::other(message));
        }
        self.inner.fill_buf()
    }

    fn consume(&mut self, amt: usize) {
        self.inner.consume(amt);
    }
}

fn kind_of(tool_on: bool) -> RunKind {
    if tool_on {
        RunKind::Cut
    } else {
        RunKind::Travel
    }
}

/// Appends `p` to the open run, first closing the run at its last point
/// when the path reverses there.
fn push_point(
    open: &mut Option<Open>,
    reading: &mut Reading,
    settings: &PlanSettings,
    p: [f64; 3],
    line: usize,
    feed: f64,
    budget: &Budget,
) -> Result<(), GcodePlanError> {
    let Some(o) = open.as_mut() else {
        return Ok(());
    };
    let n = o.run.points.len();
    let last = o.run.points[n - 1];
    if p == last {
        return Ok(());
    }
    if n >= 2 && turn(o.run.points[n - 2], last, p) > std::f64::consts::PI - REVERSAL_MARGIN {
        let run = Run {
            points: vec![last],
            lines: vec![o.run.lines[n - 1]],
            feeds: Vec::new(),
            ..o.run.clone()
        };
        let exact = o.exact;
        close(open, reading, settings, budget)?;
        *open = Some(Open { run, exact });
    }
    if let Some(o) = open.as_mut() {
        o.run.points.push(p);
        o.run.lines.push(line);
        o.run.feeds.push(feed);
    }
    Ok(())
}

/// The turning angle at `b` between a→b and b→c \[rad\].
fn turn(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let u: [f64; 3] = std::array::from_fn(|k| b[k] - a[k]);
    let v: [f64; 3] = std::array::from_fn(|k| c[k] - b[k]);
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let norm = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
    norm.atan2(u[0] * v[0] + u[1] * v[1] + u[2] * v[2])
}

/// Ends the open run: merges its nearly collinear points within δ_a / 2
/// and keeps it when it moves.
fn close(
    open: &mut Option<Open>,
    reading: &mut Reading,
    settings: &PlanSettings,
    budget: &Budget,
) -> Result<(), GcodePlanError> {
    let Some(o) = open.take() else {
        return Ok(());
    };
    let mut run = o.run;
    if run.points.len() < 2 {
        return Ok(());
    }
    let merge = 0.5 * settings.approximation_tolerance();
    if merge > 0.0 && run.points.len() > 2 {
        let kept = kerf_toolpath::merge_collinear_indices_within(&run.points, merge, budget)
            .map_err(|error| crate::error::path(run.lines[0], error))?;
        if kept.len() < run.points.len() {
            // A merged segment from kept point a to b replaces segments a..b: the lowest
            // of their feeds.
            let feeds = kept
                .windows(2)
                .map(|w| {
                    run.feeds[w[0]..w[1]]
                        .iter()
                        .copied()
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            run.lines = kept.iter().map(|&k| run.lines[k]).collect();
            run.points = kept.iter().map(|&k| run.points[k]).collect();
            run.feeds = feeds;
        }
    }
    reading.steps.push(Step::Run(run));
    Ok(())
}

/// The chords of an arc after its start, each with a sagitta ≤ δ_a / 2:
/// n = ⌈|sweep| / φ⌉ equal steps, φ = 2 acos(1 − δ_a / (2r)) (the sagitta of
/// a chord spanning φ on radius r is r (1 − cos(φ/2))), at least one per
/// half turn. A helix's chord deviates from it no more than its projection
/// does (the normal coordinate is linear in the angle on both).
fn chords(
    arc: &ArcMove,
    settings: &PlanSettings,
    line: usize,
    held: &Held<'_>,
    pending: u64,
) -> Result<Vec<[f64; 3]>, GcodePlanError> {
    let sagitta = 0.5 * settings.approximation_tolerance();
    if sagitta <= 0.0 {
        return Err(GcodePlanError::Arc {
            line,
            reason: format!(
                "an arc, and the approximation share [-] = {} leaves no tolerance for its \
                 chords",
                settings.approximation_share
            ),
        });
    }
    let ratio = sagitta / arc.radius;
    let step = if ratio >= 1.0 {
        std::f64::consts::PI
    } else {
        (2.0 * (1.0 - ratio).acos()).min(std::f64::consts::PI)
    };
    let chords = (arc.sweep.abs() / step).ceil().max(1.0);
    if chords.is_nan() || chords > settings.max_points as f64 {
        return Err(GcodePlanError::Arc {
            line,
            reason: format!(
                "the arc of radius {:.6e} m needs {chords:.3e} chords within {sagitta:.1e} m, \
                 more than the {} points allowed",
                arc.radius, settings.max_points
            ),
        });
    }
    let n = chords as usize;
    // The chords and the run's points they become, on top of the points read since the last
    // accounting.
    held.check(
        pending.saturating_add(
            bytes_of::<[f64; 3]>(n as u64).saturating_add(BYTES_PER_POINT * n as u64),
        ),
        || {
            let turns = arc.extra_turns + 1;
            format!(
                "program runs up to line {line}, the arc there: {turns} turns × {:.0} chords per \
                 turn within {sagitta:.1e} m (radius {:.3e} m), {n} chords",
                (std::f64::consts::TAU / step).ceil(),
                arc.radius
            )
        },
    )?;
    let mut out = Vec::with_capacity(n);
    for k in 1..=n {
        if k % 4096 == 0 {
            held.budget().check("arc chords")?;
        }
        out.push(if k == n {
            arc.end
        } else {
            arc.point_at(k as f64 / n as f64)
        });
    }
    out.dedup();
    Ok(out)
}
