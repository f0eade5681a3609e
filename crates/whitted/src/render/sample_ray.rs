//! The camera ray of one sample of one pixel: where the renderer and
//! `whitted explain` agree on which ray a sample is.

use crate::math::random::hash64;
use crate::math::sampling::pixel_sample;
use crate::math::{DVec2, Ray};
use crate::render::{Camera, RenderSettings};
use crate::shading::{RayDifferential, TextureFilter};

/// The seed of pixel (`x`, `y`)'s sample pattern: a hash of its position,
/// so the picture does not depend on the order pixels are rendered in.
#[inline]
pub(crate) fn pixel_pattern(x: u32, y: u32) -> u32 {
    hash64(u64::from(y) << 32 | u64::from(x)) as u32
}

/// The camera ray of sample `s` of pixel (`x`, `y`) whose pattern is
/// `pattern` ([`pixel_pattern`]).
#[inline]
pub(crate) fn sample_ray(
    camera: &Camera,
    settings: &RenderSettings,
    (x, y): (u32, u32),
    pattern: u32,
    s: u32,
) -> Ray {
    position_ray(
        camera,
        settings,
        sample_position(settings, (x, y), pattern, s),
    )
}

/// Where on the image (in pixels from its top-left corner) sample `s` of
/// pixel (`x`, `y`) whose pattern is `pattern` lies.
#[inline]
pub(crate) fn sample_position(
    settings: &RenderSettings,
    (x, y): (u32, u32),
    pattern: u32,
    s: u32,
) -> DVec2 {
    let offset = pixel_sample(s, settings.samples_per_pixel, pattern);
    DVec2::new(f64::from(x) + offset.x, f64::from(y) + offset.y)
}

/// The camera ray through `position` on the image, in pixels from its
/// top-left corner.
#[inline]
pub(crate) fn position_ray(camera: &Camera, settings: &RenderSettings, position: DVec2) -> Ray {
    camera.ray(settings.width, settings.height, position.x, position.y)
}

/// The ray differential of sample `s` of pixel (`x`, `y`) (see
/// [`sample_ray`]) when the settings filter textures, else `None`: one
/// pixel's step, scaled by `1/√spp` for several samples per pixel (the
/// spacing of their grid).
#[inline]
pub(crate) fn sample_differential(
    camera: &Camera,
    settings: &RenderSettings,
    (x, y): (u32, u32),
    pattern: u32,
    s: u32,
) -> Option<RayDifferential> {
    let position = sample_position(settings, (x, y), pattern, s);
    position_differential(camera, settings, position, differential_step(settings))
}

/// The scale of a sample's differential: `1/√spp`, the spacing of the
/// samples' grid in pixels.
#[inline]
pub(crate) fn differential_step(settings: &RenderSettings) -> f64 {
    1.0 / f64::from(settings.samples_per_pixel).sqrt()
}

/// The ray differential of the camera ray through `position` on the image
/// (in pixels) when the settings filter textures, else `None`: one pixel's
/// step times `scale`. Adaptive anti-aliasing gives its corners a whole
/// pixel's step: a corner stands for the pixel around it, however finely
/// the pixel is later subdivided.
#[inline]
pub(crate) fn position_differential(
    camera: &Camera,
    settings: &RenderSettings,
    position: DVec2,
    scale: f64,
) -> Option<RayDifferential> {
    if settings.texture_filter == TextureFilter::None {
        return None;
    }
    let differential =
        camera.ray_differential(settings.width, settings.height, position.x, position.y);
    Some(differential.scaled(scale))
}
