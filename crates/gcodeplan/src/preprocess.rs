//! Seed 000's preprocessing of a contour before planning (issue 30, item 1): the program's G01
//! cut path normalized to `[0, L]²` and resampled to `N` points equally spaced along it.
//!
//! Seed 000 (KIRL), section 4.1, "Datasets and Preprocessing": "The original linear toolpaths
//! are normalized to fit within a [0, 100]² coordinate space to ensure consistency across
//! different paths. Each toolpath is resampled to generate 200 equally spaced points, serving as
//! the input format for all approaches." Its toolpaths are G01 polylines of points in ℝ²
//! (section 2.1; "the current implementation only supports 2-axis machining", section 4.4).
//!
//! How this module reads it, where the seed says no more:
//! * **Units.** The seed names no unit for `[0, 100]²` (it is a "coordinate space"; neither mm
//!   nor inch is written). `L` is taken in the program's own length unit: millimetres under G21,
//!   inches under G20 (the unit in effect along the contour; a contour that switches units is
//!   refused).
//! * **Which dimension.** "Fit within" with one uniform scale (the aspect ratio kept): the
//!   *larger* side of the contour's XY bounding box is scaled to `L`, the other comes out
//!   `≤ L`. The box's lower-left corner is translated to the origin (the seed does not centre
//!   the path; "within [0, 100]²" is read as touching 0 on both axes). The map is
//!   `p' = s (p − min)`, i.e. `p' = s p + t` with `t = −s min` ([`Similarity`]); Z is left as
//!   it is (the seed's space is the plane).
//! * **Equal spacing.** Equal *arc length along the polyline being resampled*: point `k` of `N`
//!   lies at arc length `k S / (N − 1)` of the contour's length `S`, the first and the last
//!   points kept exactly ([`resample`]). The new points lie on the old polyline, so the
//!   resampled contour stays in the normalized box; its own chords cut the old corners, so it
//!   is a little shorter, and resampling it again is not the identity unless its chords are
//!   equal (a straight line, or points already equally spaced).
//! * **Order.** Normalize, then resample (the seed's order). The order matters for the box:
//!   resampling first would cut the extreme corners and normalize a smaller box; normalizing
//!   first fits the programmed contour, and the resampled points are its image resampled (a
//!   uniform scale keeps the ratios of arc lengths).
//!
//! What the seed's preprocessing does not define is refused with a message naming the line
//! rather than guessed ([`preprocess_program`]):
//! * **Arcs** (G2/G3) anywhere: the seed's toolpaths are G01 polylines.
//! * **Several contours**: the cut path must be one unbroken run of G1 moves with the beam or
//!   spindle on (nothing between them: no M3/M4/M5, dwell or other move). A program with none
//!   is refused too.
//! * **A contour the seed's toolpaths cannot be**: one that is not in a plane of constant Z,
//!   whose feed (F), path control (G61/G64) or length unit (G20/G21) changes along it, or of
//!   zero length (zero extent, for `--normalize`).
//!
//! What is carried through: rapids (G0) and feed moves with the tool off (G1 after M5) are not
//! preprocessed; under normalization their XY is mapped by the same [`Similarity`] (so that
//! they still meet the contour's ends; their endpoints are not held to the box, and their Z is
//! unchanged). Dwells, tool switches, path control modes and the end are kept in order. The
//! result is a G-code program ([`Preprocessed::program`]) in the contour's unit that the
//! planner reads as it reads any other; its line numbers are its own, not the source's.

use std::io::BufRead;

use kerf_budget::{bytes_of, Budget};
use kerf_gcode::{lexer::lex_line, Interpreter, Motion, PathControl, Program};

use crate::error::GcodePlanError;
use crate::settings::PlanSettings;

/// What to do to the contour (both optional and independent).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Preprocess {
    /// `L`: fit the contour's XY bounding box into `[0, L]²`, in the program's length unit.
    pub normalize: Option<f64>,
    /// `N`: replace the contour by `N ≥ 2` points equally spaced in arc length.
    pub resample: Option<usize>,
}

/// A program's length unit (G21 or G20).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// G21: millimetres.
    Millimetre,
    /// G20: inches.
    Inch,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 1e-3,
            LengthUnit::Inch => kerf_gcode::interpreter::METRES_PER_INCH,
        }
    }

    /// The unit's symbol, `mm` or `in`.
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "mm",
            LengthUnit::Inch => "in",
        }
    }

    /// The G code selecting it.
    pub fn gcode(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "G21",
            LengthUnit::Inch => "G20",
        }
    }
}

/// An axis-aligned box in the XY plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Box2 {
    /// Lower-left corner (x, y).
    pub min: [f64; 2],
    /// Upper-right corner (x, y).
    pub max: [f64; 2],
}

impl Box2 {
    /// The XY bounding box of `points` (`None` when there are none).
    pub fn of(points: &[[f64; 3]]) -> Option<Self> {
        let first = points.first()?;
        let mut b = Box2 {
            min: [first[0], first[1]],
            max: [first[0], first[1]],
        };
        for p in points {
            b.min = [b.min[0].min(p[0]), b.min[1].min(p[1])];
            b.max = [b.max[0].max(p[0]), b.max[1].max(p[1])];
        }
        Some(b)
    }

