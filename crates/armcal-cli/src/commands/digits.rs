//! Numbers on the screen that keep their significant digits: a variance in mm² from a
//! precise instrument (σ = 0.05 mm gives (1/3) tr C_s ≈ 1e-4 mm²) printed with the 5 or 6
//! decimals that suit the paper's 1 mm tracker would keep one or two digits.

/// `x` with `decimals` decimals, or as many more as it takes to show 3 significant digits
/// (at most 12 decimals; non-finite values and 0 as Rust prints them).
pub fn decimals_or_digits(x: f64, decimals: usize) -> String {
    let needed = if x.is_finite() && x != 0.0 {
        (2 - x.abs().log10().floor() as i64).clamp(0, 12) as usize
    } else {
        0
    };
    format!("{x:.*}", decimals.max(needed))
}

/// `x` with `decimals` decimals, without the sign of a value that rounds to zero: a nominal
/// of −1e-16° (what a convention change leaves of a zero angle) prints `0.00000`, not
/// `-0.00000`.
pub fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.*}", decimals);
    match s.strip_prefix('-') {
        Some(unsigned) if unsigned.chars().all(|c| c == '0' || c == '.') => unsigned.to_string(),
        _ => s,
    }
}

#[cfg(test)]
mod tests {
    use super::{decimals_or_digits, fixed};

    #[test]
    fn a_value_that_rounds_to_zero_has_no_sign() {
        assert_eq!(fixed(-1e-16, 5), "0.00000");
        assert_eq!(fixed(-0.0, 3), "0.000");
        assert_eq!(fixed(-0.000004, 5), "0.00000");
        assert_eq!(fixed(-0.000006, 5), "-0.00001");
        assert_eq!(fixed(12.5, 2), "12.50");
        assert_eq!(fixed(f64::NAN, 2), "NaN");
    }

    #[test]
    fn small_values_keep_three_significant_digits_and_large_ones_their_decimals() {
        assert_eq!(decimals_or_digits(0.335589, 5), "0.33559");
        assert_eq!(decimals_or_digits(0.000109123, 5), "0.000109");
        assert_eq!(decimals_or_digits(0.000109123, 6), "0.000109");
        assert_eq!(decimals_or_digits(1.25e-7, 5), "0.000000125");
        assert_eq!(decimals_or_digits(12.5, 3), "12.500");
        assert_eq!(decimals_or_digits(-0.0123456, 3), "-0.0123");
        assert_eq!(decimals_or_digits(0.0, 4), "0.0000");
        assert_eq!(decimals_or_digits(f64::NAN, 4), "NaN");
    }
}
