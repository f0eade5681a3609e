//! Why a pixel has its colour: the ray tree of one of its samples, traced
//! by the renderer's own integrator with a [`RayTreeRecorder`] watching
//! (what `whitted explain` prints).
//!
//! The sample's camera ray is the renderer's ([`super::sample_ray`]), the
//! world and the integrator are built as [`super::render`] builds them, and
//! the pixel is the mean of its samples' colours summed in the renderer's
//! order: so the tree's root colour is the sample's radiance, bit for bit,
//! and [`PixelExplanation::pixel`] is the rendered pixel, bit for bit.
//! With adaptive anti-aliasing the samples are the corners the pixel's
//! subdivision traces ([`super::adaptive`], the renderer's own pass run
//! on that pixel alone) and the pixel is their area average.
//!
//! The tree holds at most [`Explainer::with_max_tree_rays`] rays and light
//! verdicts (see [`RayTreeRecorder`]); the colours are exact whatever it
//! leaves out, and [`PixelExplanation::left_out`] says how much that is.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::accel::AccelKind;
use crate::integrator::{
    Cancellable, CausticMap, DEFAULT_MAX_TREE_RAYS, Integrator, RayCounts, RayNode, RayObserver,
    RayTreeRecorder, RecursionLimits, SECONDARY_RAY_BUDGET,
};
use crate::limits::Charge;
use crate::math::DVec2;
use crate::render::adaptive::{AdaptivePixels, Cost};
use crate::render::sample_ray::{
    pixel_pattern, position_differential, position_ray, sample_differential, sample_ray,
};
use crate::render::shading_of;
use crate::render::{AntiAliasing, Camera, RenderError, RenderSettings, Scene};
use crate::shading::Color;
use crate::world::World;

/// The ray tree of one sample of one pixel, and the pixel it ends in.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelExplanation {
    /// The pixel's column.
    pub x: u32,
    /// The pixel's row (0 at the top).
    pub y: u32,
    /// Which of the pixel's samples is explained: with adaptive
    /// anti-aliasing, which of the corners its subdivision traced, in
    /// reading order.
    pub sample: u32,
    /// The pixel's number of samples (of corners, with adaptive
    /// anti-aliasing).
    pub samples: u32,
    /// Where the sample lies on the image, in pixels from the top left
    /// corner.
    pub position: DVec2,
    /// How the pixel was sampled: with adaptive anti-aliasing, the pixel
    /// is the area average of its squares, each the mean of its corners.
    pub aa: AntiAliasing,
    /// The structure the rays were traced through (the costs are its).
    pub accel: AccelKind,
    /// The recursion limits the tree was traced with.
    pub limits: RecursionLimits,
    /// The ray tree; its root's colour is the sample's colour.
    pub tree: RayNode,
    /// How many rays and light verdicts the tree could hold.
    pub max_tree_rays: u64,
    /// How many the sample traced that the tree left out (0: the tree is
    /// whole); each hit where some were says so with a
    /// [`crate::integrator::Stop::TreeLimit`].
    pub left_out: u64,
    /// Every sample's colour, in order.
    pub sample_colors: Vec<Color>,
    /// The pixel as the renderer stores it, in 32-bit floats: the mean of
    /// the samples' colours, or the area average of the adaptive squares.
    pub pixel: [f32; 3],
}

/// Why a pixel cannot be explained.
#[derive(Debug, thiserror::Error)]
pub enum ExplainError {
    /// The scene's settings cannot be rendered.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The pixel is outside the image.
    #[error(
        "the pixel {x},{y} is outside the {width}x{height} image (columns 0 to {}, rows 0 to {})",
        width - 1,
        height - 1
    )]
    PixelOutside {
        /// The column asked for.
        x: u32,
        /// The row asked for.
        y: u32,
        /// The image width.
        width: u32,
        /// The image height.
        height: u32,
    },
    /// The sample is not one of the pixel's.
    #[error("sample {sample} does not exist: the pixel has {samples} (0 to {})", samples - 1)]
    SampleOutside {
        /// The sample asked for.
        sample: u32,
        /// The samples per pixel.
        samples: u32,
    },
    /// The explanation was cancelled before it was done
    /// ([`Explainer::explain_unless`]).
    #[error("the explanation was cancelled: a newer scene or camera replaced it")]
    Cancelled,
}