    /// Width (x) and height (y).
    pub fn size(&self) -> [f64; 2] {
        [self.max[0] - self.min[0], self.max[1] - self.min[1]]
    }

    /// The larger of width and height.
    pub fn extent(&self) -> f64 {
        let [w, h] = self.size();
        w.max(h)
    }
}

/// A uniform scale and translation of the XY plane, `p' = scale (p − origin)`: `origin` goes to
/// (0, 0) exactly. Z is left as it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Similarity {
    /// The scale factor `s` (> 0).
    pub scale: f64,
    /// The point mapped to the origin (the box's lower-left corner).
    pub origin: [f64; 2],
}

impl Similarity {
    /// The translation `t` of `p' = s p + t`: `−s origin`.
    pub fn offset(&self) -> [f64; 2] {
        [
            -self.scale * self.origin[0] + 0.0,
            -self.scale * self.origin[1] + 0.0,
        ]
    }

    /// The image of `p`.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        [
            self.scale * (p[0] - self.origin[0]) + 0.0,
            self.scale * (p[1] - self.origin[1]) + 0.0,
            p[2],
        ]
    }
}

fn invalid(field: &str, reason: impl Into<String>) -> GcodePlanError {
    GcodePlanError::InvalidRequest {
        field: field.to_string(),
        reason: reason.into(),
    }
}

/// The map that fits the XY bounding box of `points` into `[0, side]²`: the larger side scaled
/// to `side`, the lower-left corner to the origin (module documentation).
///
/// # Errors
/// [`GcodePlanError::InvalidRequest`] naming `normalize` when `side` is not finite and > 0, a
/// point is not finite, there are no points, or the box has zero extent (all points equal).
pub fn normalization(points: &[[f64; 3]], side: f64) -> Result<Similarity, GcodePlanError> {
    if !(side.is_finite() && side > 0.0) {
        return Err(invalid(
            "normalize",
            format!("the side L = {side} must be finite and > 0"),
        ));
    }
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return Err(invalid("normalize", "a point is not finite"));
    }
    let b = Box2::of(points).ok_or_else(|| invalid("normalize", "no points"))?;
    let extent = b.extent();
    if extent.is_nan() || extent <= 0.0 {
        return Err(invalid(
            "normalize",
            "the contour's bounding box has zero extent (all its points are equal): no scale \
             fits it to [0, L]²",
        ));
    }
    let scale = side / extent;
    if !(scale.is_finite() && scale > 0.0) {
        return Err(invalid(
            "normalize",
            format!("the scale {side} / {extent} is not a finite positive number"),
        ));
    }
    Ok(Similarity {
        scale,
        origin: b.min,
    })
}

/// `points` fitted into `[0, side]²` ([`normalization`]), each coordinate held to `[0, side]`
/// against rounding (the larger side ends at `side` within one rounding), with the map used.
///
/// # Errors
/// As [`normalization`].
pub fn normalize(
    points: &[[f64; 3]],
    side: f64,
) -> Result<(Vec<[f64; 3]>, Similarity), GcodePlanError> {
    let map = normalization(points, side)?;
    let out = points
        .iter()
        .map(|&p| {
            let [x, y, z] = map.apply(p);
            [x.clamp(0.0, side), y.clamp(0.0, side), z]
        })
        .collect();
    Ok((out, map))
}

/// Length of the polyline through `points`.
pub fn polyline_length(points: &[[f64; 3]]) -> f64 {
    points.windows(2).map(|w| distance(w[0], w[1])).sum()
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// `count` points equally spaced in arc length along the polyline through `points`: point k
/// at arc length `k S / (count − 1)` of its length `S`, the first and last points kept exactly.
///
/// # Errors
/// [`GcodePlanError::InvalidRequest`] naming `resample` when `count < 2`, a point is not
/// finite, or the polyline has zero length (fewer than two distinct points).
pub fn resample(points: &[[f64; 3]], count: usize) -> Result<Vec<[f64; 3]>, GcodePlanError> {
    if count < 2 {
        return Err(invalid(
            "resample",
            format!("{count} points: at least 2 (the first and the last) are kept"),
        ));
    }
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return Err(invalid("resample", "a point is not finite"));
    }
    // Cumulative arc length at each point.
    let mut at = Vec::with_capacity(points.len());
    let mut s = 0.0;
    at.push(0.0);
    for w in points.windows(2) {
        s += distance(w[0], w[1]);
        at.push(s);
    }
    let total = s;
    let (Some(&first), Some(&last)) = (points.first(), points.last()) else {
        return Err(invalid("resample", "no points"));
    };
    if !(total > 0.0 && total.is_finite()) {
        return Err(invalid(
            "resample",
            "the contour has zero length (fewer than two distinct points): nothing to space \
             points along",
        ));
    }
    let mut out = Vec::with_capacity(count);
    out.push(first);
    let steps = (count - 1) as f64;
    let mut j = 0; // segment from points[j] to points[j + 1]
    for k in 1..count - 1 {
        let target = total * (k as f64) / steps;
        // The segment holding `target`: the last whose start is at or before it (zero-length
        // segments are passed over, as their end is at the same arc length).
        while j + 2 < points.len() && at[j + 1] <= target {
            j += 1;
        }
        let length = at[j + 1] - at[j];
        let u = if length > 0.0 {
            ((target - at[j]) / length).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (a, b) = (points[j], points[j + 1]);
        out.push([
            a[0] + u * (b[0] - a[0]),
            a[1] + u * (b[1] - a[1]),
            a[2] + u * (b[2] - a[2]),
        ]);
    }
    out.push(last);
    Ok(out)
}

/// What the normalization did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normalization {
    /// `L` in the program's unit.
    pub side: f64,
    /// The map, in metres (its scale is the same in any unit).
    pub map: Similarity,
    /// The contour's XY box before \[m\].
    pub before: Box2,
    /// After \[m\] (within `[0, L]²`).
    pub after: Box2,
}

