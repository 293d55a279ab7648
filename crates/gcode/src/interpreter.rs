//! The modal interpreter: blocks ([`crate::lexer`]) into [`Motion`]s, in SI
//! units, in the order of execution of NISTIR 6556 (Kramer, Proctor and
//! Messina, "The NIST RS274NGC Interpreter — Version 3", 2000), Table 8:
//! feed (F), spindle speed (S), spindle on/off (M3, M4, M5), dwell (G4),
//! plane (G17–G19), length units (G20, G21), cutter radius compensation
//! (G40), tool length offset (G49), coordinate system (G54), path control
//! (G61, G61.1, G64), distance mode (G90, G91, G90.1, G91.1), motion (G0–G3,
//! G80), stop (M2, M30).
//!
//! Supported, the common subset as LinuxCNC reads it: G0, G1, G2/G3 (IJK
//! and R forms, full circles, helical, P turns), G4, G17/G18/G19, G20/G21,
//! G90/G91, G90.1/G91.1, G94 (units per minute, the only feed mode), M3/M4/M5,
//! M2/M30. G40, G49, G54 and G80 are accepted as the states kerf has anyway
//! (no cutter compensation, no tool length offset, the one coordinate
//! system with zero offsets, no canned cycle); G61, G61.1 and G64 (with its
//! P and Q) are accepted and recorded ([`Interpreter::path_control`]): the
//! front end's corner tolerance is the request's, not the program's. Every
//! other code and letter is an error naming it.

use crate::arc::{build_arc, ArcSpec};
use crate::error::GcodeError;
use crate::lexer::{Block, Word};
use crate::motion::{Motion, Plane};
use crate::settings::ReaderSettings;

/// The most turns P of one arc (a helix): more is refused as the program is read.
pub const MAX_ARC_TURNS: u32 = 1_000_000;

/// Metres per inch (exact, by definition).
pub const METRES_PER_INCH: f64 = 0.0254;

/// Path control mode (G61, G61.1, G64).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathControl {
    /// G61 or G61.1: exact path.
    Exact,
    /// G64: blending, with the P tolerance \[m\] if given (and Q's naive
    /// cam tolerance \[m\]).
    Blend {
        /// P \[m\].
        tolerance: Option<f64>,
        /// Q \[m\].
        naive_tolerance: Option<f64>,
    },
}

/// The modal motion code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum MotionMode {
    Rapid,
    Line,
    ArcCw,
    ArcCcw,
}

/// The interpreter's state between blocks (the modal state and position).
#[derive(Debug, Clone, PartialEq)]
pub struct Interpreter {
    settings: ReaderSettings,
    position: [f64; 3],
    motion: Option<MotionMode>,
    plane: Plane,
    /// Metres per program length unit (G21: 1e-3, G20: 0.0254).
    unit: f64,
    absolute: bool,
    absolute_arc_center: bool,
    /// F as programmed (length units per minute), if set.
    feed: Option<f64>,
    spindle_speed: f64,
    tool_on: bool,
    path_control: PathControl,
    ended: Option<usize>,
}

/// A G code as ten times its number (G90.1 → 901), if it is one decimal.
fn code10(value: f64) -> Option<i64> {
    let t = (value * 10.0).round();
    ((value * 10.0 - t).abs() < 1e-6 && t >= 0.0).then_some(t as i64)
}

fn code_name(letter: char, c10: i64) -> String {
    if c10 % 10 == 0 {
        format!("{letter}{}", c10 / 10)
    } else {
        format!("{letter}{}.{}", c10 / 10, c10 % 10)
    }
}

/// The modal group of a supported G code (×10), or `None`.
fn g_group(c10: i64) -> Option<&'static str> {
    Some(match c10 {
        0 | 10 | 20 | 30 | 800 => "motion (group 1)",
        40 => "non-modal (group 0)",
        170 | 180 | 190 => "plane (group 2)",
        200 | 210 => "length units (group 6)",
        400 => "cutter radius compensation (group 7)",
        490 => "tool length offset (group 8)",
        540 => "coordinate system (group 12)",
        610 | 611 | 640 => "path control (group 13)",
        900 | 910 => "distance mode (group 3)",
        901 | 911 => "arc distance mode (group 4)",
        940 => "feed rate mode (group 5)",
        _ => return None,
    })
}