/// Explains sample `sample` of pixel (`x`, `y`) of `scene` rendered with
/// its settings. The recursion runs on a thread with the renderer's stack
/// size for the scene's depth.
pub fn explain_pixel(
    scene: &Scene,
    pixel: (u32, u32),
    sample: u32,
) -> Result<PixelExplanation, ExplainError> {
    Explainer::new(scene)?.explain(&scene.camera, pixel, sample)
}

/// A scene's world and caustic map, built once as [`super::render`] builds
/// them, to explain many pixels without building them again (the live
/// preview of `whitted serve` keeps one while the scene, its structure
/// and its settings stay the same). The camera is not part of the world:
/// each explanation names its own.
pub struct Explainer<'s> {
    scene: &'s Scene,
    world: World<'s>,
    caustics: Option<CausticMap>,
    max_tree_rays: u64,
    /// The world's estimated memory, charged while it lives.
    _world_charge: Charge,
}

impl<'s> Explainer<'s> {
    /// Checks `scene`'s settings and builds its world and caustic map.
    pub fn new(scene: &'s Scene) -> Result<Self, ExplainError> {
        let settings = &scene.settings;
        settings.check()?;
        super::check_objects(&scene.objects)?;
        let world_charge = super::charge_world_of(scene).map_err(RenderError::from)?;
        // As `render` builds them.
        let world = super::build_world(scene);
        let caustics = on_deep_stack(settings.max_depth, || {
            super::photon_pass::build(&world, &shading_of(scene), settings)
                .map_err(RenderError::from)
        })??;
        Ok(Self {
            scene,
            world,
            caustics: caustics.map(|(map, _)| map),
            max_tree_rays: DEFAULT_MAX_TREE_RAYS,
            _world_charge: world_charge,
        })
    }

    /// Records at most `max_rays` rays and light verdicts in each tree
    /// (at least the camera ray; [`DEFAULT_MAX_TREE_RAYS`] unless told).
    pub fn with_max_tree_rays(mut self, max_rays: u64) -> Self {
        self.max_tree_rays = max_rays;
        self
    }

    /// Explains sample `sample` of pixel (`x`, `y`) seen through `camera`
    /// (the scene's own, or one the viewer moved). The recursion runs on a
    /// thread with the renderer's stack size for the scene's depth.
    pub fn explain(
        &self,
        camera: &Camera,
        pixel: (u32, u32),
        sample: u32,
    ) -> Result<PixelExplanation, ExplainError> {
        self.explain_unless(camera, pixel, sample, &AtomicBool::new(false))
    }

    /// [`Self::explain`], given up once `cancel` is set: the tracing then
    /// starts no further shadow or secondary rays, nor (with stratified
    /// samples) a further sample of the pixel, and the answer is
    /// [`ExplainError::Cancelled`]. Adaptive anti-aliasing's corners, a few
    /// hundred camera rays at most, are traced whole first.
    pub fn explain_unless(
        &self,
        camera: &Camera,
        (x, y): (u32, u32),
        sample: u32,
        cancel: &AtomicBool,
    ) -> Result<PixelExplanation, ExplainError> {
        let settings = &self.scene.settings;
        let (width, height) = (settings.width, settings.height);
        if x >= width || y >= height {
            return Err(ExplainError::PixelOutside {
                x,
                y,
                width,
                height,
            });
        }
        let samples = settings.samples_per_pixel;
        if settings.aa == AntiAliasing::Stratified && sample >= samples {
            return Err(ExplainError::SampleOutside { sample, samples });
        }
        on_deep_stack(settings.max_depth, || {
            self.trace_pixel(camera, (x, y), sample, cancel)
        })?
    }