/// What was done to a program ([`preprocess_program`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PreprocessReport {
    /// The length unit along the contour (the unit of `L` and of the program written).
    pub unit: LengthUnit,
    /// First and last source line of the contour's G1 moves.
    pub contour_lines: (usize, usize),
    /// Distinct points of the contour before (consecutive repeats dropped).
    pub points_before: usize,
    /// Its length before \[m\].
    pub length_before: f64,
    /// The normalization, when asked for.
    pub normalization: Option<Normalization>,
    /// Points of the contour after.
    pub points_after: usize,
    /// Its length after \[m\].
    pub length_after: f64,
    /// The arc length between resampled points \[m\], measured along the polyline resampled
    /// (after normalization), when resampling was asked for.
    pub spacing: Option<f64>,
    /// G0 moves carried through.
    pub rapids: usize,
    /// G1 moves with the tool off carried through.
    pub travel_moves: usize,
    /// A rapid added first, from where the machine starts (`settings.reader.start`, which
    /// the program does not move) to that point's image under the normalization, so that
    /// the whole program frame is mapped (a contour cut from the start position keeps its
    /// first point).
    pub start_rapid: bool,
}

/// A program preprocessed: the G-code the planner reads instead, and what was done.
#[derive(Debug, Clone, PartialEq)]
pub struct Preprocessed {
    /// The program written out (absolute, in [`PreprocessReport::unit`]).
    pub program: String,
    /// What was done.
    pub report: PreprocessReport,
}

/// Bytes accounted on a budget while the program is held, given back when dropped.
struct Accounted<'a> {
    budget: &'a Budget,
    bytes: u64,
}

impl Drop for Accounted<'_> {
    fn drop(&mut self) {
        self.budget.release(self.bytes);
    }
}

/// Motions accounted at a time.
const ACCOUNT_EVERY: u64 = 4096;

/// The length unit in effect in `interpreter` (after `line`): a relative rapid of one unit
/// along X run on a copy, its length read back.
fn unit_in(interpreter: &Interpreter, line: usize) -> Option<LengthUnit> {
    let block = lex_line("G91 G0 X1", line).ok()?;
    let mut probe = interpreter.clone();
    let mut out = Vec::new();
    probe.execute(&block, &mut out).ok()?;
    let Some(Motion::Rapid { start, end, .. }) = out.first() else {
        return None;
    };
    let d = end[0] - start[0];
    [LengthUnit::Millimetre, LengthUnit::Inch]
        .into_iter()
        .find(|u| (d - u.metres()).abs() <= 1e-9 * u.metres().max(start[0].abs()))
}

/// A motion as read, with the path control in effect for it.
type Held = (Motion, PathControl);

/// The contour found in a program.
struct Contour {
    /// Indices of its G1 moves in the motions held.
    range: std::ops::Range<usize>,
    feed: f64,
    unit: LengthUnit,
}

