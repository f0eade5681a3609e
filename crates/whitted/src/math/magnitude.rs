//! The range of sizes whitted represents, so that no intersection routine
//! squares or multiplies its way out of `f64`.
//!
//! Shapes square their lengths (a sphere's `r²`, a cylinder's `x² + y²`)
//! and multiply them by a ray's squared length; a cone's fourth-degree
//! terms come from products of two squares. Every coordinate is therefore
//! kept within ±[`MAX_COORDINATE`] and every length (a radius, a height,
//! an edge, a scale factor) either zero where zero means something (an
//! inner radius, a cone's point) or between [`MIN_LENGTH`] and
//! [`MAX_COORDINATE`]: a fourth power of either bound, `1e±120`, is far
//! from the ends of `f64` (about `1e±308`), which leaves room for the
//! products of ray and shape terms.

use super::Vec3;

/// The largest magnitude of a coordinate, a length or a scale factor.
pub const MAX_COORDINATE: f64 = 1e30;

/// The smallest non-zero length or scale factor.
pub const MIN_LENGTH: f64 = 1e-30;

/// Why a number lies outside the range whitted represents.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum MagnitudeError {
    /// Beyond [`MAX_COORDINATE`].
    #[error("{value:e} is too large: at most {MAX_COORDINATE:e} in magnitude is allowed")]
    TooLarge {
        /// The number given.
        value: f64,
    },
    /// Non-zero but below [`MIN_LENGTH`].
    #[error("{value:e} is too small: a non-zero length must be at least {MIN_LENGTH:e}")]
    TooSmall {
        /// The number given.
        value: f64,
    },
}

/// `value` when its magnitude is at most [`MAX_COORDINATE`] (NaN is
/// refused as too large).
pub fn coordinate(value: f64) -> Result<f64, MagnitudeError> {
    if value.abs() <= MAX_COORDINATE {
        Ok(value)
    } else {
        Err(MagnitudeError::TooLarge { value })
    }
}

/// `value` when it is zero or its magnitude lies between [`MIN_LENGTH`]
/// and [`MAX_COORDINATE`].
pub fn length(value: f64) -> Result<f64, MagnitudeError> {
    let value = coordinate(value)?;
    if value != 0.0 && value.abs() < MIN_LENGTH {
        Err(MagnitudeError::TooSmall { value })
    } else {
        Ok(value)
    }
}

/// The first component of `v` out of [`coordinate`]'s range, if any.
pub fn point(v: Vec3) -> Result<Vec3, MagnitudeError> {
    for c in v.to_array() {
        coordinate(c)?;
    }
    Ok(v)
}

/// The length of `v`, computed without the overflow or underflow of its
/// squares: for `[0, 1e-300, 0]` it is `1e-300`, not 0.
pub fn norm(v: Vec3) -> f64 {
    let largest = v.abs().max_element();
    if largest == 0.0 || !largest.is_finite() {
        return largest;
    }
    largest * (v / largest).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_are_bounded_in_magnitude() {
        assert_eq!(coordinate(-1e30), Ok(-1e30));
        assert_eq!(
            coordinate(2e154),
            Err(MagnitudeError::TooLarge { value: 2e154 })
        );
        assert!(coordinate(f64::NAN).is_err());
        assert!(coordinate(f64::INFINITY).is_err());
        assert_eq!(
            point(Vec3::new(0.0, -1e31, 0.0)),
            Err(MagnitudeError::TooLarge { value: -1e31 })
        );
    }

    #[test]
    fn lengths_are_zero_or_within_both_bounds() {
        assert_eq!(length(0.0), Ok(0.0));
        assert_eq!(length(1e-30), Ok(1e-30));
        assert_eq!(
            length(1e-300),
            Err(MagnitudeError::TooSmall { value: 1e-300 })
        );
        assert_eq!(
            length(1e103),
            Err(MagnitudeError::TooLarge { value: 1e103 })
        );
    }

    #[test]
    fn norms_neither_overflow_nor_underflow() {
        assert_eq!(norm(Vec3::new(0.0, 1e-300, 0.0)), 1e-300);
        assert!((norm(Vec3::new(3e200, 4e200, 0.0)) / 5e200 - 1.0).abs() < 1e-15);
        assert_eq!(norm(Vec3::ZERO), 0.0);
    }

    #[test]
    fn the_fourth_power_of_either_bound_is_a_normal_number() {
        assert!((MAX_COORDINATE.powi(4) * 1e60).is_finite());
        assert!((MIN_LENGTH.powi(4) * 1e-60).is_normal());
    }
}
