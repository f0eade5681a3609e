//! The camera ray of one sample of one pixel: where the renderer and
//! `whitted explain` agree on which ray a sample is.

use crate::math::Ray;
use crate::math::random::hash64;
use crate::math::sampling::pixel_sample;
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
    let offset = pixel_sample(s, settings.samples_per_pixel, pattern);
    camera.ray(
        settings.width,
        settings.height,
        f64::from(x) + offset.x,
        f64::from(y) + offset.y,
    )
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
    if settings.texture_filter == TextureFilter::None {
        return None;
    }
    let spp = settings.samples_per_pixel;
    let offset = pixel_sample(s, spp, pattern);
    let differential = camera.ray_differential(
        settings.width,
        settings.height,
        f64::from(x) + offset.x,
        f64::from(y) + offset.y,
    );
    Some(differential.scaled(1.0 / f64::from(spp).sqrt()))
}