/// The modal group of a supported M code, or `None`.
fn m_group(code: i64) -> Option<&'static str> {
    Some(match code {
        2 | 30 => "stopping (group 4)",
        3..=5 => "spindle (group 7)",
        _ => return None,
    })
}

/// Letters this reader takes besides G, M (and N, taken by the lexer).
const LETTERS: &str = "XYZIJKRFPQS";

impl Interpreter {
    /// A fresh interpreter: at `settings.start`, millimetres, absolute
    /// distances, incremental arc centres (G91.1), XY plane, no motion mode,
    /// no feed, tool off (LinuxCNC's defaults); path blending (G64) without
    /// a P tolerance: kerf's choice, so that a program is smoothed within
    /// the planner's tolerance unless it says G61 (exact path, a stop at
    /// every vertex).
    ///
    /// # Errors
    /// [`ReaderSettings::validate`].
    pub fn new(settings: ReaderSettings) -> Result<Self, GcodeError> {
        settings.validate()?;
        Ok(Self {
            settings,
            position: settings.start,
            motion: None,
            plane: Plane::Xy,
            unit: 1e-3,
            absolute: true,
            absolute_arc_center: false,
            feed: None,
            spindle_speed: 0.0,
            tool_on: false,
            path_control: PathControl::Blend {
                tolerance: None,
                naive_tolerance: None,
            },
            ended: None,
        })
    }

    /// The position \[m\].
    pub fn position(&self) -> [f64; 3] {
        self.position
    }

    /// The path control mode in effect.
    pub fn path_control(&self) -> PathControl {
        self.path_control
    }

    /// Whether M2/M30 was read (and on which line).
    pub fn ended(&self) -> Option<usize> {
        self.ended
    }

    /// The settings.
    pub fn settings(&self) -> &ReaderSettings {
        &self.settings
    }

    /// Executes one block, appending its motions to `out` (nothing is
    /// appended when the block fails: the state is left as it was).
    ///
    /// # Errors
    /// Every [`GcodeError`] kind but `Io` and `InvalidSetting`, naming the
    /// line and column.
    pub fn execute(&mut self, block: &Block, out: &mut Vec<Motion>) -> Result<(), GcodeError> {
        if block.deleted && self.settings.block_delete {
            return Ok(());
        }
        if block.is_empty() {
            return Ok(());
        }
        let line = block.line;
        if let Some(end_line) = self.ended {
            return Err(GcodeError::AfterEnd {
                line,
                column: block.words[0].column,
                end_line,
            });
        }
        let parsed = Parsed::from_block(block)?;
        let mut next = self.clone();
        let mut motions = Vec::new();
        next.apply(&parsed, line, &mut motions)?;
        *self = next;
        out.extend(motions);
        Ok(())
    }

