//! Reading a whole number in a range from text, and saying the true cause
//! when it is not one: `-1` is negative, `18446744073709551616` is too
//! large (not "not a whole number"), `2.5` is not whole, `abc` is not a
//! number. Scene readers and the command line share it, so both refuse
//! the same text for the same reason.

use std::num::IntErrorKind;

/// Why a text is not a whole number from `min` to `max`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WholeNumberError {
    /// Not a number at all (`abc`, `1,5`, an empty text).
    NotANumber,
    /// A number, but not a whole one (`2.5`, `1e3`, `inf`).
    NotWhole,
    /// A whole number below zero, under a minimum of zero or more.
    Negative,
    /// A whole number below the minimum.
    BelowMinimum,
    /// A whole number above the maximum, however many digits it has.
    AboveMaximum,
}

/// The whole number written in `text` (decimal digits, with an optional
/// leading `+` or `-`), if it lies from `min` to `max`.
pub fn parse_whole_number(text: &str, min: u64, max: u64) -> Result<u64, WholeNumberError> {
    let (negative, digits) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text.strip_prefix('+').unwrap_or(text)),
    };
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(if text.parse::<f64>().is_ok() {
            WholeNumberError::NotWhole
        } else {
            WholeNumberError::NotANumber
        });
    }
    let is_zero = digits.bytes().all(|b| b == b'0');
    if negative && !is_zero {
        return Err(WholeNumberError::Negative);
    }
    let value = match digits.parse::<u64>() {
        Ok(value) => value,
        Err(e) if *e.kind() == IntErrorKind::PosOverflow => {
            return Err(WholeNumberError::AboveMaximum);
        }
        Err(_) => return Err(WholeNumberError::NotANumber),
    };
    if value < min {
        Err(WholeNumberError::BelowMinimum)
    } else if value > max {
        Err(WholeNumberError::AboveMaximum)
    } else {
        Ok(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use WholeNumberError::*;

    #[test]
    fn whole_numbers_in_range_are_read() {
        assert_eq!(parse_whole_number("7", 1, 10), Ok(7));
        assert_eq!(parse_whole_number("+7", 1, 10), Ok(7));
        assert_eq!(parse_whole_number("007", 1, 10), Ok(7));
        assert_eq!(parse_whole_number("-0", 0, 10), Ok(0));
        assert_eq!(
            parse_whole_number("18446744073709551615", 0, u64::MAX),
            Ok(u64::MAX)
        );
    }

    #[test]
    fn each_refusal_names_its_true_cause() {
        for (text, cause) in [
            ("-1", Negative),
            ("-99999999999999999999999", Negative),
            ("0", BelowMinimum),
            ("-0", BelowMinimum),
            ("11", AboveMaximum),
            ("4294967296", AboveMaximum),
            ("18446744073709551616", AboveMaximum),
            ("999999999999999999999999999999", AboveMaximum),
            ("2.5", NotWhole),
            ("1e3", NotWhole),
            ("inf", NotWhole),
            ("nan", NotWhole),
            ("abc", NotANumber),
            ("", NotANumber),
            ("-", NotANumber),
            ("+-1", NotANumber),
            ("1 ", NotANumber),
            ("0x10", NotANumber),
        ] {
            assert_eq!(parse_whole_number(text, 1, 10), Err(cause), "{text:?}");
        }
    }
}
