//! Axis ticks at "nice" numbers: 1, 2 or 5 times a power of ten (Paul
//! Heckbert, "Nice numbers for graph labels", Graphics Gems, 1990).

/// The nice step for about `count` ticks over `span`: the smallest of
/// 1, 2, 5 × 10ᵏ at least `span / count` (`span` > 0 and finite, else 1).
pub fn nice_step(span: f64, count: usize) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / count.max(1) as f64;
    let power = 10f64.powf(raw.log10().floor());
    let fraction = raw / power;
    let nice = if fraction <= 1.0 + 1e-9 {
        1.0
    } else if fraction <= 2.0 + 1e-9 {
        2.0
    } else if fraction <= 5.0 + 1e-9 {
        5.0
    } else {
        10.0
    };
    nice * power
}

/// An axis range widened to whole multiples of its nice step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// Lower end of the range.
    pub lo: f64,
    /// Upper end of the range.
    pub hi: f64,
    /// Distance between ticks.
    pub step: f64,
}

impl Axis {
    /// The axis covering `lo..=hi` with about `count` nice ticks (a zero
    /// span is widened by 1 on each side, or by a tenth of the value).
    pub fn covering(lo: f64, hi: f64, count: usize) -> Self {
        let (lo, hi) = if hi > lo {
            (lo, hi)
        } else {
            let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            (lo - pad, hi + pad)
        };
        let step = nice_step(hi - lo, count);
        Self {
            lo: (lo / step).floor() * step,
            hi: (hi / step).ceil() * step,
            step,
        }
    }

    /// The ticks: every multiple of the step in `lo..=hi` (rounding
    /// forgiven by a millionth of a step), written without rounding noise.
    pub fn ticks(&self) -> Vec<f64> {
        let first = (self.lo / self.step - 1e-6).ceil() as i64;
        let last = (self.hi / self.step + 1e-6).floor() as i64;
        (first..=last).map(|k| k as f64 * self.step).collect()
    }

    /// The fraction of the range at `v` (0 at `lo`, 1 at `hi`).
    pub fn fraction(&self, v: f64) -> f64 {
        (v - self.lo) / (self.hi - self.lo)
    }
}

/// A tick label: the decimals the step needs, or scientific notation for
/// magnitudes of 10⁶ and more or below 10⁻³.
pub fn tick_label(value: f64, step: f64) -> String {
    let magnitude = value.abs().max(step.abs());
    if value == 0.0 {
        return "0".to_string();
    }
    if !(1e-3..1e6).contains(&magnitude) {
        return format!("{value:.2e}")
            .replace(".00e", "e")
            .replace("0e", "e");
    }
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    format!("{value:.decimals$}")
}
