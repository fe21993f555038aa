//! SPICE numbers: `1m`, `10u`, `5n`, `1meg`, `2.5ms`, `1e-3`, `4.7k`.
//!
//! The rules follow ngspice's own reader: an optional sign, a decimal
//! mantissa, an optional exponent, then an optional scale suffix
//! (case-insensitive: `t` 1e12, `g` 1e9, `meg` 1e6, `k` 1e3, `mil`
//! 25.4e-6, `m` 1e-3, `u` 1e-6, `n` 1e-9, `p` 1e-12, `f` 1e-15, `a`
//! 1e-18). Letters after that are a unit and ignored, which is why `1ms`
//! is 1e-3 and `1f` is a femto, never a farad. `m` is milli: mega is
//! `meg`, the classic SPICE trap.

/// The value of a SPICE number, or `None` when `text` is not one (an
/// expression such as `{tstop}`, a parameter name, trailing symbols).
pub fn parse_number(text: &str) -> Option<f64> {
    let b = text.trim().as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let int_digits = count_digits(&b[i..]);
    i += int_digits;
    let mut frac_digits = 0;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        frac_digits = count_digits(&b[i..]);
        i += frac_digits;
    }
    if int_digits + frac_digits == 0 {
        return None;
    }
    let digits = &text.trim()[..i];
    // An exponent only when digits follow: in `1e` or `1em` the `e` is a
    // unit letter, as in ngspice.
    let mut exponent: i64 = 0;
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        let exp_digits = count_digits(&b[j..]);
        if exp_digits > 0 {
            // Absurd exponents fail here or overflow to infinity below.
            exponent = text.trim()[i + 1..j + exp_digits].parse().ok()?;
            i = j + exp_digits;
        }
    }
    let rest = text.trim()[i..].to_ascii_lowercase();
    if !rest.bytes().all(|c| c.is_ascii_alphabetic()) {
        return None;
    }
    // Powers of ten join the exponent, so `5u` reads as `5e-6` exactly
    // rather than 5 × 1e-6 (which is 4.9999999999999996e-6).
    let (power, factor) = if rest.starts_with("meg") {
        (6, 1.0)
    } else if rest.starts_with("mil") {
        (-6, 25.4)
    } else {
        let power = match rest.bytes().next() {
            Some(b't') => 12,
            Some(b'g') => 9,
            Some(b'k') => 3,
            Some(b'm') => -3,
            Some(b'u') => -6,
            Some(b'n') => -9,
            Some(b'p') => -12,
            Some(b'f') => -15,
            Some(b'a') => -18,
            _ => 0,
        };
        (power, 1.0)
    };
    let mantissa: f64 = format!("{digits}e{}", exponent.checked_add(power)?)
        .parse()
        .ok()?;
    let value = mantissa * factor;
    value.is_finite().then_some(value)
}

fn count_digits(b: &[u8]) -> usize {
    b.iter().take_while(|c| c.is_ascii_digit()).count()
}

#[cfg(test)]
mod tests {
    use super::parse_number;

    fn close(text: &str, want: f64) {
        let got = parse_number(text).unwrap_or_else(|| panic!("{text:?} did not parse"));
        assert!(
            (got - want).abs() <= 1e-15 * want.abs(),
            "{text:?}: got {got:e}, want {want:e}"
        );
    }

    #[test]
    fn suffixes_and_units() {
        close("1m", 1e-3);
        close("10u", 1e-5);
        close("5n", 5e-9);
        close("1meg", 1e6);
        close("1MEG", 1e6);
        close("2.5ms", 2.5e-3);
        close("1e-3", 1e-3);
        close("1E3", 1e3);
        close("4.7k", 4.7e3);
        close("4.7kOhm", 4.7e3);
        close("3p", 3e-12);
        close("2f", 2e-15);
        close("1F", 1e-15);
        close("1a", 1e-18);
        close("1T", 1e12);
        close("1g", 1e9);
        close("10mil", 254e-6);
        close("20ms", 20e-3);
        close("1us", 1e-6);
        close("1.5e-3s", 1.5e-3);
        close("1e3k", 1e6);
        close("  7  ", 7.0);
        close("-2", -2.0);
        close("+.5", 0.5);
        close("5.", 5.0);
        close("1V", 1.0);
        close("1e", 1.0);
        close("0", 0.0);
    }

    #[test]
    fn milli_is_not_mega() {
        assert_eq!(parse_number("1M"), Some(1e-3));
        assert_eq!(parse_number("1Meg"), Some(1e6));
    }

    #[test]
    fn non_numbers() {
        for t in [
            "", "m", ".", "-", "{tstop}", "tstop", "1.2.3", "1e-3*2", "1m/s", "e3", "1e999",
        ] {
            assert_eq!(parse_number(t), None, "{t:?}");
        }
    }
}
