//! The fingerprint of a milling cell ([`cell_fingerprint`]): what an
//! indicator cache was built for, and the FNV-1a hash it and the cache
//! file's checksum use.

use kerf_mill::MillCell;

/// FNV-1a 64-bit hash.
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Rewrites every decimal number of a `Debug` text with 9 significant
/// digits, so that last-ulp differences of computed values (a different
/// libm on another machine) do not change a fingerprint.
fn canonical_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut token = String::new();
    let flush = |token: &mut String, out: &mut String| {
        if token.contains('.') {
            match token.parse::<f64>() {
                Ok(v) => out.push_str(&format!("{v:.8e}")),
                Err(_) => out.push_str(token),
            }
        } else {
            out.push_str(token);
        }
        token.clear();
    };
    for c in text.chars() {
        let continues = c.is_ascii_digit()
            || c == '.'
            || ((c == 'e' || c == 'E') && !token.is_empty())
            || ((c == '-' || c == '+') && (token.is_empty() || token.ends_with(['e', 'E'])));
        if continues {
            token.push(c);
        } else {
            flush(&mut token, &mut out);
            out.push(c);
        }
    }
    flush(&mut token, &mut out);
    out
}

/// A fingerprint of everything in the cell that the indicator depends on:
/// the milling process, the indicator settings, the state limits, the
/// dynamics model, the characteristic length, the reference joints, every
/// segment's geometry, and the cell state (joints, K, modal matrices) at
/// g = 0 of the first, middle and last segments (which catches a changed
/// URDF or TCP). FNV-1a over the `Debug` texts with every number rounded
/// to 9 significant digits (so a last-ulp difference of a computed value
/// on another machine does not make a cache stale), as 16 hex digits.
pub fn cell_fingerprint(cell: &MillCell) -> String {
    let mut text = String::new();
    text.push_str(&format!("{:?}", cell.milling_process()));
    text.push_str(&format!("{:?}", cell.indicator_settings()));
    text.push_str(&format!("{:?}", cell.state_limits()));
    text.push_str(&format!("{:?}", cell.dynamics()));
    text.push_str(&format!("{:?}", cell.characteristic_length()));
    text.push_str(&format!("{:?}", cell.reference_joints()));
    for s in cell.path().segments() {
        text.push_str(&format!("{:?}{:?}{:?}", s.length, s.mid, s.cutting_frame));
    }
    let n = cell.path().segments().len();
    for seg in [0, n / 2, n.saturating_sub(1)] {
        match cell.evaluate(seg, 0.0, None) {
            Ok(state) => text.push_str(&format!("{state:?}")),
            Err(e) => text.push_str(&e.to_string()),
        }
    }
    format!("{:016x}", fnv1a(canonical_numbers(&text).as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_numbers_round_to_nine_digits() {
        let a =
            canonical_numbers("Mode { f: 1.2345678901234567, m: -3.0e-5, n: 7, x: [0.1, 2e3] }");
        assert_eq!(
            a,
            "Mode { f: 1.23456789e0, m: -3.00000000e-5, n: 7, x: [1.00000000e-1, 2e3] }"
        );
        // A last-ulp difference vanishes.
        let x = 0.1f64 + 0.2;
        assert_ne!(format!("{x:?}"), format!("{:?}", 0.3));
        assert_eq!(
            canonical_numbers(&format!("{x:?}")),
            canonical_numbers(&format!("{:?}", 0.3))
        );
    }
}
