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

#[cfg(test)]
mod tests {
    use super::decimals_or_digits;

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