/// Reads `source` (with `settings.reader`, at most `settings.max_lines` lines) and applies
/// `options` to its one G01 contour (module documentation), writing the program back out.
///
/// The motions are held while the program is read, accounted on `budget` (and given back on
/// return).
///
/// # Errors
/// [`GcodePlanError::Program`] for the reader's errors (line and column);
/// [`GcodePlanError::InvalidRequest`] naming `normalize` or `resample` for a bad `L` or `N`,
/// or a program the seed's preprocessing does not define (arcs, no contour or several, a
/// contour not planar, with a changing feed, unit or path control, of zero length);
/// [`GcodePlanError::Interrupted`] when the budget runs out.
pub fn preprocess_program<R: BufRead>(
    source: R,
    settings: &PlanSettings,
    options: &Preprocess,
    budget: &Budget,
) -> Result<Preprocessed, GcodePlanError> {
    let field = match (options.normalize, options.resample) {
        (Some(_), None) => "normalize",
        (None, Some(_)) => "resample",
        _ => "preprocessing",
    };
    if let Some(side) = options.normalize {
        if !(side.is_finite() && side > 0.0) {
            return Err(invalid(
                "normalize",
                format!("the side L = {side} must be finite and > 0"),
            ));
        }
    }
    if let Some(n) = options.resample {
        if n < 2 {
            return Err(invalid(
                "resample",
                format!("{n} points: at least 2 (the first and the last) are kept"),
            ));
        }
    }
    let mut accounted = Accounted { budget, bytes: 0 };
    let mut program = Program::new(source, settings.reader)?.with_max_lines(settings.max_lines);
    let mut held: Vec<Held> = Vec::new();
    // Contours: (first index, one past the last) of each unbroken run of cut G1 moves.
    let mut contours: Vec<std::ops::Range<usize>> = Vec::new();
    let mut units: Vec<Option<LengthUnit>> = Vec::new();
    while let Some(motion) = program.next() {
        let motion = motion?;
        if (held.len() as u64).is_multiple_of(ACCOUNT_EVERY) {
            budget.check("preprocessing the program")?;
            let bytes =
                bytes_of::<Held>(ACCOUNT_EVERY) + bytes_of::<Option<LengthUnit>>(ACCOUNT_EVERY);
            budget.account(bytes, "preprocessing the program (its motions held)")?;
            accounted.bytes += bytes;
        }
        match motion {
            Motion::Arc { line, .. } => {
                return Err(invalid(
                    field,
                    format!(
                        "line {line}: an arc (G2/G3); seed 000's preprocessing is defined on G01 \
                         polylines only (convert the arcs to G1 chords first)"
                    ),
                ));
            }
            Motion::Line {
                tool_on: true,
                line,
                ..
            } => {
                let k = held.len();
                match contours.last_mut() {
                    Some(c) if c.end == k => c.end = k + 1,
                    _ => contours.push(k..k + 1),
                }
                units.push(unit_in(program.interpreter(), line));
            }
            _ => units.push(None),
        }
        held.push((motion, program.interpreter().path_control()));
    }
    let line_of = |k: usize| held.get(k).map_or(0, |(m, _)| m.line());
    let contour = match contours.as_slice() {
        [] => {
            return Err(invalid(
                field,
                "no G01 cut in the program (G1 with the beam or spindle on, after M3/M4): \
                 nothing to preprocess",
            ))
        }
        [one] => one.clone(),
        [a, b, ..] => {
            return Err(invalid(
                field,
                format!(
                    "the cut path has {} contours (lines {}-{}, then {}-{}{}): seed 000's \
                     preprocessing takes one contour, an unbroken run of G1 moves with the tool \
                     on; plan each contour by itself",
                    contours.len(),
                    line_of(a.start),
                    line_of(a.end - 1),
                    line_of(b.start),
                    line_of(b.end - 1),
                    if contours.len() > 2 { ", ..." } else { "" }
                ),
            ))
        }
    };
    let contour = check_contour(&held, &units, contour)?;
    // The contour's points: the first move's start, then each end (repeats dropped).
    let mut points: Vec<[f64; 3]> = Vec::with_capacity(contour.range.len() + 1);
    for (m, _) in &held[contour.range.clone()] {
        if let Motion::Line { start, end, .. } = m {
            if points.is_empty() {
                points.push(*start);
            }
            if points.last() != Some(end) {
                points.push(*end);
            }
        }
    }
    let points_before = points.len();
    let length_before = polyline_length(&points);
    let mut normalization = None;
    let mut map = None;
    if let Some(side) = options.normalize {
        let metres = side * contour.unit.metres();
        let (normalized, m) = normalize(&points, metres)?;
        let before = Box2::of(&points).ok_or_else(|| invalid("normalize", "no points"))?;
        let after = Box2::of(&normalized).ok_or_else(|| invalid("normalize", "no points"))?;
        normalization = Some(Normalization {
            side,
            map: m,
            before,
            after,
        });
        map = Some(m);
        points = normalized;
    }
    let mut spacing = None;
    if let Some(n) = options.resample {
        let resampled = resample(&points, n)?;
        spacing = Some(polyline_length(&points) / (n - 1) as f64);
        points = resampled;
    }
    let report = PreprocessReport {
        unit: contour.unit,
        contour_lines: (line_of(contour.range.start), line_of(contour.range.end - 1)),
        points_before,
        length_before,
        normalization,
        points_after: points.len(),
        length_after: polyline_length(&points),
        spacing,
        rapids: held
            .iter()
            .filter(|(m, _)| matches!(m, Motion::Rapid { .. }))
            .count(),
        travel_moves: held
            .iter()
            .filter(|(m, _)| matches!(m, Motion::Line { tool_on: false, .. }))
            .count(),
        start_rapid: map.is_some_and(|m| m.apply(settings.reader.start) != settings.reader.start),
    };
    let program = write_program(&held, &contour, &points, map.as_ref(), &report, settings);
    Ok(Preprocessed { program, report })
}

