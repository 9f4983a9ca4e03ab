//! Numbers as people and programs read them back: the shortest text that parses to the same
//! double (result files), and six significant digits (what the command line prints), so that
//! 1.1e-12 is not shown as 0.000000.

/// The shortest of the plain and the exponent forms that reads back to `x` exactly:
/// `0.1`, `1e-12`, `1.4000000000000001`, `NaN`.
pub fn shortest(x: f64) -> String {
    let plain = format!("{x}");
    let exponent = format!("{x:e}");
    if exponent.len() < plain.len() { exponent } else { plain }
}

/// A time level as people write it: fifteen significant digits in the shortest form, so that
/// the 14th step of 0.1 reads `1.4`, not `1.4000000000000001` (the double that 14 × 0.1
/// sums to; the two differ in the 17th digit).
pub fn time(t: f64) -> String {
    shortest(format!("{t:.14e}").parse().unwrap_or(t))
}

/// `x` to six significant digits, trailing zeros dropped: plain from 10⁻³ to 10⁶
/// (`0.226`, `1234.57`), in exponent form beyond (`1.1e-12`, `3.5e+08` as `3.5e8`).
pub fn readable(x: f64) -> String {
    const DIGITS: i32 = 6;
    if x == 0.0 || !x.is_finite() {
        return format!("{}", if x == 0.0 { 0.0 } else { x });
    }
    let text = format!("{:.*e}", (DIGITS - 1) as usize, x);
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    if (-3..6).contains(&exponent) {
        // Rounding decided the exponent: the plain form keeps the same digits.
        let decimals = (DIGITS - 1 - exponent).max(0) as usize;
        trim(&format!("{x:.decimals$}"))
    } else {
        format!("{}e{exponent}", trim(mantissa))
    }
}

fn trim(s: &str) -> String {
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s.to_string() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn shortest_reads_back_to_the_same_double(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            let back: f64 = shortest(x).parse().unwrap();
            prop_assert!(back.to_bits() == x.to_bits() || (x.is_nan() && back.is_nan()));
        }

        #[test]
        fn readable_keeps_six_significant_digits(m in -1.0f64..1.0, e in -300i32..300) {
            let x = m * 10f64.powi(e);
            prop_assume!(x != 0.0 && x.is_finite());
            let shown = readable(x);
            let back: f64 = shown.parse().unwrap();
            // Six significant digits: within half a unit of the sixth.
            prop_assert!(((back - x) / x).abs() <= 5.000001e-6, "{x} shown as {shown}");
            let digits = shown.split('e').next().unwrap().chars().filter(char::is_ascii_digit).collect::<String>();
            prop_assert!(digits.trim_start_matches('0').len() <= 6, "{x} shown as {shown}");
        }
    }

    #[test]
    fn small_values_are_not_zeros() {
        assert_eq!(readable(1.1e-12), "1.1e-12");
        assert_eq!(readable(0.000000001), "1e-9");
        assert_eq!(readable(0.226), "0.226");
        assert_eq!(readable(-2.5e8), "-2.5e8");
        assert_eq!(readable(999999.7), "1e6");
        assert_eq!(readable(0.0), "0");
        assert_eq!(readable(-0.0), "0");
        assert_eq!(shortest(1e-12), "1e-12");
        assert_eq!(shortest(1.4000000000000001), "1.4000000000000001");
        assert_eq!(shortest(0.25), "0.25");
        assert_eq!(time(14.0 * 0.1), "1.4");
        assert_eq!(time(1e-20), "1e-20");
        assert_eq!(time(0.1 + 0.2), "0.3");
    }
}
