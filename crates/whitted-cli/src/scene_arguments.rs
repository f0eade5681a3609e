//! The arguments that say which scene and how it is seen, shared by the
//! commands that render it (`render`, `explain`): the scene file, the
//! image size, the samples and anti-aliasing, the depth, the acceleration
//! structures, the photons, the camera and the memory budget.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use whitted::accel::AccelKind;
use whitted::limits::MemoryBudget;
use whitted::math::Vec3;
use whitted::render::{Scene, check_image_size};
use whitted::scene::{CameraOverride, LoadOptions, load_any_with};
use whitted::shading::TextureFilter;

use crate::anti_aliasing::AaArgs;
use crate::arguments;
use crate::report::note;

/// Which scene, and how it is seen.
#[derive(Debug, Args)]
pub struct SceneArgs {
    /// Scene file: .toml (ours), .nff (Neutral File Format), .obj
    /// (Wavefront, with its .mtl) or .bpt (Bézier patches). Without one,
    /// the built-in scene is rendered.
    pub scene: Option<PathBuf>,

    /// Image width in pixels (1 to 65535; at most 268435456 pixels in all).
    #[arg(long, value_name = "W", value_parser = arguments::image_side, allow_negative_numbers = true)]
    width: Option<u32>,

    /// Image height in pixels (1 to 65535; at most 268435456 pixels in all).
    #[arg(long, value_name = "H", value_parser = arguments::image_side, allow_negative_numbers = true)]
    height: Option<u32>,

    /// Samples per pixel, on a stratified seeded pattern (1 = pixel centre;
    /// at most 65536).
    #[arg(long, value_name = "N", value_parser = arguments::samples, allow_negative_numbers = true)]
    spp: Option<u32>,

    /// Maximum reflection/refraction depth (0 = no secondary rays; default 8;
    /// at most 1000).
    #[arg(long, value_name = "D", value_parser = arguments::depth, allow_negative_numbers = true)]
    max_depth: Option<u32>,

    /// Acceleration structure over the objects (overrides the scene's
    /// `accel`); every structure gives the same picture.
    #[arg(long, value_name = "NAME", value_parser = parse_accel)]
    accel: Option<AccelKind>,

    /// Structure over what the scene places itself (instances, shapes),
    /// if not `--accel`'s (overrides the scene's `accel_top`).
    #[arg(long, value_name = "NAME", value_parser = parse_accel)]
    accel_top: Option<AccelKind>,

    /// Structure of each definition and each mesh kept as an instance, if
    /// not `--accel`'s (overrides the scene's `accel_bottom`).
    #[arg(long, value_name = "NAME", value_parser = parse_accel)]
    accel_bottom: Option<AccelKind>,

    /// Photons to shoot for caustics (overrides the scene's `photons`; 0 =
    /// off, the default; at most 100000000).
    #[arg(long, value_name = "N", value_parser = arguments::photons, allow_negative_numbers = true)]
    photons: Option<u64>,

    #[command(flatten)]
    aa: Box<AaArgs>,

    /// Filter textures over each pixel's footprint (overrides the scene's
    /// `texture_filter`): `mipmap` carries ray differentials and samples
    /// images from mipmaps and checkers box-filtered; `none` (the default)
    /// looks them up at the hit point.
    #[arg(long, value_name = "NAME", value_parser = parse_texture_filter)]
    texture_filter: Option<TextureFilter>,

    /// Walk camera rays one at a time rather than a tile row's eight at a
    /// time (the same picture; to compare the time).
    #[arg(long)]
    no_packets: bool,

    /// Trace every ray by the plain closest-hit or any-hit query, without
    /// the fast paths (camera-ray packets, the shadow cache, shadow rays
    /// through glass answered from one walk, rays inside glass spheres):
    /// the same picture, the reference they are checked against.
    #[arg(long)]
    no_fast_paths: bool,

    /// Put the camera's eye here (replaces the scene's).
    #[arg(long, value_name = "X,Y,Z", value_parser = arguments::vec3, allow_hyphen_values = true)]
    eye: Option<Vec3>,

    /// Point the camera at this point (replaces the scene's).
    #[arg(long, value_name = "X,Y,Z", value_parser = arguments::vec3, allow_hyphen_values = true)]
    look_at: Option<Vec3>,

    /// The direction that is up on the image (replaces the scene's).
    #[arg(long, value_name = "X,Y,Z", value_parser = arguments::vec3, allow_hyphen_values = true)]
    up: Option<Vec3>,

