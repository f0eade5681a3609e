//! Parsers for the numbers of the command line, used as clap value parsers
//! so that a wrong value is refused before anything is read, with its true
//! cause: `-1 is negative`, `4294967296 is more than 65535, the longest
//! image side`, `2.5 is not a whole number`. Options that take them set
//! `allow_negative_numbers` (or `allow_hyphen_values`), so that `-1`
//! reaches the parser instead of being taken for an option.

use whitted::integrator::photon_map::MAX_PHOTONS;
use whitted::math::Vec3;
use whitted::render::{MAX_DEPTH, MAX_SAMPLES, MAX_SIDE};
use whitted::scene::{WholeNumberError, parse_whole_number};

/// Most timed passes `whitted bench --runs` makes of each measurement.
pub const MAX_RUNS: u64 = 1000;

/// A range of whole numbers, and what its upper end is.
struct Range {
    min: u64,
    max: u64,
    /// Why `max` is the limit, said after it ("the longest image side").
    limit: &'static str,
}

impl Range {
    /// The number in `text`, or the reason it is not one in this range.
    fn parse(&self, text: &str) -> Result<u64, String> {
        let expected = if self.max == u64::MAX {
            format!("expected a whole number, at least {}", self.min)
        } else {
            format!("expected a whole number from {} to {}", self.min, self.max)
        };
        let cause = match parse_whole_number(text, self.min, self.max) {
            Ok(value) => return Ok(value),
            Err(WholeNumberError::NotANumber) => format!("`{text}` is not a number"),
            Err(WholeNumberError::NotWhole) => format!("{text} is not a whole number"),
            Err(WholeNumberError::Negative) => format!("{text} is negative"),
            Err(WholeNumberError::BelowMinimum) => format!("{text} is less than {}", self.min),
            Err(WholeNumberError::AboveMaximum) if self.max == u64::MAX => {
                format!("{text} is too large")
            }
            Err(WholeNumberError::AboveMaximum) => {
                format!("{text} is more than {}, {}", self.max, self.limit)
            }
        };
        Err(format!("{cause}; {expected}"))
    }
}

/// An image width or height: 1 to [`MAX_SIDE`] pixels.
pub fn image_side(text: &str) -> Result<u32, String> {
    let range = Range {
        min: 1,
        max: MAX_SIDE.into(),
        limit: "the longest image side",
    };
    range.parse(text).map(|n| n as u32)
}

/// Samples per pixel: 1 to [`MAX_SAMPLES`].
pub fn samples(text: &str) -> Result<u32, String> {
    let range = Range {
        min: 1,
        max: MAX_SAMPLES.into(),
        limit: "a 256x256 grid in each pixel, finer than an 8-bit channel can show",
    };
    range.parse(text).map(|n| n as u32)
}

/// A recursion depth: 0 to [`MAX_DEPTH`].
pub fn depth(text: &str) -> Result<u32, String> {
    let range = Range {
        min: 0,
        max: MAX_DEPTH.into(),
        limit: "the deepest recursion a worker's stack is sized for",
    };
    range.parse(text).map(|n| n as u32)
}

/// Photons to shoot for caustics: 0 (off) to [`MAX_PHOTONS`].
pub fn photons(text: &str) -> Result<u64, String> {
    let range = Range {
        min: 0,
        max: MAX_PHOTONS,
        limit: "ten times what a caustic needs",
    };
    range.parse(text)
}

/// A number of worker threads: at least 1.
pub fn threads(text: &str) -> Result<usize, String> {
    let range = Range {
        min: 1,
        max: u64::MAX,
        limit: "",
    };
    let count = range.parse(text)?;
    usize::try_from(count)
        .map_err(|_| format!("{text} is too large; expected a whole number, at least 1"))
}

/// A number of timed passes: 1 to [`MAX_RUNS`].
pub fn runs(text: &str) -> Result<usize, String> {
    let range = Range {
        min: 1,
        max: MAX_RUNS,
        limit: "which is plenty for a best time",
    };
    range.parse(text).map(|n| n as usize)
}

/// A finite number, or the reason `text` is not one.
fn finite_number(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!("{} is not a finite number", text.trim())),
        Err(_) => Err(format!("`{}` is not a number", text.trim())),
    }
}

