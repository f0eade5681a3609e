//! What a render may take: the memory of its films (checked against the
//! budget before any is allocated), the worker threads that help, and the
//! report of camera samples the ray budget cut short.

use std::fmt;

use crate::accel::AccelKind;
use crate::integrator::SECONDARY_RAY_BUDGET;
use crate::limits::{Charge, MemoryBudget, MemoryError};
use crate::render::{Aov, RenderSettings};
use crate::world::{MaterialId, Objects};

/// Bytes per pixel of encoding the largest output: an EXR's copy of three
/// float channels and its compressed blocks.
const ENCODING_BYTES_PER_PIXEL: u64 = 24;

/// Bytes per pixel more for the cost AOV drawn as a heat map: its colour
/// film and encoded bytes.
const HEAT_MAP_BYTES_PER_PIXEL: u64 = 16;

/// The most worker threads per core a render starts: the work is all
/// computation, so more only waits its turn.
const THREADS_PER_CORE: usize = 4;

/// Bytes a render of `settings` holds at its peak: the colour film and
/// every AOV film (4 bytes per value), and the encoding of the largest
/// output beside them.
pub fn memory_needed(settings: &RenderSettings) -> u64 {
    let values: usize = 3 + settings.aovs.iter().map(Aov::channels).sum::<usize>();
    let mut per_pixel = 4 * values as u64 + ENCODING_BYTES_PER_PIXEL;
    if settings.aovs.contains(&Aov::Cost) {
        per_pixel += HEAT_MAP_BYTES_PER_PIXEL;
    }
    (u64::from(settings.width) * u64::from(settings.height)).saturating_mul(per_pixel)
}

/// Refuses a render whose films ([`memory_needed`]) do not fit in
/// `budget` beside what the run holds.
pub(super) fn check_memory(
    settings: &RenderSettings,
    budget: MemoryBudget,
) -> Result<(), MemoryError> {
    budget.check(
        &films_named(settings),
        memory_needed(settings),
        FILMS_REMEDY,
    )
}

/// [`check_memory`], charging the films to the ledger while the render
/// holds them.
pub(super) fn charge_memory(
    settings: &RenderSettings,
    budget: MemoryBudget,
) -> Result<Charge, MemoryError> {
    budget.charge(
        &films_named(settings),
        memory_needed(settings),
        FILMS_REMEDY,
    )
}

/// Charges a world of `objects` with structures of kind `top` and
/// `bottom` as [`Objects::estimated_world_bytes`] estimates it (its
/// geometry and structures), before it is built: hold the charge as long
/// as the world.
pub fn charge_world(
    objects: &Objects,
    (top, bottom): (AccelKind, AccelKind),
    budget: MemoryBudget,
) -> Result<Charge, MemoryError> {
    let structures = if top == bottom {
        format!("its {} structures", top.name())
    } else {
        format!("its {} and {} structures", top.name(), bottom.name())
    };
    budget.charge(
        &format!("the scene's geometry with {structures}"),
        objects.estimated_world_bytes(top, bottom),
        "use a smaller model, or a structure that takes less (the kd-tree takes the most, \
         then the BVH)",
    )
}

/// How to ask for smaller films.
const FILMS_REMEDY: &str = "render a smaller image or fewer AOVs";

/// "a 640x480 image with 2 AOVs".
fn films_named(settings: &RenderSettings) -> String {
    let (width, height) = (settings.width, settings.height);
    match settings.aovs.len() {
        0 => format!("a {width}x{height} image"),
        1 => format!("a {width}x{height} image with 1 AOV"),
        n => format!("a {width}x{height} image with {n} AOVs"),
    }
}

/// A thread count asked for that was lowered to what helps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ThreadClamp {
    /// Threads asked for.
    pub requested: usize,
    /// Threads used.
    pub used: usize,
    /// Tiles in the image (no more threads than tiles can work).
    pub tiles: usize,
    /// Cores of the machine.
    pub cores: usize,
}

impl fmt::Display for ThreadClamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} threads asked for, {} used: more would not help (the image has {} tiles \
             to share out, and this machine {} cores; at most {THREADS_PER_CORE} threads per \
             core are started)",
            self.requested, self.used, self.tiles, self.cores
        )
    }
}

/// The worker threads to start for `requested` threads (`None`: one per
/// core) over `tiles` tiles on `cores` cores: no more than the tiles, nor
/// than [`THREADS_PER_CORE`] per core. The clamp is returned when a count
/// asked for was lowered.
pub(super) fn useful_threads(
    requested: Option<usize>,
    tiles: usize,
    cores: usize,
) -> (usize, Option<ThreadClamp>) {
    let wanted = requested.unwrap_or(cores);
    let used = wanted
        .min(tiles)
        .min(THREADS_PER_CORE.saturating_mul(cores))
        .max(1);
    let clamp = requested
        .filter(|&r| r > used)
        .map(|requested| ThreadClamp {
            requested,
            used,
            tiles,
            cores,
        });
    (used, clamp)
}

/// Camera samples whose ray tree the budget of secondary rays cut short
/// ([`SECONDARY_RAY_BUDGET`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RayBudgetCut {
    /// Samples cut short.
    pub samples: u64,
    /// Camera samples in the render.
    pub total: u64,
    /// The material at which most were cut (the lowest id among equals).
    pub material: MaterialId,
    /// How the scene names it ([`crate::render::Scene::material_name`]).
    pub material_name: String,
    /// The render's maximum depth.
    pub max_depth: u32,
}

impl fmt::Display for RayBudgetCut {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} of {} camera samples reached the budget of {SECONDARY_RAY_BUDGET} secondary \
             rays per sample and were cut short, most often at material {}: it both reflects \
             and lets light through, so with max_depth {} its ray tree can double at every \
             bounce, and its weights do not fall below min_weight to stop it; the cut branches \
             show only their surfaces' own light. Lower max_depth (a full tree of depth 11 fits \
             the budget) or weaken the material's reflection or transmission",
            self.samples, self.total, self.material_name, self.max_depth
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_counts_every_film_and_the_encoding() {
        let mut settings = RenderSettings {
            width: 100,
            height: 10,
            ..RenderSettings::default()
        };
        assert_eq!(memory_needed(&settings), 1000 * (12 + 24));
        settings.aovs = vec![Aov::Normal, Aov::Cost];
        assert_eq!(memory_needed(&settings), 1000 * (4 * 7 + 24 + 16));
        settings.width = 16384;
        settings.height = 16384;
        let mut error = check_memory(&settings, MemoryBudget::given(4 << 30)).unwrap_err();
        // What other tests hold meanwhile is not this test's.
        error.held = 0;
        assert_eq!(
            error.to_string(),
            "a 16384x16384 image with 2 AOVs needs 17.0 GiB; the memory budget is 4.0 GiB \
             (as given): render a smaller image or fewer AOVs, or raise the budget with \
             --max-memory"
        );
    }

    #[test]
    fn threads_are_no_more_than_the_tiles_or_four_per_core() {
        assert_eq!(useful_threads(None, 1000, 8), (8, None));
        assert_eq!(useful_threads(Some(2), 1000, 8), (2, None));
        let (used, clamp) = useful_threads(Some(100_000), 12, 2);
        assert_eq!(used, 8);
        assert_eq!(
            clamp.unwrap().to_string(),
            "100000 threads asked for, 8 used: more would not help (the image has 12 tiles to \
             share out, and this machine 2 cores; at most 4 threads per core are started)"
        );
        assert_eq!(useful_threads(Some(16), 3, 8).0, 3);
        assert_eq!(useful_threads(None, 1, 8), (1, None));
    }
}