    /// [`Self::explain`] once the arguments are checked, on the thread
    /// that recurses.
    fn trace_pixel(
        &self,
        camera: &Camera,
        (x, y): (u32, u32),
        sample: u32,
        cancel: &AtomicBool,
    ) -> Result<PixelExplanation, ExplainError> {
        let cancelled = || cancel.load(Ordering::Relaxed);
        let (scene, world) = (self.scene, &self.world);
        let settings = &scene.settings;
        let shading = shading_of(scene);
        let limits = limits_of(settings);
        let integrator = Integrator::new(settings.integrator, world, shading, limits)
            .with_caustics(self.caustics.as_ref())
            .with_fast_paths(settings.fast_paths);
        let mut counts = RayCounts::default();
        let (pixel, samples) = match settings.aa {
            AntiAliasing::Stratified => {
                let watch = &mut Cancellable(cancel);
                stratified_samples(scene, camera, &integrator, (x, y), &mut counts, watch)
            }
            AntiAliasing::Adaptive(adaptive) => {
                let pixels =
                    AdaptivePixels::new(&integrator, camera, settings, scene.color_space, adaptive);
                let mut cost = Cost {
                    rays: &mut counts,
                    cuts: &mut HashMap::new(),
                };
                pixels.pixel_alone(x, y, &mut cost)
            }
        };
        if cancelled() {
            return Err(ExplainError::Cancelled);
        }
        let count = samples.len() as u32;
        let Some(&(position, _)) = samples.get(sample as usize) else {
            return Err(ExplainError::SampleOutside {
                sample,
                samples: count,
            });
        };
        // The sample's own ray and differential again, watched: the same
        // ray through the same integrator, so the root's colour is the
        // sample's bit for bit.
        let ray = position_ray(camera, settings, position);
        let differential = match settings.aa {
            AntiAliasing::Stratified => {
                sample_differential(camera, settings, (x, y), pixel_pattern(x, y), sample)
            }
            AntiAliasing::Adaptive(_) => position_differential(camera, settings, position, 1.0),
        };
        let mut recorder =
            RayTreeRecorder::new(world, shading, limits, self.max_tree_rays).with_cancel(cancel);
        integrator.trace_primary_observed(&ray, differential, &mut counts, &mut recorder);
        if cancelled() {
            return Err(ExplainError::Cancelled);
        }
        let (tree, left_out) = recorder.finish().ok_or(ExplainError::SampleOutside {
            sample,
            samples: count,
        })?;
        Ok(PixelExplanation {
            x,
            y,
            sample,
            samples: count,
            position,
            aa: settings.aa,
            accel: settings.accel,
            limits,
            tree,
            max_tree_rays: self.max_tree_rays.max(1),
            left_out,
            sample_colors: samples.into_iter().map(|(_, color)| color).collect(),
            pixel: pixel.to_f32(),
        })
    }
}

/// The recursion limits of `settings`, as `render` gives them.
fn limits_of(settings: &RenderSettings) -> RecursionLimits {
    RecursionLimits {
        max_depth: settings.max_depth,
        min_weight: settings.min_weight,
        ray_budget: SECONDARY_RAY_BUDGET,
    }
}