/// A vertical field of view in degrees, strictly between 0 and 180.
pub fn field_of_view(text: &str) -> Result<f64, String> {
    let expected = "expected degrees between 0 and 180 (both excluded)";
    let degrees = finite_number(text).map_err(|cause| format!("{cause}; {expected}"))?;
    if degrees > 0.0 && degrees < 180.0 {
        Ok(degrees)
    } else {
        Err(format!("{degrees} degrees is out of range; {expected}"))
    }
}

/// `X,Y,Z`: three finite numbers separated by commas.
pub fn vec3(text: &str) -> Result<Vec3, String> {
    let expected = "expected three finite numbers separated by commas, like 1,2.5,-3";
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() != 3 {
        return Err(format!(
            "{} given; {expected}",
            match parts.len() {
                1 => "one number".to_string(),
                n => format!("{n} numbers"),
            }
        ));
    }
    let mut numbers = [0.0; 3];
    for (number, part) in numbers.iter_mut().zip(parts) {
        *number = finite_number(part).map_err(|cause| format!("{cause}; {expected}"))?;
    }
    Ok(Vec3::from_array(numbers))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_range_are_read() {
        assert_eq!(image_side("65535"), Ok(65535));
        assert_eq!(samples("65536"), Ok(65536));
        assert_eq!(depth("0"), Ok(0));
        assert_eq!(threads("3"), Ok(3));
        assert_eq!(runs("1"), Ok(1));
        assert_eq!(field_of_view("179.5"), Ok(179.5));
        assert_eq!(vec3("1, -2.5,3e2"), Ok(Vec3::new(1.0, -2.5, 300.0)));
    }

    #[test]
    fn each_refusal_says_its_true_cause() {
        for (got, says) in [
            (
                image_side("-1"),
                "-1 is negative; expected a whole number from 1 to 65535",
            ),
            (
                image_side("4294967296"),
                "4294967296 is more than 65535, the longest image side; \
                 expected a whole number from 1 to 65535",
            ),
            (
                image_side("0"),
                "0 is less than 1; expected a whole number from 1 to 65535",
            ),
            (
                image_side("12.5"),
                "12.5 is not a whole number; expected a whole number from 1 to 65535",
            ),
            (
                image_side("wide"),
                "`wide` is not a number; expected a whole number from 1 to 65535",
            ),
            (
                samples("4294967295"),
                "4294967295 is more than 65536, a 256x256 grid in each pixel, finer than an \
                 8-bit channel can show; expected a whole number from 1 to 65536",
            ),
            (
                depth("-1"),
                "-1 is negative; expected a whole number from 0 to 1000",
            ),
            (
                threads("0").map(|n| n as u32),
                "0 is less than 1; expected a whole number, at least 1",
            ),
            (
                threads("99999999999999999999").map(|n| n as u32),
                "99999999999999999999 is too large; expected a whole number, at least 1",
            ),
            (
                runs("0").map(|n| n as u32),
                "0 is less than 1; expected a whole number from 1 to 1000",
            ),
        ] {
            assert_eq!(got.unwrap_err(), says);
        }
    }

    #[test]
    fn angles_and_points_say_which_part_is_wrong() {
        for (got, says) in [
            (
                field_of_view("0"),
                "0 degrees is out of range; expected degrees between 0 and 180 (both excluded)",
            ),
            (
                field_of_view("nan"),
                "nan is not a finite number; expected degrees between 0 and 180 (both excluded)",
            ),
            (
                field_of_view("-inf"),
                "-inf is not a finite number; expected degrees between 0 and 180 (both excluded)",
            ),
        ] {
            assert_eq!(got.unwrap_err(), says);
        }
        for (got, says) in [
            (vec3("1,2"), "2 numbers given"),
            (vec3("1"), "one number given"),
            (vec3("1,2,3,4"), "4 numbers given"),
            (vec3("1,x,3"), "`x` is not a number"),
            (vec3("1,2,1e999"), "1e999 is not a finite number"),
        ] {
            assert_eq!(
                got.unwrap_err(),
                format!("{says}; expected three finite numbers separated by commas, like 1,2.5,-3")
            );
        }
    }
}
