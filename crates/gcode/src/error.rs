//! [`GcodeError`]: every way a program can be refused, with its place.

use thiserror::Error;

/// Why a program (or a point list) was refused. `line` and `column` are
/// 1-based positions in the source text (columns count characters).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GcodeError {
    /// The text is not G-code: a bad character, a letter without a number,
    /// a malformed number, an unclosed comment.
    #[error("line {line}, column {column}: {reason}")]
    Syntax {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// What is wrong.
        reason: String,
    },
    /// A code or word this reader does not execute (it is never skipped).
    #[error("line {line}, column {column}: {code} is not supported ({reason})")]
    Unsupported {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The code as written, e.g. `G93` or `A`.
        code: String,
        /// Why, or what to use instead.
        reason: String,
    },
    /// Two words of one modal group (or one letter twice) in a block.
    #[error(
        "line {line}, column {column}: {second} conflicts with {first} in the same block ({group})"
    )]
    Conflict {
        /// Line.
        line: usize,
        /// Column of the second word.
        column: usize,
        /// The modal group or the letter.
        group: String,
        /// The first word.
        first: String,
        /// The second word.
        second: String,
    },
    /// A word has a value it cannot take (a negative dwell, a zero
    /// radius, a non-integer code, a number too large to be finite).
    #[error("line {line}, column {column}: {word} = {value}: {reason}")]
    BadValue {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The word's letter (or code).
        word: String,
        /// Its value.
        value: f64,
        /// The rule it breaks.
        reason: String,
    },
    /// An arc whose end point is not on its circle within the tolerance,
    /// or whose geometry is undefined.
    #[error("line {line}, column {column}: arc {reason}")]
    Arc {
        /// Line.
        line: usize,
        /// Column of the motion word (or the block's first word).
        column: usize,
        /// What is wrong, with the numbers.
        reason: String,
    },
    /// A cutting move (G1, G2, G3) before any feed was programmed.
    #[error("line {line}, column {column}: cutting move without a feed (program F before the first G1/G2/G3)")]
    MissingFeed {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
    },
    /// Axis words with no motion mode in effect.
    #[error("line {line}, column {column}: axis words without a motion mode (G0, G1, G2 or G3)")]
    NoMotionMode {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
    },
    /// Text after the program end (M2/M30) that is not blank or a comment.
    #[error(
        "line {line}, column {column}: text after the program end (M2/M30 on line {end_line})"
    )]
    AfterEnd {
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// The line of the program end.
        end_line: usize,
    },
    /// The program goes on past the most lines the reader takes
    /// ([`crate::Program::with_max_lines`]): `line` is the first line beyond the limit.
    #[error(
        "line {line}: more than {max} lines (the limit; line {line} is the first beyond it: \
         split the program)"
    )]
    TooManyLines {
        /// The first line beyond the limit (`max + 1`).
        line: usize,
        /// The most lines read.
        max: usize,
    },
    /// A setting of the reader is out of range.
    #[error("setting {name} = {value}: {reason}")]
    InvalidSetting {
        /// The setting.
        name: String,
        /// Its value.
        value: f64,
        /// The rule.
        reason: String,
    },
    /// Reading the source failed.
    #[error("line {line}: read error: {message}")]
    Io {
        /// The line being read.
        line: usize,
        /// The I/O error.
        message: String,
    },
}

impl GcodeError {
    /// The 1-based line the error is on (0 for a setting).
    pub fn line(&self) -> usize {
        match self {
            Self::Syntax { line, .. }
            | Self::Unsupported { line, .. }
            | Self::Conflict { line, .. }
            | Self::BadValue { line, .. }
            | Self::Arc { line, .. }
            | Self::MissingFeed { line, .. }
            | Self::NoMotionMode { line, .. }
            | Self::AfterEnd { line, .. }
            | Self::TooManyLines { line, .. }
            | Self::Io { line, .. } => *line,
            Self::InvalidSetting { .. } => 0,
        }
    }
}
