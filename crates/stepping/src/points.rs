//! Reference points as text: one point per line, 1 to 6 numbers separated
//! by blanks or commas, every line the same count; `#` or `;` starts a
//! comment; blank lines are skipped.

use crate::{error::StepError, spline::MAX_AXES};

/// Most points a text may hold (10⁶: 48 MB of coordinates at 6 axes).
pub const MAX_POINTS: usize = 1_000_000;

/// Reads the points of `text`, each number multiplied by `scale` (1 for
/// metres or radians, 1e-3 for millimetres).
///
/// # Errors
/// [`StepError::InvalidPoint`] naming the line: a token that is not a
/// number, a number that is not finite, no number or more than six, a count
/// that differs from the first line's, more than [`MAX_POINTS`] points, or
/// fewer than two.
pub fn parse_points(text: &str, scale: f64) -> Result<Vec<Vec<f64>>, StepError> {
    let mut out: Vec<Vec<f64>> = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let body = line.find(['#', ';']).map_or(line, |cut| &line[..cut]);
        let tokens: Vec<&str> = body
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
            .collect();
        if tokens.is_empty() {
            continue;
        }
        let bad = |reason: String| StepError::InvalidPoint {
            index: out.len(),
            reason: format!("line {}: {reason}", k + 1),
        };
        if tokens.len() > MAX_AXES {
            return Err(bad(format!(
                "{} numbers; 1 to {MAX_AXES} coordinates per point",
                tokens.len()
            )));
        }
        let mut p = Vec::with_capacity(tokens.len());
        for t in tokens {
            let v: f64 = t
                .parse()
                .map_err(|_| bad(format!("'{t}' is not a number")))?;
            if !v.is_finite() {
                return Err(bad(format!("{t} is not finite")));
            }
            p.push(v * scale);
        }
        if let Some(first) = out.first() {
            if first.len() != p.len() {
                return Err(bad(format!(
                    "{} coordinates, the first point has {}",
                    p.len(),
                    first.len()
                )));
            }
        }
        if out.len() == MAX_POINTS {
            return Err(bad(format!("more than {MAX_POINTS} points")));
        }
        out.push(p);
    }
    if out.len() < 2 {
        return Err(StepError::InvalidPoint {
            index: out.len(),
            reason: format!(
                "{} point(s): a start and at least one point to pass are needed",
                out.len()
            ),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_with_comments_commas_and_units() {
        let p = parse_points("# start\n0, 0\n\n1 2 ; a point\n3,4\n", 1e-3).unwrap();
        assert_eq!(p, vec![vec![0.0, 0.0], vec![1e-3, 2e-3], vec![3e-3, 4e-3]]);
    }

    #[test]
    fn bad_lines_are_named() {
        for (text, want) in [
            ("0\nx\n", "line 2: 'x' is not a number"),
            ("0\nNaN\n", "line 2: NaN is not finite"),
            ("0 0\n1\n", "line 2: 1 coordinates, the first point has 2"),
            ("1 2 3 4 5 6 7\n", "line 1: 7 numbers"),
            ("1\n", "1 point(s)"),
        ] {
            let e = parse_points(text, 1.0).unwrap_err().to_string();
            assert!(e.contains(want), "{text:?}: {e}");
        }
    }
}
