//! How to render: the one settings type. A scene file fills the picture's
//! part (size, samples, depth, structure), the command line may replace any
//! of it and adds the rest (threads, per-pixel data).

use super::{AntiAliasing, RenderError};
use crate::accel::AccelKind;
use crate::integrator::{IntegratorKind, PhotonSettings};
use crate::shading::TextureFilter;

/// The deepest recursion a render accepts. Each level takes a few
/// kilobytes of a worker's stack, which is sized for it.
pub const MAX_DEPTH: u32 = 1000;

/// Longest side of an image a render accepts, in pixels.
pub const MAX_SIDE: u32 = 65535;

/// Largest image (in pixels) a render accepts: a few gigabytes of film.
pub const MAX_PIXELS: u64 = 1 << 28;

/// Most samples per pixel a render accepts: 65536 is a 256 × 256 grid of
/// strata over the pixel, which resolves how much of the pixel an edge
/// covers to 1/256 along each axis, the step of an 8-bit channel. The
/// position in the pixel is the only thing a sample varies, so more
/// samples cannot change an 8-bit pixel by a step; they only multiply the
/// time (2³² samples of a single pixel would take hours).
pub const MAX_SAMPLES: u32 = 1 << 16;

/// Refuses an image of `width` × `height` pixels that a render would
/// refuse: a side of 0 or beyond [`MAX_SIDE`], or more than [`MAX_PIXELS`]
/// pixels. Readers and the command line call it as soon as they know the
/// size, before anything is loaded or built.
pub fn check_image_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(RenderError::BadSize { width, height });
    }
    if u64::from(width) * u64::from(height) > MAX_PIXELS {
        return Err(RenderError::TooManyPixels { width, height });
    }
    Ok(())
}

/// Per-pixel data besides the colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Aov {
    /// Distance along the unit-length primary ray through the pixel centre
    /// to the first hit; +∞ where nothing is hit.
    Depth,
    /// World-space shading normal at that hit (facing the camera); 0 for a
    /// miss.
    Normal,
    /// Index of the primitive hit, as a float; -1 for a miss. Inside an
    /// instance of a definition, the primitive's index in the definition
    /// (see [`crate::world::World::placement`]).
    Id,
    /// Traversal cost of that ray: acceleration-structure nodes visited plus
    /// primitives tested.
    Cost,
    /// Index of the instance of a definition hit (the world's instances,
    /// in order), as a float; -1 for a miss or a primitive placed by the
    /// world itself. With `Id`, it names what was hit.
    Instance,
}

impl Aov {
    /// Every AOV.
    pub const ALL: [Aov; 5] = [Aov::Depth, Aov::Normal, Aov::Id, Aov::Cost, Aov::Instance];

    /// The name used on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Aov::Depth => "depth",
            Aov::Normal => "normal",
            Aov::Id => "id",
            Aov::Cost => "cost",
            Aov::Instance => "instance",
        }
    }

    /// The AOV called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    /// Values per pixel.
    pub fn channels(&self) -> usize {
        match self {
            Aov::Normal => 3,
            Aov::Depth | Aov::Id | Aov::Cost | Aov::Instance => 1,
        }
    }

    /// Whether a render can give `value` as one of this AOV's channels:
    /// a depth of 0 or more (+∞ for a miss), a finite normal component,
    /// a whole index from -1 on, a whole cost from 0 on. What reads stored
    /// AOVs back (merged parts) refuses any other value.
    pub fn admits(&self, value: f32) -> bool {
        match self {
            Aov::Depth => value >= 0.0,
            Aov::Normal => value.is_finite(),
            Aov::Id | Aov::Instance => value >= -1.0 && value.fract() == 0.0,
            Aov::Cost => value >= 0.0 && value.fract() == 0.0,
        }
    }
}

