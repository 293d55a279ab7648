//! Range-checked numbers for every numeric command-line argument (issue 33, item 7), as clap
//! value parsers: a value is refused at parse time (exit code 2, no work done) unless it is
//! finite, not subnormal and inside the argument's stated range.
//!
//! The refusal reads `invalid value 'VALUE' for '--ARG <ARG>': WHY; allowed: RANGE`, and the
//! argument's `--help` states the same `RANGE` (the bounds test checks both). Ranges are
//! written `[a, b]` (both ends allowed) or `(a, b]` (a excluded), followed by the unit.
//!
//! * [`Real`]: an `f64` (seconds, rates, lengths, factors).
//! * [`Count`]: a whole number (counts, indices, seeds), `usize` or `u64`.
//! * [`Coordinates`]: a point `x,y,z` ([`Point3`]), each coordinate a [`Real`] in one range.

use std::{ffi::OsStr, marker::PhantomData};

use clap::{builder::TypedValueParser, error::ErrorKind, Arg, Command};

/// A real number in a range: `[min, max]`, or `(min, max]` when `min_open`.
#[derive(Debug, Clone, Copy)]
pub struct Real {
    min: f64,
    max: f64,
    min_open: bool,
    unit: &'static str,
}

impl Real {
    /// `[min, max] unit`.
    pub const fn closed(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            max,
            min_open: false,
            unit,
        }
    }

    /// `(min, max] unit`: `min` itself is refused.
    pub const fn above(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            max,
            min_open: true,
            unit,
        }
    }

    /// The range as stated in `--help` and in refusals, e.g. `[0, 86400] s`.
    pub fn range(&self) -> String {
        let open = if self.min_open { '(' } else { '[' };
        let r = format!("{open}{}, {}]", self.min, self.max);
        if self.unit.is_empty() {
            r
        } else {
            format!("{r} {}", self.unit)
        }
    }

    /// Checks `text` (the refusal's reason and the range, or the value).
    ///
    /// # Errors
    /// Why the value is refused: not a number, NaN, infinite, subnormal, out of the range.
    pub fn check(&self, text: &str) -> Result<f64, String> {
        let v: f64 = text
            .trim()
            .parse()
            .map_err(|_| "not a number".to_string())?;
        if v.is_nan() {
            return Err("must be finite (NaN is not a number)".into());
        }
        if v.is_infinite() {
            return Err("must be finite".into());
        }
        if v != 0.0 && !v.is_normal() {
            return Err(format!(
                "subnormal (below {:e} in magnitude); use 0 or a normal number",
                f64::MIN_POSITIVE
            ));
        }
        let low = if self.min_open {
            v > self.min
        } else {
            v >= self.min
        };
        if !(low && v <= self.max) {
            return Err("out of range".into());
        }
        // -0 is 0.
        Ok(v + 0.0)
    }
}

/// The clap error of a refused value.
fn refusal(cmd: &Command, arg: Option<&Arg>, value: &OsStr, why: &str, range: &str) -> clap::Error {
    let name = arg.map_or_else(|| "the argument".to_string(), |a| a.to_string());
    let mut cmd = cmd.clone();
    cmd.error(
        ErrorKind::ValueValidation,
        format!(
            "invalid value '{}' for '{name}': {why}; allowed: {range}",
            value.to_string_lossy()
        ),
    )
}

impl TypedValueParser for Real {
    type Value = f64;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<f64, clap::Error> {
        let text = value.to_string_lossy();
        self.check(&text)
            .map_err(|why| refusal(cmd, arg, value, &why, &self.range()))
    }
}

/// A point `x,y,z`: three reals separated by commas, each checked by [`Real`] (as an
/// `--origin` takes it). Parsed by [`Coordinates`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point3(pub [f64; 3]);

/// The value parser of a [`Point3`]: each coordinate in the same range.
#[derive(Debug, Clone, Copy)]
pub struct Coordinates(pub Real);

impl Coordinates {
    /// Checks `text` (`x,y,z`).
    ///
    /// # Errors
    /// Why the value is refused: not three numbers, or a coordinate as [`Real::check`] says.
    pub fn check(&self, text: &str) -> Result<Point3, String> {
        Triple {
            what: "coordinates",
            names: ["x", "y", "z"],
            value: self.0,
        }
        .check(text)
        .map(Point3)
    }
}

