//! Plain point lists: one point per line, `x y [z]` (blanks or commas
//! between the numbers; `#` or `;` starts a comment; blank lines are
//! skipped), the format of seed 000's contours. Every number keeps `f64`
//! precision; the result is in metres.

use std::io::BufRead;

use crate::error::GcodeError;

/// The length unit of a point list's numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointUnit {
    /// Millimetres.
    Millimetre,
    /// Metres.
    Metre,
}

impl PointUnit {
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            PointUnit::Millimetre => 1e-3,
            PointUnit::Metre => 1.0,
        }
    }
}

/// Reads a point list.
///
/// # Arguments
/// * `source` — the text, read line by line.
/// * `unit` — the unit of its numbers.
///
/// # Returns
/// The points in metres (z = 0 where a line has two numbers).
///
/// # Errors
/// [`GcodeError::Syntax`] for a line with another count of numbers or a
/// token that is not a number, naming the line and column;
/// [`GcodeError::BadValue`] for a number that is not finite;
/// [`GcodeError::Io`].
pub fn read_points<R: BufRead>(source: R, unit: PointUnit) -> Result<Vec<[f64; 3]>, GcodeError> {
    let mut out = Vec::new();
    for (k, text) in source.lines().enumerate() {
        let line = k + 1;
        let text = text.map_err(|e| GcodeError::Io {
            line,
            message: e.to_string(),
        })?;
        let body = text
            .find(['#', ';'])
            .map_or(text.as_str(), |cut| &text[..cut]);
        let mut values = Vec::with_capacity(3);
        let mut column = 1;
        for token in body.split(|c: char| c.is_whitespace() || c == ',') {
            if token.is_empty() {
                column += 1;
                continue;
            }
            let char_column = body[..column - 1].chars().count() + 1;
            let v: f64 = token.parse().map_err(|_| GcodeError::Syntax {
                line,
                column: char_column,
                reason: format!("{token:?} is not a number"),
            })?;
            if !v.is_finite() {
                return Err(GcodeError::BadValue {
                    line,
                    column: char_column,
                    word: "point".to_string(),
                    value: v,
                    reason: "not a finite number".to_string(),
                });
            }
            values.push(v * unit.metres());
            column += token.len() + 1;
        }
        match values.len() {
            0 => {}
            2 => out.push([values[0], values[1], 0.0]),
            3 => out.push([values[0], values[1], values[2]]),
            n => {
                return Err(GcodeError::Syntax {
                    line,
                    column: 1,
                    reason: format!("{n} numbers: a point is x y or x y z"),
                })
            }
        }
    }
    Ok(out)
}