/// How to render: image size, sampling, recursion limits, the acceleration
/// structure, threads and per-pixel data.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel (1 means exactly the pixel centre), when `aa` is
    /// stratified.
    pub samples_per_pixel: u32,
    /// How the camera samples each pixel.
    pub aa: AntiAliasing,
    /// Deepest reflection/refraction recursion; 0 traces primary rays only.
    pub max_depth: u32,
    /// A branch whose weight on the pixel falls below this stops early
    /// (adaptive depth control, Hall and Greenberg 1983).
    pub min_weight: f64,
    /// The acceleration structure to build over the primitives.
    pub accel: AccelKind,
    /// The structure over what the world places itself, if not `accel`.
    pub accel_top: Option<AccelKind>,
    /// The structure of each definition and each mesh kept as an
    /// instance, if not `accel`.
    pub accel_bottom: Option<AccelKind>,
    /// The algorithm that computes the colour along each camera ray.
    pub integrator: IntegratorKind,
    /// Photon-mapped caustics: off unless photons are asked for.
    pub photons: PhotonSettings,
    /// How textures are filtered: off (a point lookup, as always) unless
    /// asked for.
    pub texture_filter: TextureFilter,
    /// Worker threads; `None` uses every core. The picture is the same for
    /// any count.
    pub threads: Option<usize>,
    /// Whether a tile row's camera rays are walked eight at a time where
    /// the world allows it ([`crate::world::World::intersect_packet`]);
    /// the picture is the same either way, only the time differs.
    pub packets: bool,
    /// Whether rays take the fast paths: camera-ray packets (as
    /// `packets`) and the culling of camera rays that miss the world's
    /// image, the shadow cache, shadow rays through clear surfaces answered
    /// by one classifying walk and their crossings, and rays inside glass
    /// spheres tested against what reaches in. The picture and the ray
    /// counts are the same either way; off, every ray takes the plain
    /// closest-hit or any-hit query: the reference the tests compare
    /// against.
    pub fast_paths: bool,
    /// Per-pixel data to produce alongside the colour.
    pub aovs: Vec<Aov>,
}

impl RenderSettings {
    /// Refuses settings a render cannot honour: see [`check_image_size`],
    /// samples from 1 to [`MAX_SAMPLES`], a depth of at most [`MAX_DEPTH`].
    pub fn check(&self) -> Result<(), RenderError> {
        check_image_size(self.width, self.height)?;
        if self.samples_per_pixel == 0 {
            return Err(RenderError::NoSamples);
        }
        if self.samples_per_pixel > MAX_SAMPLES {
            return Err(RenderError::TooManySamples(self.samples_per_pixel));
        }
        if self.max_depth > MAX_DEPTH {
            return Err(RenderError::DepthTooLarge(self.max_depth));
        }
        self.photons.check()?;
        self.aa.check()?;
        Ok(())
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: 1,
            aa: AntiAliasing::Stratified,
            max_depth: 8,
            min_weight: 1e-3,
            accel: AccelKind::default(),
            accel_top: None,
            accel_bottom: None,
            integrator: IntegratorKind::default(),
            photons: PhotonSettings::default(),
            texture_filter: TextureFilter::None,
            threads: None,
            packets: true,
            fast_paths: true,
            aovs: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_pass_their_own_check() {
        assert!(RenderSettings::default().check().is_ok());
    }

    #[test]
    fn sizes_samples_and_depths_beyond_the_limits_are_refused() {
        assert!(check_image_size(1, 1).is_ok());
        assert!(check_image_size(MAX_SIDE, 4096).is_ok());
        for (width, height) in [(0, 1), (1, 0), (MAX_SIDE + 1, 1), (1, u32::MAX)] {
            assert!(
                matches!(
                    check_image_size(width, height),
                    Err(RenderError::BadSize { .. })
                ),
                "{width}x{height}"
            );
        }
        assert!(matches!(
            check_image_size(MAX_SIDE, MAX_SIDE),
            Err(RenderError::TooManyPixels { .. })
        ));
        let with = |samples_per_pixel, max_depth| RenderSettings {
            samples_per_pixel,
            max_depth,
            ..RenderSettings::default()
        };
        assert!(with(MAX_SAMPLES, MAX_DEPTH).check().is_ok());
        assert!(matches!(with(0, 1).check(), Err(RenderError::NoSamples)));
        assert!(matches!(
            with(MAX_SAMPLES + 1, 1).check(),
            Err(RenderError::TooManySamples(65537))
        ));
        assert!(matches!(
            with(1, MAX_DEPTH + 1).check(),
            Err(RenderError::DepthTooLarge(1001))
        ));
    }
}
