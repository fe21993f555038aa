//! Engineering notation shared by the reports: three significant digits
//! and an SI prefix, so that "12.5 µs" and "3.3 V" read without exponents.

/// The SI prefix of 10^exponent (a multiple of 3 within ±15).
pub(crate) fn prefix(exponent: i32) -> &'static str {
    match exponent {
        -15 => "f",
        -12 => "p",
        -9 => "n",
        -6 => "µ",
        -3 => "m",
        3 => "k",
        6 => "M",
        9 => "G",
        12 => "T",
        _ => "",
    }
}

/// `value` with three significant digits and an SI prefix: "12.5 µs".
pub fn engineering(value: f64, unit: &str) -> String {
    // A mass reads in grams: "2.2 g", not "2.2 mkg".
    if unit == "kg" {
        return engineering(value * 1e3, "g");
    }
    if value == 0.0 || !value.is_finite() {
        return format!("0 {unit}");
    }
    // Below the smallest prefix (f): an exponent, not fifteen zeros.
    if value.abs() < 0.9995e-15 {
        return format!("{value:.2e} {unit}");
    }
    let mut exponent = (3.0 * (value.abs().log10() / 3.0).floor()).clamp(-15.0, 12.0) as i32;
    // 999.96 µs rounds to three digits as 1000 µs: that is 1 ms.
    let scaled = value.abs() / 10f64.powi(exponent);
    let digits = (2 - scaled.log10().floor() as i32).clamp(0, 15);
    let rounded = (scaled * 10f64.powi(digits)).round() / 10f64.powi(digits);
    if rounded >= 1000.0 && exponent < 12 {
        exponent += 3;
    }
    significant(value, exponent, unit)
}

/// `value` in units of 10^`exponent` (an SI prefix) with three
/// significant digits, trailing zeros dropped: "1 kΩ", not "1.00 kΩ".
pub(crate) fn significant(value: f64, exponent: i32, unit: &str) -> String {
    let scaled = value / 10f64.powi(exponent);
    let magnitude = if scaled == 0.0 {
        0
    } else {
        scaled.abs().log10().floor() as i32
    };
    let decimals = (2 - magnitude).clamp(0, 15) as usize;
    let mut text = format!("{scaled:.decimals$}");
    if text.contains('.') {
        text = text.trim_end_matches('0').trim_end_matches('.').to_owned();
    }
    if text == "-0" {
        text = "0".to_owned();
    }
    format!("{text} {}{unit}", prefix(exponent))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_that_rounds_up_to_the_next_prefix_takes_it() {
        assert_eq!(engineering(0.000_999_96, "s"), "1 ms");
        assert_eq!(engineering(999.96, "V"), "1 kV");
        assert_eq!(engineering(0.000_999_4, "s"), "999 µs");
        assert_eq!(engineering(12.5e-6, "s"), "12.5 µs");
        assert_eq!(engineering(-0.000_999_96, "s"), "-1 ms");
    }

    #[test]
    fn below_the_smallest_prefix_an_exponent() {
        assert_eq!(engineering(1.16e-25, "J"), "1.16e-25 J");
        assert_eq!(engineering(-3.0e-18, "s"), "-3.00e-18 s");
        assert_eq!(engineering(2.0e-15, "J"), "2 fJ");
    }
}