/// The value parser of three named reals `a,b,c` in one range (`--limits V,A,J`).
#[derive(Debug, Clone, Copy)]
pub struct Triple {
    /// What the three are, as the refusal says ("coordinates", "limits").
    pub what: &'static str,
    /// The three names, as the refusal states them.
    pub names: [&'static str; 3],
    /// The range of each.
    pub value: Real,
}

impl Triple {
    /// Checks `text` (`a,b,c`).
    ///
    /// # Errors
    /// Why the value is refused: not three numbers, or one as [`Real::check`] says.
    pub fn check(&self, text: &str) -> Result<[f64; 3], String> {
        let parts: Vec<&str> = text.split(',').collect();
        if parts.len() != 3 {
            return Err(format!(
                "{} value(s); three {} {} separated by commas are required",
                parts.len(),
                self.what,
                self.names.join(",")
            ));
        }
        let mut p = [0.0; 3];
        for (k, (part, name)) in parts.iter().zip(self.names).enumerate() {
            p[k] = self
                .value
                .check(part)
                .map_err(|why| format!("{name}: {why}"))?;
        }
        Ok(p)
    }
}

impl TypedValueParser for Triple {
    type Value = [f64; 3];

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<[f64; 3], clap::Error> {
        let text = value.to_string_lossy();
        self.check(&text)
            .map_err(|why| refusal(cmd, arg, value, &why, &self.value.range()))
    }
}

impl TypedValueParser for Coordinates {
    type Value = Point3;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<Point3, clap::Error> {
        let text = value.to_string_lossy();
        self.check(&text)
            .map_err(|why| refusal(cmd, arg, value, &why, &self.0.range()))
    }
}

/// A whole number in `[min, max]`, parsed as `T` (`usize` or `u64`).
#[derive(Debug)]
pub struct Count<T> {
    min: u64,
    max: u64,
    unit: &'static str,
    of: PhantomData<fn() -> T>,
}

impl<T> Clone for Count<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Count<T> {}

impl<T> Count<T> {
    /// `[min, max] unit`.
    pub const fn new(min: u64, max: u64, unit: &'static str) -> Self {
        Self {
            min,
            max,
            unit,
            of: PhantomData,
        }
    }

    /// The smallest and the largest value.
    pub fn bounds(&self) -> (u64, u64) {
        (self.min, self.max)
    }

    /// The range as stated in `--help` and in refusals, e.g. `[1, 10000] speeds`.
    pub fn range(&self) -> String {
        if self.unit.is_empty() {
            format!("[{}, {}]", self.min, self.max)
        } else {
            format!("[{}, {}] {}", self.min, self.max, self.unit)
        }
    }

    /// Checks `text`.
    ///
    /// # Errors
    /// Why the value is refused: not a whole number, out of the range.
    pub fn check(&self, text: &str) -> Result<u64, String> {
        let t = text.trim();
        if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
            return Err(format!("`{t}` is not a whole number"));
        }
        let v: u64 = t.parse().map_err(|_| "out of range".to_string())?;
        if !(self.min..=self.max).contains(&v) {
            return Err("out of range".into());
        }
        Ok(v)
    }
}

impl<T> TypedValueParser for Count<T>
where
    T: TryFrom<u64> + Clone + Send + Sync + 'static,
{
    type Value = T;

    fn parse_ref(&self, cmd: &Command, arg: Option<&Arg>, value: &OsStr) -> Result<T, clap::Error> {
        let text = value.to_string_lossy();
        self.check(&text)
            .and_then(|v| T::try_from(v).map_err(|_| "out of range".to_string()))
            .map_err(|why| refusal(cmd, arg, value, &why, &self.range()))
    }
}

/// Seconds a command waits or lingers: `[0, 86400] s` (one day; `Duration::from_secs_f64`
/// panics on 1e308, which is why every duration argument is bounded).
pub const SECONDS: Real = Real::closed(0.0, 86_400.0, "s");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_are_finite_normal_and_in_range() {
        let r = Real::closed(0.0, 10.0, "s");
        assert_eq!(r.range(), "[0, 10] s");
        assert_eq!(r.check("2.5"), Ok(2.5));
        assert_eq!(r.check("-0").map(f64::to_bits), Ok(0.0f64.to_bits()));
        for bad in [
            "nan", "NaN", "inf", "-inf", "1e308", "-1", "5e-324", "x", "",
        ] {
            assert!(r.check(bad).is_err(), "{bad}");
        }
        let open = Real::above(0.0, 1.0, "");
        assert_eq!(open.range(), "(0, 1]");
        assert!(open.check("0").is_err());
        assert_eq!(open.check("1"), Ok(1.0));
    }

    #[test]
    fn points_are_three_checked_reals() {
        let c = Coordinates(Real::closed(-10.0, 10.0, "m"));
        assert_eq!(c.check("1,-2,0").unwrap(), Point3([1.0, -2.0, 0.0]));
        assert!(c.check("1,2").unwrap_err().contains("three coordinates"));
        assert!(c
            .check("1,2,3,4")
            .unwrap_err()
            .contains("three coordinates"));
        assert!(c
            .check("1,NaN,3")
            .unwrap_err()
            .starts_with("y: must be finite"));
        assert!(c
            .check("1,2,11")
            .unwrap_err()
            .starts_with("z: out of range"));
    }

    #[test]
    fn counts_are_whole_and_in_range() {
        let c = Count::<usize>::new(1, 100, "speeds");
        assert_eq!(c.range(), "[1, 100] speeds");
        assert_eq!(c.check("100"), Ok(100));
        for bad in [
            "0",
            "101",
            "-1",
            "1e3",
            "5e-324",
            "NaN",
            "18446744073709551616",
            "",
        ] {
            assert!(c.check(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn refusals_name_the_argument_and_the_range() {
        let cmd = Command::new("kerf").arg(Arg::new("linger").long("linger").value_parser(SECONDS));
        let e = cmd
            .clone()
            .try_get_matches_from(["kerf", "--linger=1e308"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("invalid value '1e308' for '--linger <linger>'")
                && e.contains("allowed: [0, 86400] s"),
            "{e}"
        );
        let m = cmd.try_get_matches_from(["kerf", "--linger=3"]).unwrap();
        assert_eq!(m.get_one::<f64>("linger"), Some(&3.0));
    }
}
