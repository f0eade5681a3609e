//! A scene's world and caustic map built once, to render many passes that
//! differ only in what a viewer changes between them: the camera, the
//! image size, the samples per pixel and the AOVs (the live preview of
//! `whitted serve` renders every pass of every camera move from one).
//!
//! A [`Pass`] can hold nothing else, so everything that shapes the world
//! or the photon map (objects, lights, materials, structures, photon
//! settings) and every other setting comes from the prepared scene: a
//! pass cannot disagree with the world it is traced through. Each pass is
//! rendered by the code [`super::render`] runs, bit for bit as a render of
//! the scene with the pass's values.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use crate::integrator::CausticMap;
use crate::limits::{Charge, MemoryBudget};
use crate::render::photon_pass::{self, PhotonReport};
use crate::render::{
    Aov, Camera, PixelSelection, Progress, RenderError, RenderOutput, RenderSettings, Scene,
};
use crate::world::World;

/// What may change from one pass of a prepared scene to the next.
#[derive(Clone, Debug, PartialEq)]
pub struct Pass {
    /// The camera.
    pub camera: Camera,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// The AOVs to render besides the colour, in order.
    pub aovs: Vec<Aov>,
}

impl Pass {
    /// The pass `scene` itself asks for.
    pub fn of(scene: &Scene) -> Self {
        let settings = &scene.settings;
        Self {
            camera: scene.camera.clone(),
            width: settings.width,
            height: settings.height,
            samples_per_pixel: settings.samples_per_pixel,
            aovs: settings.aovs.clone(),
        }
    }

    /// The scene's settings with this pass's values.
    fn settings(&self, scene: &Scene) -> RenderSettings {
        RenderSettings {
            width: self.width,
            height: self.height,
            samples_per_pixel: self.samples_per_pixel,
            aovs: self.aovs.clone(),
            ..scene.settings.clone()
        }
    }
}

/// A scene's world and caustic map, built once as [`super::render`] builds
/// them, to render many [`Pass`]es.
pub struct Prepared<'s> {
    pub(super) scene: &'s Scene,
    pub(super) world: World<'s>,
    pub(super) caustics: Option<(CausticMap, PhotonReport)>,
    build_seconds: f64,
    /// The world's estimated memory, charged while it lives.
    _world_charge: Charge,
}

impl<'s> Prepared<'s> {
    /// Checks `scene` (its settings, instances, primitive count and its
    /// own image against the memory budget) and builds its world and
    /// caustic map.
    pub fn new(scene: &'s Scene) -> Result<Self, RenderError> {
        let settings = &scene.settings;
        settings.check()?;
        super::check_objects(&scene.objects)?;
        // The films alone first, for an image too large whatever the
        // scene; they are weighed again beside the world when the render
        // takes them.
        super::resources::check_memory(settings, MemoryBudget::current())?;
        let world_charge = super::charge_world_of(scene)?;
        let start = Instant::now();
        let world = super::build_world(scene);
        let build_seconds = start.elapsed().as_secs_f64();
        let caustics = if settings.photons.enabled() {
            let tiles = super::tile_count(settings.width, settings.height);
            let (pool, _) = super::worker_pool(settings, tiles)?;
            pool.install(|| photon_pass::build(&world, &super::shading_of(scene), settings))?
        } else {
            None
        };
        Ok(Self {
            scene,
            world,
            caustics,
            build_seconds,
            _world_charge: world_charge,
        })
    }

    /// The scene the world was built from.
    pub fn scene(&self) -> &'s Scene {
        self.scene
    }

    /// Seconds it took to build the world (its acceleration structures).
    pub fn build_seconds(&self) -> f64 {
        self.build_seconds
    }

    /// Renders `pass` of the prepared scene as [`super::render_cancellable`]
    /// renders the scene with the pass's values, bit for bit, without
    /// building anything: [`RenderOutput::build_seconds`] is 0.
    pub fn render(
        &self,
        pass: &Pass,
        cancel: &AtomicBool,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<RenderOutput, RenderError> {
        let settings = pass.settings(self.scene);
        let whole = PixelSelection::whole(pass.width, pass.height);
        super::trace_pixels(
            self,
            &pass.camera,
            &settings,
            &whole,
            Some(cancel),
            progress,
            0.0,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    /// A scene with caustics, instances and a reflective floor.
    fn scene() -> Scene {
        let text = include_str!("../../../../scenes/caustics.toml");
        let mut scene =
            crate::scene::parse_scene(text, std::path::Path::new("caustics.toml")).unwrap();
        scene.settings.threads = Some(2);
        scene.settings.photons.count = 4000;
        scene
    }

    #[test]
    fn passes_of_one_prepared_scene_are_the_renders_of_the_scene_bit_for_bit() {
        let base = scene();
        let prepared = Prepared::new(&base).unwrap();
        let turned = Camera::new(
            Vec3::new(3.0, 4.0, -6.0),
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            35.0,
        )
        .unwrap();
        let passes = [
            (base.camera.clone(), 24, 18, 1, vec![]),
            (turned.clone(), 40, 30, 4, vec![Aov::Depth, Aov::Normal]),
            (turned, 17, 9, 2, vec![Aov::Id, Aov::Instance, Aov::Cost]),
            (base.camera.clone(), 33, 20, 1, vec![Aov::Depth]),
        ];
        let cancel = AtomicBool::new(false);
        for (camera, width, height, samples_per_pixel, aovs) in passes {
            let pass = Pass {
                camera,
                width,
                height,
                samples_per_pixel,
                aovs,
            };
            let mut alone = base.clone();
            alone.camera = pass.camera.clone();
            alone.settings = pass.settings(&base);
            let expected = super::super::render(&alone, &|_| {}).unwrap();
            let got = prepared.render(&pass, &cancel, &|_| {}).unwrap();
            assert_eq!(got.image, expected.image, "{width}x{height}");
            assert_eq!(got.aovs, expected.aovs);
            assert_eq!(got.rays, expected.rays);
            let kept = |p: Option<PhotonReport>| p.map(|p| (p.emitted, p.stored));
            assert_eq!(kept(got.photons), kept(expected.photons));
            assert!(got.photons.is_some());
            assert_eq!(got.build_seconds, 0.0);
        }
    }

    #[test]
    fn a_pass_of_the_scene_itself_is_its_render() {
        let mut base = scene();
        base.settings.width = 20;
        base.settings.height = 15;
        let prepared = Prepared::new(&base).unwrap();
        let got = prepared
            .render(&Pass::of(&base), &AtomicBool::new(false), &|_| {})
            .unwrap();
        assert_eq!(
            got.image,
            super::super::render(&base, &|_| {}).unwrap().image
        );
    }

    #[test]
    fn a_pass_with_bad_values_is_refused() {
        let base = scene();
        let prepared = Prepared::new(&base).unwrap();
        let pass = Pass {
            width: 0,
            ..Pass::of(&base)
        };
        let cancel = AtomicBool::new(false);
        let refused = prepared.render(&pass, &cancel, &|_| {});
        assert!(matches!(refused, Err(RenderError::BadSize { .. })));
    }
}