/// The contour's feed, unit; refused when it is not one the seed's preprocessing defines.
fn check_contour(
    held: &[Held],
    units: &[Option<LengthUnit>],
    range: std::ops::Range<usize>,
) -> Result<Contour, GcodePlanError> {
    let mut feed = None;
    let mut unit = None;
    let mut control = None;
    let mut z = None;
    for k in range.clone() {
        let (m, c) = &held[k];
        let Motion::Line {
            start,
            end,
            feed: f,
            line,
            ..
        } = m
        else {
            continue;
        };
        let line = *line;
        let refuse = |reason: String| {
            Err(invalid(
                "preprocessing",
                format!("line {line}: {reason}; seed 000's contours are single G01 polylines"),
            ))
        };
        let z0 = *z.get_or_insert(start[2]);
        if (end[2] - z0).abs() > 1e-9 || (start[2] - z0).abs() > 1e-9 {
            return refuse(format!(
                "the contour leaves the plane Z = {:.6} m (it is not planar: seed 000's toolpaths \
                 are 2-axis, in XY)",
                z0
            ));
        }
        match (units.get(k).copied().flatten(), unit) {
            (Some(u), None) => unit = Some(u),
            (Some(u), Some(u0)) if u != u0 => {
                return refuse(format!(
                    "the length unit changes along the contour ({} to {})",
                    u0.gcode(),
                    u.gcode()
                ));
            }
            _ => {}
        }
        let f0 = *feed.get_or_insert(*f);
        if (f - f0).abs() > 1e-12 * f0.abs() {
            return refuse(format!(
                "the feed changes along the contour ({:.6} to {:.6} m/s): resampling would have \
                 to guess the feed between the new points",
                f0, f
            ));
        }
        let c0 = *control.get_or_insert(*c);
        if *c != c0 {
            return refuse("the path control mode (G61/G64) changes along the contour".into());
        }
    }
    let first_line = held.get(range.start).map_or(0, |(m, _)| m.line());
    let unit = unit.ok_or_else(|| {
        invalid(
            "preprocessing",
            format!("line {first_line}: the length unit (G20/G21) of the contour is unknown"),
        )
    })?;
    let feed = feed.ok_or_else(|| invalid("preprocessing", "the contour has no G1 move"))?;
    Ok(Contour { range, feed, unit })
}

/// A number for G-code: the shortest decimal that reads back to the same `f64` (no exponent).
fn num(v: f64) -> String {
    format!("{}", v + 0.0)
}

