//! How many photons to shoot and how to gather them: the `[render]` keys
//! `photons`, `gather` and `radius`, and `--photons` on the command line.

/// The most photons a render shoots: ten times the most a caustic needs
/// (Jensen's caustics use from 10⁵ to 10⁶), and about 5 GB of map if
/// every one were stored. The memory budget is checked as well.
pub const MAX_PHOTONS: u64 = 100_000_000;

/// The most photons one estimate gathers.
pub const MAX_GATHER: u32 = 10_000;

/// The gathering radius when the scene gives none: this fraction of the
/// diagonal of the box around the scene's bounded objects.
pub const RADIUS_OF_DIAGONAL: f64 = 0.02;

/// Photon mapping for caustics: off (0 photons, the default) or the
/// photons to shoot and how each estimate gathers them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonSettings {
    /// Photons to shoot from the lights, shared in proportion to their
    /// power; 0 switches caustics off.
    pub count: u64,
    /// How many nearest photons an estimate gathers (Jensen's k).
    pub gather: u32,
    /// The largest distance an estimate gathers from, in scene units;
    /// `None` takes [`RADIUS_OF_DIAGONAL`] of the scene's size.
    pub radius: Option<f64>,
}

impl Default for PhotonSettings {
    fn default() -> Self {
        Self {
            count: 0,
            gather: 50,
            radius: None,
        }
    }
}

/// Photon settings a render cannot use.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum PhotonSettingsError {
    /// More photons than [`MAX_PHOTONS`].
    #[error("{0} photons is too many: at most {MAX_PHOTONS} are allowed")]
    TooManyPhotons(u64),
    /// A gather count of 0 or beyond [`MAX_GATHER`].
    #[error("`gather` must be from 1 to {MAX_GATHER} photons, got {0}")]
    BadGather(u32),
    /// A radius that is not a positive finite number.
    #[error("the photon gathering `radius` must be a positive finite number, got {0}")]
    BadRadius(f64),
}

impl PhotonSettings {
    /// True when photons are shot at all.
    pub fn enabled(&self) -> bool {
        self.count > 0
    }

    /// Refuses settings beyond the limits above.
    pub fn check(&self) -> Result<(), PhotonSettingsError> {
        if self.count > MAX_PHOTONS {
            return Err(PhotonSettingsError::TooManyPhotons(self.count));
        }
        if self.gather == 0 || self.gather > MAX_GATHER {
            return Err(PhotonSettingsError::BadGather(self.gather));
        }
        match self.radius {
            Some(r) if !(r.is_finite() && r > 0.0) => Err(PhotonSettingsError::BadRadius(r)),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn photons_are_off_by_default_and_limits_are_checked() {
        let d = PhotonSettings::default();
        assert!(!d.enabled());
        assert!(d.check().is_ok());
        let with = |count, gather, radius| PhotonSettings {
            count,
            gather,
            radius,
        };
        assert!(with(MAX_PHOTONS, MAX_GATHER, Some(1e-6)).check().is_ok());
        assert_eq!(
            with(MAX_PHOTONS + 1, 50, None).check(),
            Err(PhotonSettingsError::TooManyPhotons(MAX_PHOTONS + 1))
        );
        assert!(with(1, 0, None).check().is_err());
        assert!(with(1, MAX_GATHER + 1, None).check().is_err());
        for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(with(1, 50, Some(r)).check().is_err(), "{r}");
        }
    }
}