    fn apply(&mut self, p: &Parsed, line: usize, out: &mut Vec<Motion>) -> Result<(), GcodeError> {
        let bad = |w: &Word, reason: &str| GcodeError::BadValue {
            line,
            column: w.column,
            word: w.letter.to_string(),
            value: w.value,
            reason: reason.to_string(),
        };
        // Feed mode (G94 only), F, S.
        if let Some(w) = p.letter('F') {
            if w.value < 0.0 {
                return Err(bad(w, "a feed must be >= 0"));
            }
            self.feed = Some(w.value);
        }
        if let Some(w) = p.letter('S') {
            if w.value < 0.0 {
                return Err(bad(w, "a spindle speed must be >= 0"));
            }
            self.spindle_speed = w.value;
        }
        // Spindle / beam.
        if let Some((code, _)) = p.m(&[3, 4, 5]) {
            self.tool_on = code != 5;
            out.push(Motion::Tool {
                on: self.tool_on,
                reverse: code == 4,
                speed_rpm: self.spindle_speed,
                line,
            });
        }
        // Dwell.
        let dwell = p.g(&[40]);
        if let Some((_, gw)) = dwell {
            if let Some(axis) = p.axis_word() {
                return Err(GcodeError::Conflict {
                    line,
                    column: axis.column,
                    group: "G4 takes no axis words".to_string(),
                    first: "G4".to_string(),
                    second: axis.letter.to_string(),
                });
            }
            let Some(pw) = p.letter('P') else {
                return Err(GcodeError::BadValue {
                    line,
                    column: gw.column,
                    word: "G4".to_string(),
                    value: 4.0,
                    reason: "a dwell needs its time P [s]".to_string(),
                });
            };
            if pw.value < 0.0 {
                return Err(bad(pw, "a dwell time must be >= 0 s"));
            }
            out.push(Motion::Dwell {
                seconds: pw.value,
                line,
            });
        }
        // Plane, units, path control, distance modes.
        if let Some((c, _)) = p.g(&[170, 180, 190]) {
            self.plane = match c {
                170 => Plane::Xy,
                180 => Plane::Zx,
                _ => Plane::Yz,
            };
        }
        if let Some((c, _)) = p.g(&[200, 210]) {
            self.unit = if c == 200 { METRES_PER_INCH } else { 1e-3 };
        }
        if let Some((c, _)) = p.g(&[610, 611, 640]) {
            self.path_control = if c == 640 {
                let length = |l: char| -> Result<Option<f64>, GcodeError> {
                    match p.letter(l) {
                        Some(w) if w.value < 0.0 => Err(bad(w, "a tolerance must be >= 0")),
                        Some(w) => Ok(Some(w.value * self.unit)),
                        None => Ok(None),
                    }
                };
                PathControl::Blend {
                    tolerance: length('P')?,
                    naive_tolerance: length('Q')?,
                }
            } else {
                PathControl::Exact
            };
        }
        if let Some((c, _)) = p.g(&[900, 910]) {
            self.absolute = c == 900;
        }
        if let Some((c, _)) = p.g(&[901, 911]) {
            self.absolute_arc_center = c == 901;
        }
        // Motion.
        if let Some((c, _)) = p.g(&[0, 10, 20, 30, 800]) {
            self.motion = match c {
                0 => Some(MotionMode::Rapid),
                10 => Some(MotionMode::Line),
                20 => Some(MotionMode::ArcCw),
                30 => Some(MotionMode::ArcCcw),
                _ => None,
            };
            if c == 800 {
                if let Some(axis) = p.axis_word() {
                    return Err(GcodeError::Conflict {
                        line,
                        column: axis.column,
                        group: "G80 cancels the motion mode".to_string(),
                        first: "G80".to_string(),
                        second: axis.letter.to_string(),
                    });
                }
            }
        }
        let arc_words = p.arc_word();
        let moves = p.axis_word().is_some() || (p.motion_word && arc_words.is_some());
        if let Some(w) = arc_words {
            if !matches!(self.motion, Some(MotionMode::ArcCw | MotionMode::ArcCcw)) || !moves {
                return Err(GcodeError::Unsupported {
                    line,
                    column: w.column,
                    code: w.letter.to_string(),
                    reason: "I, J, K and R belong to a G2/G3 move".to_string(),
                });
            }
        }
        if let Some(w) = p.letter('P') {
            let used = dwell.is_some()
                || p.g(&[640]).is_some()
                || (moves && matches!(self.motion, Some(MotionMode::ArcCw | MotionMode::ArcCcw)));
            if !used {
                return Err(GcodeError::Unsupported {
                    line,
                    column: w.column,
                    code: "P".to_string(),
                    reason: "P belongs to G4, G64 or a G2/G3 move".to_string(),
                });
            }
        }
        if let Some(w) = p.letter('Q') {
            if p.g(&[640]).is_none() {
                return Err(GcodeError::Unsupported {
                    line,
                    column: w.column,
                    code: "Q".to_string(),
                    reason: "Q belongs to G64".to_string(),
                });
            }
        }
        if moves {
            let Some(mode) = self.motion else {
                let column = p.axis_word().or(arc_words).map_or(1, |w| w.column);
                return Err(GcodeError::NoMotionMode { line, column });
            };
            let column = p.first_column;
            let start = self.position;
            let mut end = start;
            for (k, l) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                if let Some(w) = p.letter(l) {
                    let v = w.value * self.unit;
                    end[k] = if self.absolute { v } else { start[k] + v };
                }
            }
            if end.iter().any(|v| !v.is_finite()) {
                return Err(GcodeError::BadValue {
                    line,
                    column,
                    word: "XYZ".to_string(),
                    value: f64::INFINITY,
                    reason: "the end point is not finite".to_string(),
                });
            }
            match mode {
                MotionMode::Rapid => out.push(Motion::Rapid { start, end, line }),
                MotionMode::Line => {
                    let feed = self.feed_m_per_s(line, column)?;
                    out.push(Motion::Line {
                        start,
                        end,
                        feed,
                        tool_on: self.tool_on,
                        line,
                    });
                }
                MotionMode::ArcCw | MotionMode::ArcCcw => {
                    let feed = self.feed_m_per_s(line, column)?;
                    let spec = self.arc_spec(p, start, line, column)?;
                    let turns = match p.letter('P') {
                        None => 1,
                        Some(w) => {
                            if !(w.value >= 1.0
                                && w.value.fract() == 0.0
                                && w.value <= MAX_ARC_TURNS as f64)
                            {
                                return Err(bad(
                                    w,
                                    "the turns P of an arc must be an integer in [1, 1000000]",
                                ));
                            }
                            w.value as u32
                        }
                    };
                    let arc = build_arc(
                        start,
                        end,
                        self.plane,
                        mode == MotionMode::ArcCw,
                        spec,
                        turns,
                        (
                            self.settings.arc_tolerance,
                            self.settings.arc_relative_tolerance,
                        ),
                    )
                    .map_err(|reason| GcodeError::Arc {
                        line,
                        column,
                        reason,
                    })?;
                    out.push(Motion::Arc {
                        arc,
                        feed,
                        tool_on: self.tool_on,
                        line,
                    });
                }
            }
            self.position = end;
        }
        if p.m(&[2, 30]).is_some() {
            self.tool_on = false;
            self.ended = Some(line);
            out.push(Motion::End { line });
        }
        Ok(())
    }

    /// The programmed feed in m/s (G94: length units per minute).
    fn feed_m_per_s(&self, line: usize, column: usize) -> Result<f64, GcodeError> {
        match self.feed {
            Some(f) if f > 0.0 => Ok(f * self.unit / 60.0),
            _ => Err(GcodeError::MissingFeed { line, column }),
        }
    }

    /// The centre or radius of a G2/G3 block.
    fn arc_spec(
        &self,
        p: &Parsed,
        start: [f64; 3],
        line: usize,
        column: usize,
    ) -> Result<ArcSpec, GcodeError> {
        let [a, b, n] = self.plane.axes();
        let offset_letter = |axis: usize| ['I', 'J', 'K'][axis];
        if let Some(w) = p.letter(offset_letter(n)) {
            return Err(GcodeError::Unsupported {
                line,
                column: w.column,
                code: w.letter.to_string(),
                reason: format!(
                    "the offset along the arc plane's normal (the plane is {:?})",
                    self.plane
                ),
            });
        }
        let offsets = [p.letter(offset_letter(a)), p.letter(offset_letter(b))];
        match (p.letter('R'), offsets) {
            (Some(r), [None, None]) => Ok(ArcSpec::Radius(r.value * self.unit)),
            (Some(r), _) => Err(GcodeError::Conflict {
                line,
                column: r.column,
                group: "arc format".to_string(),
                first: "I/J/K".to_string(),
                second: "R".to_string(),
            }),
            (None, [None, None]) => Err(GcodeError::Arc {
                line,
                column,
                reason: "needs a centre (I, J, K) or a radius R".to_string(),
            }),
            (None, [oa, ob]) => {
                let mut c = start;
                for (axis, w) in [(a, oa), (b, ob)] {
                    let v = w.map_or(0.0, |w| w.value * self.unit);
                    c[axis] = if self.absolute_arc_center {
                        // G90.1: absolute; a missing offset is the axis' zero.
                        v
                    } else {
                        start[axis] + v
                    };
                }
                Ok(ArcSpec::Center(c))
            }
        }
    }
}

