//! The `MIN:MAX:COUNT` grids of `kerf lobes --rpm` and `--feed`, checked at parse time by
//! [`GridParser`] (finite, normal, bounded values and a bounded count).

use std::ffi::OsStr;

use clap::{builder::TypedValueParser, error::ErrorKind, Arg, Command};

use crate::bounds::{Count, Real};

/// An evenly spaced grid `MIN:MAX:COUNT` (COUNT = 1 needs MIN = MAX).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// First value.
    pub min: f64,
    /// Last value.
    pub max: f64,
    /// Number of values (≥ 1).
    pub count: usize,
}

impl Grid {
    /// Validates a grid: MIN <= MAX, MIN >= `lower` (> when `strict`), COUNT >= 1, COUNT 1
    /// only with MIN = MAX.
    ///
    /// # Errors
    /// A message naming the option: NaN or infinite bounds, MIN > MAX, COUNT 0, COUNT 1 with
    /// MIN ≠ MAX, a bound under `lower`.
    pub fn new(
        name: &str,
        min: f64,
        max: f64,
        count: usize,
        lower: f64,
        strict: bool,
    ) -> Result<Self, String> {
        let text = format!("{min}:{max}:{count}");
        if !(min.is_finite() && max.is_finite()) {
            return Err(format!("--{name} {text}: bounds must be finite"));
        }
        if min > max {
            return Err(format!("--{name} {text}: MIN {min} > MAX {max}"));
        }
        if count == 0 {
            return Err(format!("--{name} {text}: COUNT must be >= 1"));
        }
        if count == 1 && min != max {
            return Err(format!("--{name} {text}: COUNT 1 needs MIN = MAX"));
        }
        if min < lower || (strict && min == lower) {
            let rel = if strict { ">" } else { ">=" };
            return Err(format!("--{name} {text}: MIN must be {rel} {lower}"));
        }
        Ok(Self { min, max, count })
    }

    /// The values, evenly spaced from `min` to `max` inclusive.
    pub fn values(&self) -> Vec<f64> {
        if self.count == 1 {
            return vec![self.min];
        }
        let n = (self.count - 1) as f64;
        (0..self.count)
            .map(|i| self.min + (self.max - self.min) * i as f64 / n)
            .collect()
    }
}

/// The value parser of a grid argument: `MIN:MAX:COUNT` with MIN and MAX in `values` and
/// COUNT in `count` (the refusal and `--help` state both ranges).
#[derive(Debug, Clone, Copy)]
pub struct GridParser {
    /// The option's name without dashes (`rpm`, `feed`).
    pub name: &'static str,
    /// The range of MIN and MAX.
    pub values: Real,
    /// The range of COUNT.
    pub count: Count<usize>,
}

impl GridParser {
    /// The ranges as stated in `--help` and refusals.
    pub fn range(&self) -> String {
        format!(
            "MIN:MAX:COUNT, MIN and MAX in {}, COUNT in {}",
            self.values.range(),
            self.count.range()
        )
    }

    /// Checks `text`.
    ///
    /// # Errors
    /// Why it is refused: syntax, a bound or the count out of its range, MIN > MAX, COUNT 1
    /// with MIN ≠ MAX.
    pub fn check(&self, text: &str) -> Result<Grid, String> {
        let parts: Vec<&str> = text.split(':').collect();
        let [min, max, count] = parts[..] else {
            return Err("expected MIN:MAX:COUNT".into());
        };
        let min = self
            .values
            .check(min)
            .map_err(|e| format!("MIN is {}: {e}", min.trim()))?;
        let max = self
            .values
            .check(max)
            .map_err(|e| format!("MAX is {}: {e}", max.trim()))?;
        let (low, high) = self.count.bounds();
        let count = self
            .count
            .check(count)
            .ok()
            .and_then(|c| usize::try_from(c).ok())
            .ok_or_else(|| {
                format!(
                    "COUNT must be >= {low} and <= {high}, got `{}`",
                    count.trim()
                )
            })?;
        Grid::new(self.name, min, max, count, f64::NEG_INFINITY, false)
    }
}

impl TypedValueParser for GridParser {
    type Value = Grid;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<Grid, clap::Error> {
        self.check(&value.to_string_lossy()).map_err(|why| {
            let name = arg.map_or_else(|| self.name.to_string(), |a| a.to_string());
            cmd.clone().error(
                ErrorKind::ValueValidation,
                format!(
                    "invalid value '{}' for '{name}': {why}; allowed: {}",
                    value.to_string_lossy(),
                    self.range()
                ),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_parses_and_refuses_bad_ranges() {
        let p = GridParser {
            name: "rpm",
            values: Real::above(0.0, 1e6, "rpm"),
            count: Count::new(1, 10, "speeds"),
        };
        assert_eq!(p.check("1:2:2").unwrap().values(), vec![1.0, 2.0]);
        assert_eq!(
            p.check("2000:4000:5").unwrap().values(),
            vec![2000.0, 2500.0, 3000.0, 3500.0, 4000.0]
        );
        for bad in ["4000:2000:5", "2000:4000:0", "2000:4000", "2000:4000:1"] {
            assert!(p.check(bad).is_err(), "{bad}");
        }
        for bad in [
            "0:2:2",
            "1:2:11",
            "1:nan:2",
            "1:1e308:2",
            "5e-324:2:2",
            "1:2:1e3",
        ] {
            assert!(p.check(bad).is_err(), "{bad}");
        }
    }
}
