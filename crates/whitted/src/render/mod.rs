//! Rendering a scene into a film: tiles spread over threads, each pixel's
//! samples placed by a pattern seeded from the pixel's position, so the
//! picture is identical bit for bit whatever the number of threads.

mod adaptive;
mod camera;
mod explain;
mod gradient_note;
mod implicit_cost;
mod merge;
mod non_finite;
mod part;
mod photon_pass;
mod prepared;
mod resources;
mod sample_ray;
mod scene;
mod selection;
mod settings;
mod sources;
mod trace_timing;
mod world_on_image;

pub use adaptive::{
    Adaptive, AdaptiveError, AntiAliasing, DEFAULT_AA_DEPTH, DEFAULT_AA_THRESHOLD, MAX_AA_DEPTH,
};
pub use camera::{Camera, CameraError};
pub use explain::{ExplainError, Explainer, PixelExplanation, explain_pixel};
pub use gradient_note::GradientExceeded;
pub use implicit_cost::{SLOW_RAY_SECONDS, SlowImplicit, slow_implicit_surfaces};
pub use merge::{MergeError, Merged, merge_parts};
pub use part::{
    BUILT_IN_SCENE, Part, PartError, PartHeader, encode_part, parse_part, read_part, scene_sha256,
};
pub use photon_pass::PhotonReport;
pub use prepared::{Pass, Prepared};
pub use resources::{RayBudgetCut, ThreadClamp, charge_world, memory_needed};
pub use scene::Scene;
pub use selection::{PixelSelection, SelectionError, Share, Window};
pub use settings::{
    Aov, MAX_DEPTH, MAX_PIXELS, MAX_SAMPLES, MAX_SIDE, RenderSettings, check_image_size,
};
pub use sources::{LineIndex, ObjectSource, ObjectSources, PrimitiveDescription, SourceLocation};
pub use trace_timing::TraceTiming;

use std::collections::HashMap;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use crate::accel::{AccelKind, QueryContext};
use crate::image::{ColorSpace, Film, FilmAllocError};
use crate::integrator::{
    FirstHit, Integrator, RayCounts, RayKind, RecursionLimits, SECONDARY_RAY_BUDGET, Shading,
    Unobserved,
};
use crate::limits::{Charge, MemoryBudget, MemoryError};
use crate::math::{DVec2, Ray, Vec3};
use crate::shading::Color;
use crate::world::{Hit, MAX_PRIMITIVES, MaterialId, PACKET_SIZE, Surface, World};
use adaptive::{AdaptivePixels, Cost};
use non_finite::NonFinite;
use sample_ray::{differential_step, pixel_pattern, position_differential, sample_position};
use world_on_image::WorldOnImage;

/// Side of the square tiles the image is cut into, in pixels.
const TILE_SIZE: u32 = 16;

/// How many pixels ahead of the one it shades a row starts loading the
/// surface of a camera ray's hit ([`World::prefetch_surface`]).
const SURFACES_AHEAD: usize = 2;

/// A primitive count as a message gives it: [`Objects::primitive_count`]'s
/// `usize::MAX` stands for a count that overflowed.
///
/// [`Objects::primitive_count`]: crate::world::Objects::primitive_count
fn count_in_words(count: usize) -> String {
    if count == usize::MAX {
        format!("more than {}", usize::MAX)
    } else {
        count.to_string()
    }
}

/// Checks what building a world of `objects` relies on
/// ([`World::build_levels`]): instances that
/// [`Objects::check_instances`] accepts, and at most [`MAX_PRIMITIVES`]
/// primitives, every placement counted. Every command checks a scene so
/// before it builds a world.
///
/// [`Objects::check_instances`]: crate::world::Objects::check_instances
pub fn check_objects(objects: &crate::world::Objects) -> Result<(), RenderError> {
    objects.check_instances()?;
    let primitives = objects.primitive_count();
    if primitives > MAX_PRIMITIVES {
        return Err(RenderError::TooManyPrimitives(primitives));
    }
    Ok(())
}

/// The world of `scene`, its structures of the kinds its settings ask for
/// (shared by [`render`] and [`explain_pixel`], which must trace the same).
fn build_world(scene: &Scene) -> World<'_> {
    let (top, bottom) = world_kinds(&scene.settings);
    World::build_levels(&scene.objects, top, bottom)
}

/// The structure kinds of a world's top level and of its instances, as
/// `settings` ask for them.
fn world_kinds(settings: &RenderSettings) -> (AccelKind, AccelKind) {
    (
        settings.accel_top.unwrap_or(settings.accel),
        settings.accel_bottom.unwrap_or(settings.accel),
    )
}

/// [`resources::charge_world`] for the world [`build_world`] builds of
/// `scene`.
fn charge_world_of(scene: &Scene) -> Result<Charge, MemoryError> {
    resources::charge_world(
        &scene.objects,
        world_kinds(&scene.settings),
        MemoryBudget::current(),
    )
}

/// Worker stack: a base for everything but the recursion, plus room for
/// each level (one level measured at about 1.5 KiB in a release build; the
/// margin covers debug builds).
fn worker_stack_bytes(max_depth: u32) -> usize {
    (2 << 20) + max_depth as usize * (16 << 10)
}

/// How far a render has come.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Pixels finished.
    pub done: u64,
    /// Pixels in the image.
    pub total: u64,
}

