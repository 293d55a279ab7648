//! The `MIN:MAX:COUNT` grids of `kerf lobes --rpm` and `--feed`.

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
    /// Parses `MIN:MAX:COUNT` for the option `name`, requiring `MIN >= lower` (and
    /// `MIN > lower` when `strict`).
    ///
    /// # Errors
    /// A message naming the option: wrong syntax, NaN or infinite bounds, MIN > MAX, COUNT 0,
    /// COUNT 1 with MIN ≠ MAX, a bound under `lower`.
    pub fn parse(name: &str, text: &str, lower: f64, strict: bool) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(':').collect();
        let [min, max, count] = parts[..] else {
            return Err(format!("--{name} {text}: expected MIN:MAX:COUNT"));
        };
        let num = |what: &str, s: &str| -> Result<f64, String> {
            let v: f64 = s
                .trim()
                .parse()
                .map_err(|_| format!("--{name} {text}: {what} `{s}` is not a number"))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("--{name} {text}: {what} is {v}, must be finite"))
            }
        };
        let min = num("MIN", min)?;
        let max = num("MAX", max)?;
        let count: usize = count
            .trim()
            .parse()
            .map_err(|_| format!("--{name} {text}: COUNT `{count}` is not a whole number"))?;
        Self::new(name, min, max, count, lower, strict)
    }

    /// Validates a grid (the checks of [`Grid::parse`]).
    ///
    /// # Errors
    /// As [`Grid::parse`].
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_parses_and_refuses_bad_ranges() {
        let g = Grid::parse("rpm", "2000:4000:5", 0.0, true).expect("grid");
        assert_eq!(g.values(), vec![2000.0, 2500.0, 3000.0, 3500.0, 4000.0]);
        assert_eq!(
            Grid::parse("feed", "0:0:1", 0.0, false)
                .expect("single")
                .values(),
            vec![0.0]
        );
        for bad in [
            "4000:2000:5",
            "NaN:4000:5",
            "2000:inf:5",
            "2000:4000:0",
            "2000:4000",
        ] {
            assert!(Grid::parse("rpm", bad, 0.0, true).is_err(), "{bad}");
        }
        assert!(Grid::parse("rpm", "0:4000:5", 0.0, true).is_err());
        assert!(Grid::parse("feed", "-0.01:0.06:5", 0.0, false).is_err());
        assert!(Grid::parse("feed", "0.01:0.06:1", 0.0, false).is_err());
    }
}