/// A block's words checked for this reader: supported codes and letters,
/// one word per modal group and letter.
struct Parsed {
    /// (code ×10, word) of the G words.
    g: Vec<(i64, Word)>,
    /// (code, word) of the M words.
    m: Vec<(i64, Word)>,
    /// Other words by letter.
    others: Vec<Word>,
    /// A G0–G3 word is in the block.
    motion_word: bool,
    /// Column of the first word.
    first_column: usize,
}

impl Parsed {
    fn from_block(block: &Block) -> Result<Self, GcodeError> {
        let line = block.line;
        let mut g: Vec<(i64, Word)> = Vec::new();
        let mut m: Vec<(i64, Word)> = Vec::new();
        let mut others: Vec<Word> = Vec::new();
        let mut groups: Vec<(&'static str, String)> = Vec::new();
        for w in &block.words {
            match w.letter {
                'G' | 'M' => {
                    let c10 = code10(w.value).ok_or_else(|| GcodeError::BadValue {
                        line,
                        column: w.column,
                        word: w.letter.to_string(),
                        value: w.value,
                        reason: "a code is a non-negative number with at most one decimal"
                            .to_string(),
                    })?;
                    let name = code_name(w.letter, c10);
                    let group = if w.letter == 'G' {
                        g_group(c10)
                    } else if c10 % 10 == 0 {
                        m_group(c10 / 10)
                    } else {
                        None
                    };
                    let Some(group) = group else {
                        let reason = match (w.letter, c10) {
                            ('G', 930) | ('G', 950) => "kerf reads feeds in units per minute (G94) only",
                            ('M', _) => "the supported M codes are M2, M3, M4, M5 and M30",
                            _ => "not in the subset kerf reads (G0-G4, G17-G21, G40, G49, G54, G61, G61.1, G64, G80, G90, G91, G90.1, G91.1, G94)",
                        };
                        return Err(GcodeError::Unsupported {
                            line,
                            column: w.column,
                            code: name,
                            reason: reason.to_string(),
                        });
                    };
                    if let Some((_, first)) = groups.iter().find(|(gr, _)| *gr == group) {
                        return Err(GcodeError::Conflict {
                            line,
                            column: w.column,
                            group: group.to_string(),
                            first: first.clone(),
                            second: name,
                        });
                    }
                    groups.push((group, name));
                    if w.letter == 'G' {
                        g.push((c10, *w));
                    } else {
                        m.push((c10 / 10, *w));
                    }
                }
                l if LETTERS.contains(l) => {
                    if let Some(first) = others.iter().find(|o| o.letter == l) {
                        return Err(GcodeError::Conflict {
                            line,
                            column: w.column,
                            group: format!("the letter {l} twice"),
                            first: format!("{l}{}", first.value),
                            second: format!("{l}{}", w.value),
                        });
                    }
                    others.push(*w);
                }
                l => {
                    return Err(GcodeError::Unsupported {
                        line,
                        column: w.column,
                        code: l.to_string(),
                        reason: "the words kerf reads are G, M, N, X, Y, Z, I, J, K, R, F, P, Q, S"
                            .to_string(),
                    })
                }
            }
        }
        let motion_word = g.iter().any(|(c, _)| matches!(c, 0 | 10 | 20 | 30));
        let first_column = block.words.first().map_or(1, |w| w.column);
        Ok(Self {
            g,
            m,
            others,
            motion_word,
            first_column,
        })
    }

    fn letter(&self, l: char) -> Option<&Word> {
        self.others.iter().find(|w| w.letter == l)
    }

    fn g(&self, codes: &[i64]) -> Option<(i64, Word)> {
        self.g.iter().find(|(c, _)| codes.contains(c)).copied()
    }

    fn m(&self, codes: &[i64]) -> Option<(i64, Word)> {
        self.m.iter().find(|(c, _)| codes.contains(c)).copied()
    }

    fn axis_word(&self) -> Option<&Word> {
        self.others
            .iter()
            .find(|w| matches!(w.letter, 'X' | 'Y' | 'Z'))
    }

    fn arc_word(&self) -> Option<&Word> {
        self.others
            .iter()
            .find(|w| matches!(w.letter, 'I' | 'J' | 'K' | 'R'))
    }
}