    /// Vertical field of view in degrees, top edge to bottom edge
    /// (replaces the scene's; between 0 and 180, both excluded).
    #[arg(long, value_name = "DEG", value_parser = arguments::field_of_view, allow_hyphen_values = true)]
    fov: Option<f64>,

    /// The memory budget: the most an image, a texture or an input file
    /// may take, like 512M or 8G (default: 3/4 of this machine's memory).
    #[arg(long, value_name = "SIZE", value_parser = whitted::limits::parse_size)]
    max_memory: Option<u64>,
}

/// Parses the name of an acceleration structure.
fn parse_accel(name: &str) -> Result<AccelKind, String> {
    AccelKind::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = AccelKind::ALL.iter().map(AccelKind::name).collect();
        format!("expected one of: {}", names.join(", "))
    })
}

fn parse_texture_filter(name: &str) -> Result<TextureFilter, String> {
    TextureFilter::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = TextureFilter::ALL.iter().map(|f| f.name()).collect();
        format!("expected one of: {}", names.join(", "))
    })
}

impl SceneArgs {
    /// The parts of the scene's camera the arguments replace.
    fn camera_override(&self) -> CameraOverride {
        CameraOverride {
            eye: self.eye,
            look_at: self.look_at,
            up: self.up,
            fov_degrees: self.fov,
        }
    }

    /// Refuses, before the scene is read, what the arguments alone show
    /// cannot be rendered: an image of too many pixels, a camera no scene
    /// could have. (Each value was checked on its own as it was parsed.)
    /// Sets the memory budget.
    pub fn check(&self) -> Result<(), String> {
        if let (Some(width), Some(height)) = (self.width, self.height) {
            check_image_size(width, height)
                .map_err(|e| format!("--width {width} --height {height}: {e}"))?;
        }
        self.camera_override()
            .check()
            .map_err(|e| format!("the camera asked for is invalid: {e}"))?;
        if let Some(bytes) = self.max_memory {
            MemoryBudget::given(bytes).set_current();
        }
        Ok(())
    }

    /// Reads the scene (the built-in one without a file) and applies the
    /// arguments to it; unless `quiet`, reports the reader's warnings and
    /// what was read.
    pub fn load(&self, quiet: bool) -> Result<Scene, String> {
        self.load_with_warnings(quiet).map(|(scene, _)| scene)
    }

    /// [`SceneArgs::load`], also giving the reader's warnings as they
    /// are printed (for a caller that shows them elsewhere too).
    pub fn load_with_warnings(&self, quiet: bool) -> Result<(Scene, Vec<String>), String> {
        let options = LoadOptions {
            camera: self.camera_override(),
        };
        let mut warnings = Vec::new();
        let mut scene = match &self.scene {
            Some(path) => {
                let start = Instant::now();
                let loaded = load_any_with(path, &options).map_err(|e| e.to_string())?;
                warnings = loaded.warnings.iter().map(ToString::to_string).collect();
                if !quiet {
                    for warning in &warnings {
                        note!("{warning}\n");
                    }
                    let primitives = match loaded.scene.objects.checked_primitive_count() {
                        Some(count) => count.to_string(),
                        None => format!("more than {}", usize::MAX),
                    };
                    note!(
                        "{}: read in {:.3} s, {primitives} primitives",
                        path.display(),
                        start.elapsed().as_secs_f64(),
                    );
                }
                loaded.scene
            }
            None => {
                let mut scene = whitted::scene::default_scene();
                scene.camera = options
                    .camera
                    .apply(&scene.camera)
                    .map_err(|e| format!("the camera asked for is invalid: {e}"))?;
                scene
            }
        };
        let settings = &mut scene.settings;
        settings.width = self.width.unwrap_or(settings.width);
        settings.height = self.height.unwrap_or(settings.height);
        settings.samples_per_pixel = self.spp.unwrap_or(settings.samples_per_pixel);
        settings.max_depth = self.max_depth.unwrap_or(settings.max_depth);
        settings.accel = self.accel.unwrap_or(settings.accel);
        settings.accel_top = self.accel_top.or(settings.accel_top);
        settings.accel_bottom = self.accel_bottom.or(settings.accel_bottom);
        settings.photons.count = self.photons.unwrap_or(settings.photons.count);
        settings.aa = self.aa.apply(settings.aa)?;
        settings.texture_filter = self.texture_filter.unwrap_or(settings.texture_filter);
        settings.packets &= !self.no_packets;
        settings.fast_paths &= !self.no_fast_paths;
        Ok((scene, warnings))
    }
}