/// A finished render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOutput {
    /// The colour image (3 channels, in the scene's colour space).
    pub image: Film,
    /// The requested AOVs, in the order asked for.
    pub aovs: Vec<(Aov, Film)>,
    /// How many rays of each kind were traced.
    pub rays: RayCounts,
    /// The kinds of rays the integrator traces, in report order.
    pub ray_kinds: &'static [RayKind],
    /// Seconds spent building the world (its acceleration structures).
    pub build_seconds: f64,
    /// How long the tiles took, and how busy the threads were.
    pub trace: TraceTiming,
    /// The thread count asked for, when it was lowered to what helps.
    pub thread_clamp: Option<ThreadClamp>,
    /// The camera samples the budget of secondary rays cut short, if any.
    pub ray_budget_cut: Option<RayBudgetCut>,
    /// The implicit surface whose function grew faster than its
    /// `max_gradient` allows, if any.
    pub gradient_exceeded: Option<GradientExceeded>,
    /// What the photon pass did, when caustics were asked for.
    pub photons: Option<PhotonReport>,
}

/// Why a render could not start.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// Width or height is zero, or the image is too large to address.
    #[error(
        "the image size {width}x{height} is not valid: both sides must be between 1 and {MAX_SIDE}"
    )]
    BadSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// Zero samples per pixel.
    #[error("samples per pixel must be at least 1")]
    NoSamples,
    /// More samples per pixel than [`MAX_SAMPLES`].
    #[error(
        "{0} samples per pixel is too many: at most {MAX_SAMPLES} are allowed (a 256x256 grid \
         in each pixel, finer than an 8-bit channel can show)"
    )]
    TooManySamples(u32),
    /// A recursion depth beyond [`MAX_DEPTH`].
    #[error("the maximum depth {0} is too large: at most {MAX_DEPTH} is allowed")]
    DepthTooLarge(u32),
    /// More pixels than [`MAX_PIXELS`].
    #[error("the image {width}x{height} is too large: at most {MAX_PIXELS} pixels are allowed")]
    TooManyPixels {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// More primitives (every placement of a mesh counted) than a world
    /// numbers.
    #[error(
        "the scene has {} primitives (every placement of a mesh counted): at most {MAX_PRIMITIVES} are allowed",
        count_in_words(*.0)
    )]
    TooManyPrimitives(usize),
    /// The photon settings are out of range.
    #[error(transparent)]
    Photons(#[from] crate::integrator::photon_map::PhotonSettingsError),
    /// Instances a world cannot be built from (a scene built in code; the
    /// readers refuse them with a located message).
    #[error("the scene's instances are invalid: {0}")]
    Instances(#[from] crate::world::InstanceError),
    /// The films, or the world as estimated, would exceed the memory
    /// budget.
    #[error(transparent)]
    Memory(#[from] MemoryError),
    /// The system refused a film's memory, which the budget allowed.
    #[error(transparent)]
    FilmAlloc(#[from] FilmAllocError),
    /// Some pixels' colours came out infinite or NaN: the scene's numbers
    /// (each bounded as it is read, see [`crate::shading::factor`])
    /// multiplied over many bounces beyond what a 32-bit float holds. The
    /// film is not returned, so no picture with inf or NaN is ever written.
    #[error(
        "{count} pixel(s) came out with a colour that is not a finite number (the first at \
         column {x}, row {y}): the scene's colours, intensities and reflections multiply \
         beyond the range of a 32-bit float; lower them or the maximum depth"
    )]
    NotFinite {
        /// How many pixels.
        count: u64,
        /// The first one's column.
        x: u32,
        /// The first one's row.
        y: u32,
    },
    /// The adaptive anti-aliasing parameters are out of range.
    #[error(transparent)]
    AntiAliasing(#[from] AdaptiveError),
    /// The pixels asked for are not in the image.
    #[error(transparent)]
    Selection(#[from] SelectionError),
    /// The render was cancelled ([`render_cancellable`]) before it ended.
    #[error("the render was cancelled")]
    Cancelled,
    /// The thread pool could not be created.
    #[error("could not start {threads} worker threads: {message}")]
    Threads {
        /// Requested thread count.
        threads: usize,
        /// What the system said.
        message: String,
    },
}

/// One finished tile: its pixels and the rays it took.
struct Tile {
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
    color: Vec<f32>,
    aovs: Vec<Vec<f32>>,
    rays: RayCounts,
    /// Samples the ray budget cut short, by the material they were cut at.
    cuts: HashMap<MaterialId, u64>,
    /// How many of its pixels were rendered (the others are black).
    selected: u64,
}

impl Tile {
    /// Its pixels whose colour is not finite.
    fn non_finite(&self) -> NonFinite {
        NonFinite::of_tile(self.x0, self.y0, self.width, &self.color)
    }
}

/// The films of a render being filled in as tiles finish.
struct Films {
    image: Film,
    aovs: Vec<(Aov, Film)>,
    rays: RayCounts,
    cuts: HashMap<MaterialId, u64>,
    /// The image's pixels whose colour is not finite, as the workers
    /// found them in their tiles.
    non_finite: NonFinite,
}

impl Films {
    /// Copies a finished tile in, a row of its pixels at a time, with
    /// `non_finite`, what its worker found of its pixels (the caller holds
    /// the lock around the films meanwhile, and drops the tile after).
    fn add(&mut self, tile: &Tile, non_finite: NonFinite) {
        self.rays += tile.rays;
        self.non_finite.add(non_finite);
        for (&material, &samples) in &tile.cuts {
            *self.cuts.entry(material).or_default() += samples;
        }
        let width = tile.width as usize;
        for dy in 0..tile.height {
            let row = dy as usize * width..(dy as usize + 1) * width;
            let y = tile.y0 + dy;
            self.image
                .set_row(tile.x0, y, &tile.color[3 * row.start..3 * row.end]);
            for ((aov, film), data) in self.aovs.iter_mut().zip(&tile.aovs) {
                let c = aov.channels();
                film.set_row(tile.x0, y, &data[c * row.start..c * row.end]);
            }
        }
    }
}

/// Renders `scene` with its settings: builds its world once, hands it to
/// the integrator and spreads the tiles over the worker threads.
/// `progress` is called from worker threads as tiles finish.
///
/// Before anything is allocated, the films' memory ([`memory_needed`]) is
/// checked against the memory budget ([`MemoryBudget::current`]). No more
/// threads are started than there are tiles, nor than 4 per core
/// ([`RenderOutput::thread_clamp`] says when a count asked for was
/// lowered).
pub fn render(
    scene: &Scene,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RenderOutput, RenderError> {
    let whole = PixelSelection::whole(scene.settings.width, scene.settings.height);
    render_selected(scene, &whole, progress)
}

/// Renders `scene` as [`render`] does, but stops early with
/// [`RenderError::Cancelled`] once `cancel` is set: each tile checks it
/// before it starts, so a cancelled render ends within a tile's time per
/// thread (the live preview of `whitted serve` cancels a render when a
/// newer one is asked for).
pub fn render_cancellable(
    scene: &Scene,
    cancel: &AtomicBool,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RenderOutput, RenderError> {
    let whole = PixelSelection::whole(scene.settings.width, scene.settings.height);
    render_pixels(scene, &whole, Some(cancel), progress)
}

/// Renders the pixels of `scene` that `selection` holds, as [`render`]
/// does (each bit for bit as a whole render has it), and leaves the others
/// black. Progress counts the selected pixels.
pub fn render_selected(
    scene: &Scene,
    selection: &PixelSelection,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RenderOutput, RenderError> {
    render_pixels(scene, selection, None, progress)
}

/// [`render_selected`], stopping early when `cancel` is given and set.
fn render_pixels(
    scene: &Scene,
    selection: &PixelSelection,
    cancel: Option<&AtomicBool>,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RenderOutput, RenderError> {
    selection.check(scene.settings.width, scene.settings.height)?;
    let prepared = Prepared::new(scene)?;
    let build_seconds = prepared.build_seconds();
    let settings = &scene.settings;
    trace_pixels(
        &prepared,
        &scene.camera,
        settings,
        selection,
        cancel,
        progress,
        build_seconds,
    )
}

/// How many tiles cover a `width` x `height` image.
fn tile_count(width: u32, height: u32) -> usize {
    (width.div_ceil(TILE_SIZE) * height.div_ceil(TILE_SIZE)) as usize
}

/// The worker threads for `tiles` tiles of a render with `settings`.
fn worker_pool(
    settings: &RenderSettings,
    tiles: usize,
) -> Result<(rayon::ThreadPool, Option<ThreadClamp>), RenderError> {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let (threads, thread_clamp) = resources::useful_threads(settings.threads, tiles, cores);
    let pool = rayon::ThreadPoolBuilder::new()
        .stack_size(worker_stack_bytes(settings.max_depth))
        .num_threads(threads)
        .build()
        .map_err(|e| RenderError::Threads {
            threads,
            message: e.to_string(),
        })?;
    Ok((pool, thread_clamp))
}

/// The shading inputs of `scene`.
fn shading_of(scene: &Scene) -> Shading<'_> {
    Shading {
        materials: &scene.materials,
        lights: &scene.lights,
        background: scene.background,
        ambient: scene.ambient,
    }
}

/// Renders the pixels `selection` holds through the world of `prepared`,
/// seen by `camera`, with `settings` (the prepared scene's, or those of a
/// [`Pass`] of it): the tiles spread over the worker threads.
fn trace_pixels(
    prepared: &Prepared<'_>,
    camera: &Camera,
    settings: &RenderSettings,
    selection: &PixelSelection,
    cancel: Option<&AtomicBool>,
    progress: &(dyn Fn(Progress) + Sync),
    build_seconds: f64,
) -> Result<RenderOutput, RenderError> {
    let cancelled = || is_cancelled(cancel);
    let scene = prepared.scene;
    let (width, height) = (settings.width, settings.height);
    settings.check()?;
    selection.check(width, height)?;
    // Held until the films are returned: a render beside it is weighed
    // with them.
    let _films = resources::charge_memory(settings, MemoryBudget::current())?;
    let tiles_x = width.div_ceil(TILE_SIZE);
    let tiles_y = height.div_ceil(TILE_SIZE);
    let tiles: Vec<u32> = (0..tiles_x * tiles_y)
        .filter(|&index| tile_is_selected(selection, index % tiles_x, index / tiles_x))
        .collect();
    let (pool, thread_clamp) = worker_pool(settings, tiles.len())?;

    gradient_note::forget(&scene.objects);
    let limits = RecursionLimits {
        max_depth: settings.max_depth,
        min_weight: settings.min_weight,
        ray_budget: SECONDARY_RAY_BUDGET,
    };
    let caustics = prepared.caustics.as_ref();
    let integrator = Integrator::new(
        settings.integrator,
        &prepared.world,
        shading_of(scene),
        limits,
    )
    .with_caustics(caustics.map(|(map, _)| map))
    .with_fast_paths(settings.fast_paths);
    let total = selection.pixel_count();
    let done = AtomicU64::new(0);
    let mut films = Films {
        image: Film::try_new(width, height, 3)?.with_color_space(scene.color_space),
        aovs: settings
            .aovs
            .iter()
            .map(|&a| Ok((a, Film::try_new(width, height, a.channels())?)))
            .collect::<Result<_, FilmAllocError>>()?,
        rays: RayCounts::default(),
        cuts: HashMap::new(),
        non_finite: NonFinite::default(),
    };
    pool.install(|| {
        films.image.map_pages();
        films.aovs.iter_mut().for_each(|(_, film)| film.map_pages());
    });
    let films = Mutex::new(films);
    let on_image = settings
        .fast_paths
        .then(|| WorldOnImage::new(camera, width, height, &prepared.world))
        .flatten();
    let clock = trace_timing::TraceClock::start();
    // Each worker takes the next tile from a shared counter until none is
    // left: a thread that finishes early takes more, so both cores stay
    // busy to the last tile. (Rayon's `for_each` over the list splits it
    // into a few long runs up front, and where the costly tiles sit
    // together one thread sits idle: see docs/performance-log.md, "Tile
    // scheduling".)
    let next_tile = AtomicUsize::new(0);
    pool.broadcast(|_| {
        while let Some(&index) = tiles.get(next_tile.fetch_add(1, Ordering::Relaxed)) {
            if cancelled() {
                return;
            }
            let Some(tile) = clock.tile(|| {
                render_tile(
                    &integrator,
                    (camera, on_image.as_ref()),
                    scene.color_space,
                    (settings, selection),
                    (index % tiles_x, index / tiles_x),
                    cancel,
                )
            }) else {
                return;
            };
            let pixels = tile.selected;
            let non_finite = tile.non_finite();
            films
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .add(&tile, non_finite);
            let now = done.fetch_add(pixels, Ordering::Relaxed) + pixels;
            progress(Progress { done: now, total });
        }
        clock.out_of_work();
    });
    let trace = clock.finish(pool.current_num_threads());
    if cancelled() {
        return Err(RenderError::Cancelled);
    }
    let films = films.into_inner().unwrap_or_else(PoisonError::into_inner);
    films.non_finite.check()?;
    let ray_budget_cut = budget_cut(scene, settings, &films.cuts, films.rays[RayKind::Primary]);
    Ok(RenderOutput {
        image: films.image,
        aovs: films.aovs,
        rays: films.rays,
        ray_kinds: integrator.ray_kinds(),
        build_seconds,
        trace,
        thread_clamp,
        ray_budget_cut,
        gradient_exceeded: gradient_note::report(&scene.objects),
        photons: caustics.map(|&(_, report)| report),
    })
}

/// The report of the samples the ray budget cut short, by the material
/// they were cut at: the material with the most (the lowest id among
/// equals, so the report does not depend on the threads). `camera_rays` is
/// the total when the pixels were sampled adaptively.
fn budget_cut(
    scene: &Scene,
    settings: &RenderSettings,
    cuts: &HashMap<MaterialId, u64>,
    camera_rays: u64,
) -> Option<RayBudgetCut> {
    let (&material, _) = cuts
        .iter()
        .max_by_key(|&(material, &samples)| (samples, std::cmp::Reverse(material.0)))?;
    Some(RayBudgetCut {
        samples: cuts.values().sum(),
        total: match settings.aa {
            AntiAliasing::Stratified => {
                u64::from(settings.width)
                    * u64::from(settings.height)
                    * u64::from(settings.samples_per_pixel)
            }
            AntiAliasing::Adaptive(_) => camera_rays,
        },
        material,
        material_name: scene.material_name(material),
        max_depth: settings.max_depth,
    })
}

/// Whether tile (`tile_x`, `tile_y`) has a selected pixel.
fn tile_is_selected(selection: &PixelSelection, tile_x: u32, tile_y: u32) -> bool {
    let w = selection.window;
    let (x0, y0) = (tile_x * TILE_SIZE, tile_y * TILE_SIZE);
    x0 < w.x1 && x0 + TILE_SIZE > w.x0 && (y0..y0 + TILE_SIZE).any(|y| selection.has_row(y))
}

/// Whether `cancel` is given and set.
fn is_cancelled(cancel: Option<&AtomicBool>) -> bool {
    cancel.is_some_and(|c| c.load(Ordering::Relaxed))
}

/// Renders the selected pixels of tile (`tile_x`, `tile_y`) of the image
/// (the others are left black), seen by `camera`; `on_image`, where known,
/// is where the world can appear. `None` once `cancel` is set: it is
/// checked before each pixel is shaded, so a cancelled render stops within
/// a pixel's work per thread.
fn render_tile(
    integrator: &Integrator,
    (camera, on_image): (&Camera, Option<&WorldOnImage>),
    color_space: ColorSpace,
    (settings, selection): (&RenderSettings, &PixelSelection),
    (tile_x, tile_y): (u32, u32),
    cancel: Option<&AtomicBool>,
) -> Option<Tile> {
    let x0 = tile_x * TILE_SIZE;
    let y0 = tile_y * TILE_SIZE;
    let width = TILE_SIZE.min(settings.width - x0);
    let height = TILE_SIZE.min(settings.height - y0);
    let pixels = (width * height) as usize;
    let mut tile = Tile {
        x0,
        y0,
        width,
        height,
        color: Vec::with_capacity(3 * pixels),
        aovs: settings
            .aovs
            .iter()
            .map(|a| Vec::with_capacity(a.channels() * pixels))
            .collect(),
        rays: RayCounts::default(),
        cuts: HashMap::new(),
        selected: 0,
    };
    let mut adaptive = match settings.aa {
        AntiAliasing::Stratified => None,
        AntiAliasing::Adaptive(a) => Some(AdaptivePixels::new(
            integrator,
            camera,
            settings,
            color_space,
            a,
        )),
    };
    let row = x0..x0 + width;
    let mut samples = RowSamples::new(settings, width, on_image);
    for y in y0..y0 + height {
        let finished = match &mut adaptive {
            Some(adaptive) => adaptive_row(
                integrator,
                camera,
                (settings, selection),
                adaptive,
                (row.clone(), y),
                &mut tile,
                cancel,
            ),
            None => samples.trace(
                integrator,
                camera,
                (settings, selection),
                (row.clone(), y),
                &mut tile,
                cancel,
            ),
        };
        if !finished {
            return None;
        }
    }
    Some(tile)
}

/// The pixels `row` of row `y` sampled adaptively, appended to `tile`;
/// false, with the row unfinished, once `cancel` is set.
fn adaptive_row(
    integrator: &Integrator,
    camera: &Camera,
    (settings, selection): (&RenderSettings, &PixelSelection),
    adaptive: &mut AdaptivePixels,
    (row, y): (Range<u32>, u32),
    tile: &mut Tile,
    cancel: Option<&AtomicBool>,
) -> bool {
    for x in row {
        if !selection.contains(x, y) {
            push_unselected(settings, tile);
            continue;
        }
        if is_cancelled(cancel) {
            return false;
        }
        tile.selected += 1;
        let mut cost = Cost {
            rays: &mut tile.rays,
            cuts: &mut tile.cuts,
        };
        let color = adaptive.pixel(x, y, &mut cost);
        tile.color.extend_from_slice(&color.to_f32());
        push_aovs(integrator, camera, settings, x, y, None, &mut tile.aovs);
    }
    true
}

/// The ray through a pixel's centre and its first hit, if any.
type Centre = (Ray, Option<(Hit, Surface)>);

/// A tile's stratified samples, a row at a time: the row's camera rays
/// for one sample index are made before any is traced, four at a time
/// ([`Camera::rays`]), so that their square roots and divisions overlap
/// rather than each waiting for the previous pixel's trace (measured:
/// docs/performance-log.md, `RowSamples` and "A row's camera rays four at
/// a time"); in worlds that walk packets, their closest hits are then found
/// [`PACKET_SIZE`] rays at a time ([`World::intersect_packet`]), before
/// each is shaded.
struct RowSamples<'w> {
    positions: [DVec2; TILE_SIZE as usize],
    rays: [Ray; TILE_SIZE as usize],
    patterns: [u32; TILE_SIZE as usize],
    sums: [Color; TILE_SIZE as usize],
    /// Each ray's closest hit, where packets found them.
    hits: [Option<Hit>; TILE_SIZE as usize],
    /// With one sample and AOVs, each pixel's ray and its first hit.
    centres: Vec<Option<Centre>>,
    /// Where the world can appear, when known: rays elsewhere are given
    /// no hit without a walk.
    on_image: Option<&'w WorldOnImage>,
}

impl<'w> RowSamples<'w> {
    /// Room for rows of `width` pixels rendered with `settings`, where the
    /// world appears within `on_image` (when known).
    fn new(settings: &RenderSettings, width: u32, on_image: Option<&'w WorldOnImage>) -> Self {
        let keep_centres = settings.samples_per_pixel == 1 && !settings.aovs.is_empty();
        Self {
            positions: [DVec2::ZERO; TILE_SIZE as usize],
            rays: [Ray::new(Vec3::ZERO, Vec3::Z); TILE_SIZE as usize],
            patterns: [0; TILE_SIZE as usize],
            sums: [Color::ZERO; TILE_SIZE as usize],
            hits: [None; TILE_SIZE as usize],
            centres: vec![None; if keep_centres { width as usize } else { 0 }],
            on_image,
        }
    }

    /// The pixels `row` of row `y`, each the mean of its samples, appended
    /// to `tile` (the unselected ones black); false, with the row
    /// unfinished, once `cancel` is set.
    fn trace(
        &mut self,
        integrator: &Integrator,
        camera: &Camera,
        (settings, selection): (&RenderSettings, &PixelSelection),
        (row, y): (Range<u32>, u32),
        tile: &mut Tile,
        cancel: Option<&AtomicBool>,
    ) -> bool {
        let spp = settings.samples_per_pixel;
        let world = integrator.world();
        let packets = settings.packets && settings.fast_paths && world.walks_packets();
        // The hits are this row's only where `find_hits` filled them.
        let prefetch = packets && world.prefetches_surfaces() && selection.has_row(y);
        // The selection, asked once for the row rather than per pixel.
        let (row_selected, columns) = (selection.has_row(y), selection.columns());
        let selected = |x: u32| row_selected && columns.contains(&x);
        // One sample sits at the pixel's centre whatever the pattern.
        for (i, x) in row.clone().enumerate() {
            self.patterns[i] = if spp > 1 { pixel_pattern(x, y) } else { 0 };
            self.sums[i] = Color::ZERO;
        }
        let step = differential_step(settings);
        // A row wholly off the world's image: its rays miss, so they are
        // not even made (AOVs make their centre's ray themselves).
        let misses = self
            .on_image
            .is_some_and(|grid| grid.misses_pixels(row.clone(), y));
        for s in 0..spp {
            if misses {
                for (i, x) in row.clone().enumerate() {
                    if selected(x) {
                        self.sums[i] += integrator.camera_miss(&mut tile.rays).color;
                    }
                }
                continue;
            }
            for (i, x) in row.clone().enumerate() {
                self.positions[i] = sample_position(settings, (x, y), self.patterns[i], s);
            }
            let count = row.len();
            let (width, height) = (settings.width, settings.height);
            camera.rays(width, height, &self.positions[..count], &mut self.rays);
            if packets {
                self.find_hits(world, selection, (row.clone(), y));
            }
            if prefetch {
                for hit in self.hits[..count].iter().flatten() {
                    world.prefetch_surface_start(hit);
                }
            }
            for (i, x) in row.clone().enumerate() {
                if !selected(x) {
                    continue;
                }
                if is_cancelled(cancel) {
                    return false;
                }
                let ray = &self.rays[i];
                if prefetch && let Some(Some(ahead)) = self.hits[..count].get(i + SURFACES_AHEAD) {
                    world.prefetch_surface(ahead);
                }
                let hit = if packets {
                    self.hits[i]
                } else if self.on_image.is_some_and(|w| !w.may_hit(x, y)) {
                    None
                } else {
                    world.intersect(ray)
                };
                let differential = position_differential(camera, settings, self.positions[i], step);
                let counts = &mut tile.rays;
                let sample = match self.centres.get_mut(i) {
                    Some(centre) => {
                        let mut first = FirstHit::default();
                        let sample =
                            integrator.shade_camera_hit(ray, hit, differential, counts, &mut first);
                        *centre = Some((*ray, first.hit));
                        sample
                    }
                    None => {
                        integrator.shade_camera_hit(ray, hit, differential, counts, &mut Unobserved)
                    }
                };
                if let Some(material) = sample.cut_at {
                    *tile.cuts.entry(material).or_default() += 1;
                }
                self.sums[i] += sample.color;
            }
        }
        for (i, x) in row.enumerate() {
            if !selected(x) {
                push_unselected(settings, tile);
                continue;
            }
            tile.selected += 1;
            let color = mean(self.sums[i], spp);
            tile.color.extend_from_slice(&color.to_f32());
            if !settings.aovs.is_empty() {
                let centre = self.centres.get_mut(i).and_then(Option::take);
                push_aovs(integrator, camera, settings, x, y, centre, &mut tile.aovs);
            }
        }
        true
    }

    /// The closest hits of the selected pixels' rays of `row` (of row `y`),
    /// found [`PACKET_SIZE`] at a time, into `hits`.
    fn find_hits(
        &mut self,
        world: &World,
        selection: &PixelSelection,
        (row, y): (Range<u32>, u32),
    ) {
        if !selection.has_row(y) {
            return;
        }
        let window = selection.window;
        let first = (window.x0.max(row.start) - row.start) as usize;
        let end = (window.x1.min(row.end).max(row.start) - row.start) as usize;
        let mut ctx = QueryContext::default();
        for start in (first..end).step_by(PACKET_SIZE) {
            let lanes = start..end.min(start + PACKET_SIZE);
            let pixels = row.start + lanes.start as u32..row.start + lanes.end as u32;
            if let Some(grid) = self.on_image
                && grid.misses_pixels(pixels, y)
            {
                self.hits[lanes].fill(None);
                continue;
            }
            world.intersect_packet(&self.rays[lanes.clone()], &mut ctx, &mut self.hits[lanes]);
        }
    }
}

/// `sum` over `spp` samples: multiplied by the exact reciprocal when `spp`
/// is a power of two (the same result, without a division's latency per
/// pixel), divided otherwise.
#[inline]
fn mean(sum: Color, spp: u32) -> Color {
    if spp.is_power_of_two() {
        sum * (1.0 / f64::from(spp))
    } else {
        sum / f64::from(spp)
    }
}

/// Appends a pixel left out of the selection to `tile`: black, and zero
/// in every AOV.
fn push_unselected(settings: &RenderSettings, tile: &mut Tile) {
    tile.color.extend_from_slice(&[0.0; 3]);
    for (aov, data) in settings.aovs.iter().zip(&mut tile.aovs) {
        data.resize(data.len() + aov.channels(), 0.0);
    }
}

/// Appends the AOVs of pixel (`x`, `y`): those of the ray through its
/// centre, given as `centre` with its first hit when it was traced.
fn push_aovs(
    integrator: &Integrator,
    camera: &Camera,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    centre: Option<Centre>,
    aovs: &mut [Vec<f32>],
) {
    if settings.aovs.is_empty() {
        return;
    }
    let (ray, first_hit) = centre.unwrap_or_else(|| {
        let ray = camera.ray(
            settings.width,
            settings.height,
            f64::from(x) + 0.5,
            f64::from(y) + 0.5,
        );
        let hit = integrator.first_hit(&ray);
        (ray, hit)
    });
    for (aov, data) in settings.aovs.iter().zip(aovs.iter_mut()) {
        match (aov, &first_hit) {
            (Aov::Depth, Some((hit, _))) => data.push(hit.t() as f32),
            (Aov::Depth, None) => data.push(f32::INFINITY),
            (Aov::Normal, Some((_, surface))) => {
                let n = if ray.dir.dot(surface.normal) < 0.0 {
                    surface.normal
                } else {
                    -surface.normal
                };
                data.extend_from_slice(&[n.x as f32, n.y as f32, n.z as f32]);
            }
            (Aov::Normal, None) => data.extend_from_slice(&[0.0; 3]),
            (Aov::Id, Some((hit, _))) => data.push(
                integrator
                    .world()
                    .placement(hit.primitive)
                    .map_or(hit.primitive.0, |(_, p)| p) as f32,
            ),
            (Aov::Instance, Some((hit, _))) => data.push(
                integrator
                    .world()
                    .placement(hit.primitive)
                    .map_or(-1.0, |(k, _)| k as f32),
            ),
            (Aov::Instance, None) => data.push(-1.0),
            (Aov::Id, None) => data.push(-1.0),
            (Aov::Cost, _) => {
                let counters = integrator.traversal_cost(&ray);
                data.push((counters.nodes + counters.primitives) as f32);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The integrator of `scene`'s settings over `prepared`'s world, as the
    /// tests here need it (no caustic map).
    fn plain_integrator<'a>(scene: &'a Scene, prepared: &'a Prepared<'a>) -> Integrator<'a> {
        let settings = &scene.settings;
        let limits = RecursionLimits {
            max_depth: settings.max_depth,
            min_weight: settings.min_weight,
            ray_budget: SECONDARY_RAY_BUDGET,
        };
        Integrator::new(
            settings.integrator,
            &prepared.world,
            shading_of(scene),
            limits,
        )
    }

    /// A glass ball that reflects and transmits everything, in a mirror
    /// box: its ray tree grows at every bounce and no weight decays.
    const GLASS_IN_MIRRORS: &str = include_str!("../../tests/hostile_scenes/glass_in_mirrors.toml");

    fn glass_in_mirrors() -> Scene {
        let mut scene =
            crate::scene::parse_scene(GLASS_IN_MIRRORS, std::path::Path::new("box.toml")).unwrap();
        scene.settings.width = 4;
        scene.settings.height = 4;
        scene
    }

    #[test]
    fn tiles_gathered_in_any_order_name_the_image_s_first_bad_pixel() {
        // Edge tiles narrower and shorter than the others, bad pixels off
        // the diagonal, tiles added in a shuffled order.
        let (width, height) = (2 * TILE_SIZE + 7, TILE_SIZE + 5);
        let mut picture = Film::new(width, height, 3);
        for y in 0..height {
            for x in 0..width {
                let i = (y * width + x) as f32;
                picture.set_pixel(x, y, &[i, i + 0.25, i + 0.5]);
            }
        }
        let bad = [
            (TILE_SIZE + 3, 2),
            (5, TILE_SIZE + 1),
            (2 * TILE_SIZE + 4, 1),
        ];
        for (k, &(x, y)) in bad.iter().enumerate() {
            let value = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][k];
            picture.set_pixel(x, y, &[0.5, value, 0.5]);
        }
        let mut tiles: Vec<Tile> = (0..tile_count(width, height) as u32)
            .map(|index| {
                let tiles_x = width.div_ceil(TILE_SIZE);
                let (x0, y0) = (index % tiles_x * TILE_SIZE, index / tiles_x * TILE_SIZE);
                let (w, h) = (TILE_SIZE.min(width - x0), TILE_SIZE.min(height - y0));
                let color = (y0..y0 + h)
                    .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
                    .flat_map(|(x, y)| picture.pixel(x, y).to_vec())
                    .collect();
                Tile {
                    x0,
                    y0,
                    width: w,
                    height: h,
                    color,
                    aovs: Vec::new(),
                    rays: RayCounts::default(),
                    cuts: HashMap::new(),
                    selected: u64::from(w * h),
                }
            })
            .collect();
        tiles.reverse();
        tiles.swap(0, 2);
        let mut films = Films {
            image: Film::new(width, height, 3),
            aovs: Vec::new(),
            rays: RayCounts::default(),
            cuts: HashMap::new(),
            non_finite: NonFinite::default(),
        };
        for tile in &tiles {
            films.add(tile, tile.non_finite());
        }
        let same = |a: &Film, b: &Film| {
            a.data()
                .iter()
                .zip(b.data())
                .all(|(p, q)| p.to_bits() == q.to_bits())
        };
        assert!(same(&films.image, &picture));
        let Err(RenderError::NotFinite { count, x, y }) = films.non_finite.check() else {
            panic!("the bad pixels went unnoticed");
        };
        assert_eq!((count, x, y), (3, 2 * TILE_SIZE + 4, 1));
    }

    #[test]
    fn an_exploding_ray_tree_is_cut_at_the_budget_and_names_its_material() {
        let scene = glass_in_mirrors();
        let output = render(&scene, &|_| {}).unwrap();
        let cut = output.ray_budget_cut.unwrap();
        assert_eq!((cut.samples, cut.total), (16, 16));
        assert_eq!(cut.material_name, "`glass`");
        assert_eq!(cut.max_depth, 40);
        let secondary = output.rays[RayKind::Reflected] + output.rays[RayKind::Refracted];
        assert!(
            secondary <= 16 * u64::from(SECONDARY_RAY_BUDGET),
            "{secondary}"
        );
    }

    #[test]
    fn where_the_budget_cuts_does_not_depend_on_the_threads() {
        let mut scene = glass_in_mirrors();
        scene.settings.threads = Some(1);
        let one = render(&scene, &|_| {}).unwrap();
        scene.settings.threads = Some(3);
        let three = render(&scene, &|_| {}).unwrap();
        assert_eq!(one.image, three.image);
        assert_eq!(one.rays, three.rays);
        assert_eq!(one.ray_budget_cut, three.ray_budget_cut);
    }

    #[test]
    fn camera_ray_packets_give_the_picture_of_single_rays() {
        // A window that cuts tiles and rows, every other row, two samples
        // and the AOVs that keep the first hit: the packets must find the
        // same hits, pixel for pixel, as rays walked one at a time.
        let mut scene = crate::scene::default_scene();
        scene.settings.width = 83;
        scene.settings.height = 61;
        scene.settings.samples_per_pixel = 2;
        scene.settings.threads = Some(2);
        scene.settings.aovs = vec![Aov::Depth, Aov::Normal, Aov::Id];
        let world = World::new(&scene.objects);
        assert_eq!(world.walks_packets(), has_avx());
        let selection = PixelSelection {
            window: Window {
                x0: 5,
                y0: 3,
                x1: 70,
                y1: 58,
            },
            share: Some(Share { index: 1, count: 2 }),
        };
        let packets = render_selected(&scene, &selection, &|_| {}).unwrap();
        scene.settings.packets = false;
        let single = render_selected(&scene, &selection, &|_| {}).unwrap();
        assert_eq!(packets.image, single.image);
        assert_eq!(packets.aovs, single.aovs);
        assert_eq!(packets.rays, single.rays);
        scene.settings.samples_per_pixel = 1;
        let whole_single = render(&scene, &|_| {}).unwrap();
        scene.settings.packets = true;
        let whole_packets = render(&scene, &|_| {}).unwrap();
        assert_eq!(whole_packets.image, whole_single.image);
        assert_eq!(whole_packets.aovs, whole_single.aovs);
    }

    #[test]
    fn pixels_culled_off_the_world_s_image_are_those_the_walks_give() {
        // Jacks: spheres and cylinders with background all around and
        // between them, lit and mirrored, one sample or three, packets or
        // single rays, with the AOVs that keep the first hit, on an image
        // of partial tiles and cells, whole or in a window that starts off
        // the packets' grid.
        let jacks = "b 0.2 0.05 0.2\nv\nfrom 0 0 -8\nat 0 0 0\nup 0 1 0\nangle 25\n\
            hither 0.001\nresolution 96 64\nl -10 3 -20\nf 0.737 0.561 0.561 0.7 0.7 11 0.5 1\n\
            c -0.7 -0.13 -0.22 0.075 0.7 0.13 0.22 0.075\nc 0 -0.65 0.375 0.075 0 0.65 -0.375 0.075\n\
            s 0.7 0.13 0.22 0.15\ns 0 0.65 -0.375 0.15\ns -0.26 0.35 0.61 0.15\n";
        let mut scene = crate::scene::parse_nff(jacks, std::path::Path::new("jacks.nff")).unwrap();
        (scene.settings.width, scene.settings.height) = (93, 61);
        let (mut culled, mut hit) = (0, 0);
        let aovs = [vec![], vec![Aov::Depth, Aov::Normal, Aov::Id]];
        for ((spp, packets), aovs) in [(1, true), (3, true), (1, false)]
            .into_iter()
            .flat_map(|case| aovs.iter().map(move |a| (case, a.clone())))
        {
            scene.settings.samples_per_pixel = spp;
            scene.settings.packets = packets;
            scene.settings.aovs = aovs;
            let prepared = Prepared::new(&scene).unwrap();
            let settings = &scene.settings;
            let integrator = plain_integrator(&scene, &prepared);
            let (width, height) = (settings.width, settings.height);
            let grid = WorldOnImage::new(&scene.camera, width, height, &prepared.world).unwrap();
            let window = PixelSelection {
                window: Window {
                    x0: 13,
                    y0: 3,
                    x1: 90,
                    y1: 58,
                },
                share: Some(Share { index: 0, count: 2 }),
            };
            for selection in [PixelSelection::whole(width, height), window] {
                for tile_y in 0..height.div_ceil(TILE_SIZE) {
                    for tile_x in 0..width.div_ceil(TILE_SIZE) {
                        let tile = |on_image| {
                            let view = (&scene.camera, on_image);
                            let (at, space) = ((tile_x, tile_y), scene.color_space);
                            render_tile(&integrator, view, space, (settings, &selection), at, None)
                                .unwrap()
                        };
                        let (walked, kept) = (tile(None), tile(Some(&grid)));
                        assert_eq!(walked.color, kept.color, "tile {tile_x}, {tile_y}");
                        assert_eq!(walked.aovs, kept.aovs, "tile {tile_x}, {tile_y}");
                        assert_eq!(walked.rays, kept.rays, "tile {tile_x}, {tile_y}");
                    }
                }
            }
            for y in 0..height {
                for x in 0..width {
                    let centre = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                    let ray = scene.camera.ray(width, height, centre.0, centre.1);
                    culled += usize::from(!grid.may_hit(x, y));
                    hit += usize::from(prepared.world.intersect(&ray).is_some());
                }
            }
        }
        // Most of the background is culled.
        assert!(
            culled > 3 * hit && culled < 6 * 93 * 61 - hit,
            "{culled} culled, {hit} hit"
        );
    }

    /// Whether the current backend has AVX, which the packet walk needs
    /// (`WHITTED_ISA=sse2` turns it off).
    fn has_avx() -> bool {
        crate::accel::Backend::current().has_avx()
    }

    #[test]
    fn a_normal_scene_stays_within_the_budget_and_asks_no_clamp() {
        let mut scene = crate::scene::default_scene();
        scene.settings.width = 32;
        scene.settings.height = 24;
        scene.settings.threads = Some(1);
        let output = render(&scene, &|_| {}).unwrap();
        assert_eq!(output.ray_budget_cut, None);
        assert_eq!(output.thread_clamp, None);
        scene.settings.threads = Some(1000);
        let clamped = render(&scene, &|_| {}).unwrap();
        let clamp = clamped.thread_clamp.unwrap();
        assert_eq!(clamp.tiles, 4);
        assert!(clamp.used <= clamp.tiles, "{clamp:?}");
        assert_eq!(clamped.image, output.image);
    }

    #[test]
    fn a_tile_stops_before_its_next_pixel_once_cancelled_stratified_or_adaptive() {
        for aa in [
            AntiAliasing::Stratified,
            AntiAliasing::Adaptive(Adaptive::default()),
        ] {
            let mut scene = crate::scene::default_scene();
            scene.settings.width = 16;
            scene.settings.height = 16;
            scene.settings.aa = aa;
            let prepared = Prepared::new(&scene).unwrap();
            let settings = &scene.settings;
            let integrator = plain_integrator(&scene, &prepared);
            let whole = PixelSelection::whole(16, 16);
            let tile = |cancel: &AtomicBool| {
                render_tile(
                    &integrator,
                    (&scene.camera, None),
                    scene.color_space,
                    (settings, &whole),
                    (0, 0),
                    Some(cancel),
                )
            };
            let kept = tile(&AtomicBool::new(false)).unwrap();
            let plain = render(&scene, &|_| {}).unwrap();
            assert_eq!(kept.color, plain.image.data(), "{aa:?}");
            assert!(tile(&AtomicBool::new(true)).is_none(), "{aa:?}");
        }
    }

    #[test]
    fn a_cancelled_render_stops_and_an_uncancelled_one_is_the_plain_render() {
        let mut scene = crate::scene::default_scene();
        scene.settings.width = 64;
        scene.settings.height = 48;
        scene.settings.threads = Some(1);
        let cancel = AtomicBool::new(false);
        let plain = render(&scene, &|_| {}).unwrap();
        let kept = render_cancellable(&scene, &cancel, &|_| {}).unwrap();
        assert_eq!(kept.image, plain.image);
        let tiles = std::sync::atomic::AtomicU64::new(0);
        let stopped = render_cancellable(&scene, &cancel, &|_| {
            if tiles.fetch_add(1, Ordering::Relaxed) == 2 {
                cancel.store(true, Ordering::Relaxed);
            }
        });
        assert!(matches!(stopped, Err(RenderError::Cancelled)));
        assert_eq!(tiles.load(Ordering::Relaxed), 3, "tiles rendered of 12");
    }
}