/// The program written out: header, the motions held (the contour replaced by `points`, the
/// others mapped by `map`), in `report.unit`.
fn write_program(
    held: &[Held],
    contour: &Contour,
    points: &[[f64; 3]],
    map: Option<&Similarity>,
    report: &PreprocessReport,
    settings: &PlanSettings,
) -> String {
    use std::fmt::Write;
    let unit = contour.unit.metres();
    let per_minute = 60.0 / unit;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "; preprocessed as seed 000 section 4.1 (kerf plan gcode): contour of lines {}-{}, {} \
         points -> {}",
        report.contour_lines.0, report.contour_lines.1, report.points_before, report.points_after
    );
    let _ = writeln!(s, "{} G90 G17", contour.unit.gcode());
    let xyz = |p: [f64; 3]| {
        let p = map.map_or(p, |m| m.apply(p));
        format!(
            "X{} Y{} Z{}",
            num(p[0] / unit),
            num(p[1] / unit),
            num(p[2] / unit)
        )
    };
    if report.start_rapid {
        let _ = writeln!(s, "G0 {}", xyz(settings.reader.start));
    }
    let mut control = PathControl::Blend {
        tolerance: None,
        naive_tolerance: None,
    };
    for (k, (m, c)) in held.iter().enumerate() {
        if k > contour.range.start && k < contour.range.end {
            continue;
        }
        if *c != control {
            let _ = match c {
                PathControl::Exact => writeln!(s, "G61"),
                PathControl::Blend {
                    tolerance,
                    naive_tolerance,
                } => {
                    let mut g = "G64".to_string();
                    if let Some(p) = tolerance {
                        let _ = write!(g, " P{}", num(p / unit));
                    }
                    if let Some(q) = naive_tolerance {
                        let _ = write!(g, " Q{}", num(q / unit));
                    }
                    writeln!(s, "{g}")
                }
            };
            control = *c;
        }
        if k == contour.range.start {
            let f = num(contour.feed * per_minute);
            for (i, p) in points.iter().enumerate().skip(1) {
                let [x, y, z] = *p;
                if i == 1 {
                    let _ = writeln!(
                        s,
                        "G1 X{} Y{} Z{} F{f}",
                        num(x / unit),
                        num(y / unit),
                        num(z / unit)
                    );
                } else {
                    let _ = writeln!(
                        s,
                        "X{} Y{} Z{}",
                        num(x / unit),
                        num(y / unit),
                        num(z / unit)
                    );
                }
            }
            continue;
        }
        let _ = match m {
            Motion::Rapid { end, .. } => writeln!(s, "G0 {}", xyz(*end)),
            Motion::Line { end, feed, .. } => {
                writeln!(s, "G1 {} F{}", xyz(*end), num(feed * per_minute))
            }
            // Refused before anything is written.
            Motion::Arc { .. } => Ok(()),
            Motion::Dwell { seconds, .. } => writeln!(s, "G4 P{}", num(*seconds)),
            Motion::Tool {
                on,
                reverse,
                speed_rpm,
                ..
            } => {
                let code = match (on, reverse) {
                    (false, _) => "M5",
                    (true, false) => "M3",
                    (true, true) => "M4",
                };
                if *on && *speed_rpm > 0.0 {
                    writeln!(s, "{code} S{}", num(*speed_rpm))
                } else {
                    writeln!(s, "{code}")
                }
            }
            Motion::End { .. } => writeln!(s, "M2"),
        };
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// The arc length at which `p` lies on the polyline (it must lie on it within 1e-12).
    fn arc_position(points: &[[f64; 3]], p: [f64; 3]) -> f64 {
        let mut s = 0.0;
        for w in points.windows(2) {
            let (a, b) = (w[0], w[1]);
            let l = distance(a, b);
            let (da, db) = (distance(a, p), distance(p, b));
            if (da + db - l).abs() <= 1e-12 * l.max(1.0) {
                return s + da;
            }
            s += l;
        }
        panic!("{p:?} is not on the polyline");
    }

    /// A zigzag of unequal segments, not self-intersecting.
    fn zigzag() -> Vec<[f64; 3]> {
        vec![
            [-4.0, 0.0, 0.5],
            [-7.0, 60.0, 0.5],
            [-16.0, 66.0, 0.5],
            [-11.0, 74.0, 0.5],
            [-8.0, 70.0, 0.5],
            [-6.0, 86.0, 0.5],
            [0.0, 98.0, 0.5],
            [0.0, 98.0, 0.5],
            [16.0, 66.0, 0.5],
            [4.0, 0.0, 0.5],
        ]
    }

    #[test]
    fn resampled_points_are_equally_spaced_along_the_contour_ends_kept() {
        let p = zigzag();
        let total = polyline_length(&p);
        for n in [2, 3, 7, 200, 1001] {
            let r = resample(&p, n).unwrap();
            assert_eq!(r.len(), n);
            assert_eq!(r[0], p[0]);
            assert_eq!(r[n - 1], p[p.len() - 1]);
            for (k, q) in r.iter().enumerate() {
                let s = arc_position(&p, *q);
                let want = total * k as f64 / (n - 1) as f64;
                assert!(close(s, want, 1e-9), "n {n} k {k}: {s} vs {want}");
                assert_eq!(q[2], 0.5);
            }
            // Chords cut corners: never longer than the contour.
            assert!(polyline_length(&r) <= total + 1e-9);
        }
        // Dense resampling converges to the contour's length.
        // Each chord across a corner is shorter than the two pieces it replaces by less than
        // twice the spacing.
        let dense = resample(&p, 100_001).unwrap();
        let spacing = total / 100_000.0;
        let short = total - polyline_length(&dense);
        assert!((0.0..=2.0 * 8.0 * spacing).contains(&short), "{short}");
    }

    #[test]
    fn a_square_resampled_at_its_corners_is_itself() {
        let sq = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
        ];
        let r = resample(&sq, 5).unwrap();
        for (a, b) in r.iter().zip(&sq) {
            for i in 0..3 {
                assert!(close(a[i], b[i], 1e-12), "{r:?}");
            }
        }
        let r = resample(&sq, 9).unwrap();
        assert!(
            close(r[1][0], 0.5, 1e-12) && close(r[1][1], 0.0, 1e-12),
            "{r:?}"
        );
        assert!(
            close(r[3][0], 1.0, 1e-12) && close(r[3][1], 0.5, 1e-12),
            "{r:?}"
        );
        assert!(close(polyline_length(&r), 4.0, 1e-12));
    }

    #[test]
    fn resampling_is_idempotent_where_the_points_are_already_equally_spaced() {
        // A straight line: any resampling is equally spaced in chords too.
        let line = [[0.0, 0.0, 0.0], [0.3, 0.1, 0.0], [3.0, 1.0, 0.0]];
        let once = resample(&line, 37).unwrap();
        let twice = resample(&once, 37).unwrap();
        for (a, b) in once.iter().zip(&twice) {
            assert!(close(a[0], b[0], 1e-9) && close(a[1], b[1], 1e-9));
        }
        // A regular polygon (closed), resampled at its own count.
        let n = 12;
        let poly: Vec<[f64; 3]> = (0..=n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                [5.0 * t.cos(), 5.0 * t.sin(), 0.0]
            })
            .collect();
        let r = resample(&poly, n + 1).unwrap();
        for (a, b) in r.iter().zip(&poly) {
            assert!(
                close(a[0], b[0], 1e-9) && close(a[1], b[1], 1e-9),
                "{a:?} {b:?}"
            );
        }
    }

    #[test]
    fn normalized_contours_fit_the_box_aspect_kept_and_normalizing_again_changes_nothing() {
        let p = zigzag();
        let before = Box2::of(&p).unwrap();
        for side in [100.0, 0.1, 1e-3 * 100.0, 7.5] {
            let (n, map) = normalize(&p, side).unwrap();
            let b = Box2::of(&n).unwrap();
            assert_eq!(b.min, [0.0, 0.0]);
            // The larger side (height, 98) scaled to L; the other (width 32) kept in proportion.
            assert!(close(b.max[1], side, 1e-12 * side), "{b:?}");
            assert!(close(b.max[0], side * 32.0 / 98.0, 1e-9 * side), "{b:?}");
            assert!(b.max[0] <= side && b.max[1] <= side);
            assert!(close(map.scale, side / 98.0, 1e-15 * map.scale));
            assert_eq!(map.origin, before.min);
            let [tx, ty] = map.offset();
            assert!(close(tx, 16.0 * side / 98.0, 1e-12) && close(ty, 0.0, 1e-12));
            // Lengths scale by s; Z is kept.
            assert!(close(
                polyline_length(&n),
                map.scale * polyline_length(&p),
                1e-9 * side
            ));
            assert!(n.iter().all(|q| q[2] == 0.5));
            // Idempotent.
            let (again, map2) = normalize(&n, side).unwrap();
            assert!(close(map2.scale, 1.0, 1e-12));
            for (a, b) in again.iter().zip(&n) {
                assert!(close(a[0], b[0], 1e-9 * side) && close(a[1], b[1], 1e-9 * side));
            }
        }
        // A wide box: the width is the side scaled.
        let wide = [[10.0, 5.0, 0.0], [50.0, 15.0, 0.0]];
        let (n, _) = normalize(&wide, 100.0).unwrap();
        assert_eq!(n[0], [0.0, 0.0, 0.0]);
        assert!(close(n[1][0], 100.0, 1e-12) && close(n[1][1], 25.0, 1e-12));
    }

    #[test]
    fn resampling_the_normalized_contour_is_the_image_of_the_resampled_one() {
        let p = zigzag();
        let (n, map) = normalize(&p, 100.0).unwrap();
        let a = resample(&n, 200).unwrap();
        let b: Vec<[f64; 3]> = resample(&p, 200)
            .unwrap()
            .into_iter()
            .map(|q| map.apply(q))
            .collect();
        for (x, y) in a.iter().zip(&b) {
            assert!(
                close(x[0], y[0], 1e-9) && close(x[1], y[1], 1e-9),
                "{x:?} {y:?}"
            );
        }
        // The other order normalizes the box of the resampled points, which misses the
        // contour's extreme corners (x = -16 here): not the same.
        let (c, _) = normalize(&resample(&p, 200).unwrap(), 100.0).unwrap();
        assert!(a.iter().zip(&c).any(|(x, y)| (x[0] - y[0]).abs() > 1e-3));
    }

    #[test]
    fn degenerate_inputs_are_refused() {
        let p = zigzag();
        for side in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(normalize(&p, side).is_err(), "{side}");
        }
        for n in [0, 1] {
            let e = resample(&p, n).unwrap_err().to_string();
            assert!(e.contains("resample"), "{e}");
        }
        let dot = [[1.0, 2.0, 0.0], [1.0, 2.0, 0.0]];
        assert!(normalize(&dot, 100.0).is_err());
        assert!(resample(&dot, 10).is_err());
        assert!(resample(&[], 10).is_err());
        assert!(resample(&[[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]], 10).is_err());
    }

    fn settings() -> PlanSettings {
        PlanSettings::laser_cutter()
    }

    fn run(text: &str, options: Preprocess) -> Result<Preprocessed, GcodePlanError> {
        preprocess_program(text.as_bytes(), &settings(), &options, &Budget::unlimited())
    }

    const W: &str = "G21 G90 G17\nG0 X0 Y30\nM3 S1000\nG1 X22 Y0 F4200\nX30 Y38\nX36 Y0\n\
                     X60 Y40\nM5\nG0 X0 Y0\nM2\n";

    #[test]
    fn a_program_is_written_back_with_its_contour_preprocessed() {
        let both = Preprocess {
            normalize: Some(100.0),
            resample: Some(50),
        };
        let out = run(W, both).unwrap();
        let r = &out.report;
        assert_eq!(r.unit, LengthUnit::Millimetre);
        assert_eq!(r.contour_lines, (4, 7));
        assert_eq!((r.points_before, r.points_after), (5, 50));
        assert_eq!((r.rapids, r.travel_moves), (2, 0));
        let n = r.normalization.unwrap();
        assert!(close(n.map.scale, 100.0 / 60.0, 1e-12));
        assert!(
            close(n.after.max[0], 0.1, 1e-15) && close(n.after.max[1], 40.0 / 60.0 * 0.1, 1e-15)
        );
        // Read back: the same contour, the rapids mapped, the tool and the feed kept.
        let motions = kerf_gcode::read_program(&out.program, Default::default()).unwrap();
        let cut: Vec<[f64; 3]> = motions
            .iter()
            .filter_map(|m| match m {
                Motion::Line {
                    end,
                    feed,
                    tool_on: true,
                    ..
                } => {
                    assert!(close(*feed, 0.07, 1e-12));
                    Some(*end)
                }
                _ => None,
            })
            .collect();
        assert_eq!(cut.len(), 49);
        assert!(close(cut[48][0], 0.1, 1e-12) && close(cut[48][1], 0.1 * 40.0 / 60.0, 1e-12));
        let rapids: Vec<[f64; 3]> = motions
            .iter()
            .filter_map(|m| match m {
                Motion::Rapid { end, .. } => Some(*end),
                _ => None,
            })
            .collect();
        // G0 X0 Y30 mm is the contour's start: (0, 30 s) mm.
        assert!(
            close(rapids[0][1], 30e-3 * 100.0 / 60.0, 1e-12),
            "{rapids:?}"
        );
        assert!(motions.iter().any(
            |m| matches!(m, Motion::Tool { on: true, speed_rpm, .. } if *speed_rpm == 1000.0)
        ));
        assert!(matches!(motions.last(), Some(Motion::End { .. })));
        // Each flag alone.
        let only = run(
            W,
            Preprocess {
                normalize: None,
                resample: Some(9),
            },
        )
        .unwrap();
        assert!(only.report.normalization.is_none());
        assert_eq!(only.report.points_after, 9);
        let only = run(
            W,
            Preprocess {
                normalize: Some(1.0),
                resample: None,
            },
        )
        .unwrap();
        assert_eq!(only.report.points_after, 5);
        assert!(only.report.spacing.is_none());
    }

    #[test]
    fn a_contour_cut_from_the_start_position_keeps_its_first_point() {
        let text = "M3\nG1 X-10 Y5 F100\nX20 Y25\nM5\nM2\n";
        let opts = Preprocess {
            normalize: Some(100.0),
            resample: None,
        };
        let out = run(text, opts).unwrap();
        assert!(out.report.start_rapid);
        let map = out.report.normalization.unwrap().map;
        let motions = kerf_gcode::read_program(&out.program, Default::default()).unwrap();
        let Some(Motion::Rapid { end, .. }) = motions.first() else {
            panic!("{motions:?}");
        };
        let want = map.apply([0.0; 3]);
        assert!(close(end[0], want[0], 1e-15) && close(end[1], want[1], 1e-15));
        let first_cut = motions
            .iter()
            .find_map(|m| match m {
                Motion::Line { start, .. } => Some(*start),
                _ => None,
            })
            .unwrap();
        assert!(
            close(first_cut[0], 10e-3 * map.scale, 1e-12),
            "{first_cut:?}"
        );
        // Resampling alone moves nothing.
        let out = run(
            text,
            Preprocess {
                normalize: None,
                resample: Some(5),
            },
        )
        .unwrap();
        assert!(!out.report.start_rapid);
    }

    #[test]
    fn inches_are_the_programs_unit() {
        let text = "G20 G90\nG0 X0 Y1\nM3\nG1 X1 Y0 F100\nX2 Y2\nM5\nM2\n";
        let out = run(
            text,
            Preprocess {
                normalize: Some(4.0),
                resample: None,
            },
        )
        .unwrap();
        assert_eq!(out.report.unit, LengthUnit::Inch);
        let n = out.report.normalization.unwrap();
        assert!(close(n.after.max[1], 4.0 * 0.0254, 1e-15), "{n:?}");
        assert!(out.program.contains("G20"));
    }

    #[test]
    fn what_the_seed_does_not_define_is_refused() {
        let opts = Preprocess {
            normalize: Some(100.0),
            resample: Some(200),
        };
        let cases = [
            (
                "G0 X0 Y0\nM3\nG1 X1 F100\nG2 X3 Y0 I1 J0\nM5\n",
                "line 4: an arc",
            ),
            (
                "M3\nG1 X1 F100\nX2 Y1\nM5\nG0 X5\nM3\nG1 X6 Y1\nM5\n",
                "2 contours (lines 2-3, then 7-7)",
            ),
            ("G0 X1\nG1 X2 F100\n", "no G01 cut"),
            (
                "M3\nG1 X1 F100\nX2 Z-1\n",
                "line 3: the contour leaves the plane",
            ),
            ("M3\nG1 X1 F100\nX2 F200\n", "line 3: the feed changes"),
            ("M3\nG1 X1 F100\nG61 X2\n", "line 3: the path control mode"),
            (
                "M3\nG1 X1 F100\nG20 X2\n",
                "line 3: the length unit changes",
            ),
            ("G0 X1\nM3\nG1 X1 F100\n", "zero extent"),
        ];
        for (text, expect) in cases {
            let e = run(text, opts).unwrap_err().to_string();
            assert!(e.contains(expect), "{text}: {e}");
        }
        let e = run(
            W,
            Preprocess {
                normalize: Some(f64::NAN),
                resample: None,
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("normalize"), "{e}");
        let e = run(
            W,
            Preprocess {
                normalize: None,
                resample: Some(0),
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("resample"), "{e}");
    }

    #[test]
    fn the_motions_held_are_accounted_and_given_back() {
        let budget = Budget::unlimited().with_memory(Some(1 << 30));
        let opts = Preprocess {
            normalize: None,
            resample: Some(10),
        };
        preprocess_program(W.as_bytes(), &settings(), &opts, &budget).unwrap();
        assert_eq!(budget.memory_used(), 0);
        let tight = Budget::unlimited().with_memory(Some(1024));
        let e = preprocess_program(W.as_bytes(), &settings(), &opts, &tight).unwrap_err();
        assert!(matches!(e, GcodePlanError::Interrupted(_)), "{e}");
    }
}
