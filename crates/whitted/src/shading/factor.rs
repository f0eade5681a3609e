//! The range of the numbers that multiply into radiance: colours,
//! intensities, emissions, attenuation terms, indices of refraction.
//!
//! A pixel's colour is a product of such numbers (a light's intensity, its
//! attenuation, a surface's colour, its reflection weight, again for each
//! bounce) and is stored as a 32-bit float, which ends at about `3.4e38`.
//! Each factor is kept at most [`MAX_FACTOR`], and each number that divides
//! the light (an attenuation term, an index of refraction) at least its
//! inverse, so that one light on one surface stays far inside that range;
//! the render checks the film for what deep recursion could still carry
//! beyond it, and refuses a film that holds inf or NaN.

/// The largest colour component, intensity, emission or other factor of
/// radiance.
pub const MAX_FACTOR: f64 = 1e12;

/// The smallest non-zero number that divides radiance: `1 / MAX_FACTOR`.
pub const MIN_DIVISOR: f64 = 1.0 / MAX_FACTOR;

/// Why a factor of radiance is out of range.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum FactorError {
    /// Beyond [`MAX_FACTOR`] (or not a number).
    #[error(
        "{value:e} is too large: at most {MAX_FACTOR:e} is allowed, so that products of \
         colours, intensities and emissions stay finite"
    )]
    TooLarge {
        /// The number given.
        value: f64,
    },
    /// A non-zero divisor below [`MIN_DIVISOR`].
    #[error(
        "{value:e} is too small: a non-zero number that divides the light must be at least \
         {MIN_DIVISOR:e}"
    )]
    TooSmall {
        /// The number given.
        value: f64,
    },
}

/// `value` when its magnitude is at most [`MAX_FACTOR`].
pub fn factor(value: f64) -> Result<f64, FactorError> {
    if value.abs() <= MAX_FACTOR {
        Ok(value)
    } else {
        Err(FactorError::TooLarge { value })
    }
}

/// `value` when it is zero or its magnitude lies between [`MIN_DIVISOR`]
/// and [`MAX_FACTOR`].
pub fn divisor(value: f64) -> Result<f64, FactorError> {
    let value = factor(value)?;
    if value != 0.0 && value.abs() < MIN_DIVISOR {
        Err(FactorError::TooSmall { value })
    } else {
        Ok(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_are_bounded_and_divisors_bounded_both_ways() {
        assert_eq!(factor(1e12), Ok(1e12));
        assert_eq!(factor(1e39), Err(FactorError::TooLarge { value: 1e39 }));
        assert!(factor(f64::NAN).is_err());
        assert_eq!(divisor(0.0), Ok(0.0));
        assert_eq!(
            divisor(1e-308),
            Err(FactorError::TooSmall { value: 1e-308 })
        );
    }

    #[test]
    fn one_light_on_one_surface_stays_within_a_32_bit_float() {
        let product = MAX_FACTOR * MAX_FACTOR / MIN_DIVISOR;
        assert!(product < f64::from(f32::MAX));
    }
}
