//! The photon pass of a render that asks for caustics: the map built on
//! the render's own threads before the first tile, and what it took.

use std::fmt;
use std::time::Instant;

use crate::integrator::{CausticMap, Shading};
use crate::limits::MemoryError;
use crate::render::RenderSettings;
use crate::world::World;

/// What the photon pass did, for the report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonReport {
    /// Photons the lights sent.
    pub emitted: u64,
    /// Photons kept in the caustic map.
    pub stored: usize,
    /// The gathering radius used, in scene units.
    pub radius: f64,
    /// Wall-clock seconds of the pass, the map's tree included.
    pub seconds: f64,
}

impl fmt::Display for PhotonReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "caustic map: {} photons shot, {} kept, gathered within {:.4} in {:.2} s",
            self.emitted, self.stored, self.radius, self.seconds
        )
    }
}

/// The caustic map of `settings`, built over `world` on the current rayon
/// pool, and its report; `None` when photons are off.
pub(super) fn build(
    world: &World<'_>,
    shading: &Shading<'_>,
    settings: &RenderSettings,
) -> Result<Option<(CausticMap, PhotonReport)>, MemoryError> {
    if !settings.photons.enabled() {
        return Ok(None);
    }
    let start = Instant::now();
    let map = CausticMap::build(world, shading, &settings.photons, settings.fast_paths)?;
    let report = PhotonReport {
        emitted: map.emitted(),
        stored: map.photons().len(),
        radius: map.radius(),
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok(Some((map, report)))
}