/// Runs `work` on a thread with the renderer's stack size for
/// `max_depth`.
fn on_deep_stack<T: Send>(
    max_depth: u32,
    work: impl FnOnce() -> T + Send,
) -> Result<T, RenderError> {
    let stack = super::worker_stack_bytes(max_depth);
    std::thread::scope(|scope| {
        Ok(std::thread::Builder::new()
            .stack_size(stack)
            .spawn_scoped(scope, work)
            .map_err(|e| RenderError::Threads {
                threads: 1,
                message: e.to_string(),
            })?
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
    })
}

/// The stratified samples of pixel (`x`, `y`), each with its position on
/// the image and its colour, and their mean summed in the renderer's order.
fn stratified_samples(
    scene: &Scene,
    camera: &Camera,
    integrator: &Integrator<'_>,
    (x, y): (u32, u32),
    counts: &mut RayCounts,
    watch: &mut Cancellable<'_>,
) -> (Color, Vec<(DVec2, Color)>) {
    let settings = &scene.settings;
    let spp = settings.samples_per_pixel;
    let pattern = pixel_pattern(x, y);
    let mut sum = Color::ZERO;
    let mut samples = Vec::with_capacity(spp as usize);
    for s in 0..spp {
        if watch.stopped() {
            break;
        }
        let ray = sample_ray(camera, settings, (x, y), pattern, s);
        let differential = sample_differential(camera, settings, (x, y), pattern, s);
        let color = integrator
            .trace_primary_observed(&ray, differential, counts, watch)
            .color;
        let offset = crate::math::sampling::pixel_sample(s, spp, pattern);
        samples.push((
            DVec2::new(f64::from(x) + offset.x, f64::from(y) + offset.y),
            color,
        ));
        sum += color;
    }
    (sum / f64::from(spp), samples)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{RayKind, Unobserved};
    use crate::math::DVec2;

    /// A glass ball in a mirror box, its tree as deep as the budget allows.
    fn glass_in_mirrors() -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/hostile_scenes/glass_in_mirrors.toml");
        crate::scene::load_any(&path).unwrap()
    }

    #[test]
    fn a_stopped_sample_starts_no_shadow_or_secondary_ray() {
        let scene = glass_in_mirrors();
        let world = super::super::build_world(&scene);
        let settings = &scene.settings;
        let integrator = Integrator::new(
            settings.integrator,
            &world,
            shading_of(&scene),
            limits_of(settings),
        );
        let ray = position_ray(&scene.camera, settings, DVec2::new(4.0, 4.0));
        let counts = |stop: bool| {
            let mut counts = RayCounts::default();
            let flag = AtomicBool::new(stop);
            integrator.trace_primary_observed(&ray, None, &mut counts, &mut Cancellable(&flag));
            counts
        };
        let mut unobserved = RayCounts::default();
        integrator.trace_primary_observed(&ray, None, &mut unobserved, &mut Unobserved);
        // Not stopped: the same work as without the watch.
        assert_eq!(counts(false), unobserved);
        assert!(unobserved[RayKind::Reflected] > 100, "{unobserved:?}");
        let stopped = counts(true);
        assert_eq!(stopped[RayKind::Primary], 1);
        assert_eq!(
            stopped.total(),
            1,
            "only the camera ray is traced: {stopped:?}"
        );
    }

    /// The glass ball in its mirror box lit by an area light of 4096
    /// samples, whose pixel takes millions of shadow rays: cancelled while
    /// it is traced, it ends at once.
    #[test]
    fn an_explanation_cancelled_while_traced_ends_at_once() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/hostile_scenes/glass_in_mirrors_area_light.toml");
        let scene = crate::scene::load_any(&path).unwrap();
        let explainer = Explainer::new(&scene).unwrap();
        let cancel = AtomicBool::new(false);
        let start = std::time::Instant::now();
        let answer = std::thread::scope(|scope| {
            let explaining =
                scope.spawn(|| explainer.explain_unless(&scene.camera, (4, 4), 0, &cancel));
            std::thread::sleep(std::time::Duration::from_millis(200));
            cancel.store(true, Ordering::Relaxed);
            explaining.join().unwrap()
        });
        assert!(matches!(answer, Err(ExplainError::Cancelled)), "{answer:?}");
        let elapsed = start.elapsed();
        assert!(elapsed < std::time::Duration::from_secs(10), "{elapsed:?}");
    }

    #[test]
    fn a_cancelled_explanation_says_so() {
        let scene = glass_in_mirrors();
        let explainer = Explainer::new(&scene).unwrap();
        let cancelled = explainer.explain_unless(&scene.camera, (4, 4), 0, &AtomicBool::new(true));
        let error = cancelled.unwrap_err();
        assert!(matches!(error, ExplainError::Cancelled));
        assert_eq!(
            error.to_string(),
            "the explanation was cancelled: a newer scene or camera replaced it"
        );
        let kept = explainer.explain_unless(&scene.camera, (4, 4), 0, &AtomicBool::new(false));
        let whole = explainer.explain(&scene.camera, (4, 4), 0);
        assert_eq!(kept.unwrap().tree, whole.unwrap().tree);
    }
}
