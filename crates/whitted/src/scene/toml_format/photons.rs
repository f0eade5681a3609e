//! The photon keys of `[render]`: `photons`, `gather` and `radius`
//! (see [`crate::integrator::photon_map`]).
//!
//! ```toml
//! [render]
//! photons = 200000   # photons shot from the lights; 0 (the default) is off
//! gather = 50        # nearest photons per estimate (1 to 10000)
//! radius = 0.05      # largest gathering distance; default 2% of the scene
//! ```

use super::reader::{Fields, Parsed, Reader};
use crate::integrator::photon_map::{MAX_GATHER, MAX_PHOTONS, PhotonSettings};

/// The keys read here.
pub(super) const PHOTON_KEYS: [&str; 3] = ["photons", "gather", "radius"];

/// The photon settings of a `[render]` table, defaults where a key is
/// absent.
pub(super) fn read_photons(r: &mut Reader<'_>, f: &Fields<'_, '_>) -> Parsed<PhotonSettings> {
    let d = PhotonSettings::default();
    let max_photons = u32::try_from(MAX_PHOTONS).unwrap_or(u32::MAX);
    let count = r.or_default(f, "photons", 0, |r, v, k| r.count(v, k, 0, max_photons));
    let gather = r.or_default(f, "gather", d.gather, |r, v, k| {
        r.count(v, k, 1, MAX_GATHER)
    });
    let radius = r.optional(f, "radius", Reader::positive);
    Ok(PhotonSettings {
        count: u64::from(count?),
        gather: gather?,
        radius: radius?,
    })
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, errors, scene};
    use super::*;

    #[test]
    fn photon_keys_are_read_and_default_to_off() {
        assert_eq!(scene(CAMERA).settings.photons, PhotonSettings::default());
        let s = scene(&format!(
            "{CAMERA}[render]\nphotons = 200000\ngather = 80\nradius = 0.25\n"
        ));
        assert_eq!(
            s.settings.photons,
            PhotonSettings {
                count: 200_000,
                gather: 80,
                radius: Some(0.25),
            }
        );
    }

    #[test]
    fn photon_keys_out_of_range_are_reported_at_once() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[render]\nphotons = 100000001\ngather = 0\nradius = -1\n"
            )),
            [
                "`photons` must be at most 100000000, got 100000001",
                "`gather` must be at least 1, got 0",
                "`radius` must be greater than 0, got -1",
            ]
        );
    }
}
