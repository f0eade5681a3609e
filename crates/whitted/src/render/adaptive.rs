//! Adaptive anti-aliasing: Whitted's subdivision of the pixel, as
//! POV-Ray's `+AM2` does it.
//!
//! A camera ray is traced through each corner of the pixel. Where the four
//! corners of a square differ by more than the threshold, the square is cut
//! into four and the new corners traced, down to squares
//! `1 / 2^depth` of a pixel wide (and, beyond POV-Ray, down to
//! `1 / 2^min_depth` whatever the corners). The pixel's colour is the area average of
//! its squares, each the mean of its four corners.
//!
//! Corners lie on a fine grid (`2^depth` steps per pixel) and are cached by
//! their integer position within a tile, so a corner shared by neighbouring
//! pixels or squares is traced once per tile. A corner's colour is a
//! function of its position alone, and each pixel's subdivision depends on
//! its own corners only, so a pixel is the same whatever tile, thread or
//! selection (`--tile`, `--crop`) renders it.
//!
//! Two colours differ by the sum over red, green and blue of the difference
//! of their 8-bit codes as the PNG writer would encode them (through the
//! sRGB curve for linear scenes), divided by 255: POV-Ray's measure (the sum
//! of the channel differences) on what the picture shows.

use std::collections::HashMap;
use std::fmt;

use rustc_hash::FxHashMap;

use crate::image::ColorSpace;
use crate::integrator::{Integrator, RayCounts};
use crate::math::DVec2;
use crate::shading::Color;
use crate::world::MaterialId;

use super::sample_ray::{position_differential, position_ray};
use super::{Camera, RenderSettings};

/// The deepest subdivision accepted: squares 1/64 of a pixel wide, at most
/// 65² = 4225 camera rays in a pixel.
pub const MAX_AA_DEPTH: u32 = 6;

/// POV-Ray's default threshold (`Antialias_Threshold`).
pub const DEFAULT_AA_THRESHOLD: f64 = 0.3;

/// POV-Ray's default depth (`Antialias_Depth`): squares 1/8 of a pixel wide.
pub const DEFAULT_AA_DEPTH: u32 = 3;

/// How the camera samples each pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AntiAliasing {
    /// `samples_per_pixel` samples on a stratified pattern seeded by the
    /// pixel's position (one sample is the pixel centre).
    #[default]
    Stratified,
    /// Corners of the pixel, subdivided where they differ.
    Adaptive(Adaptive),
}

/// The parameters of adaptive subdivision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// A square is cut when two of its corners differ by more than this
    /// (the sum of the three channels' differences, each in [0, 1] of the
    /// displayed value).
    pub threshold: f64,
    /// The most times a pixel is halved along each side.
    pub depth: u32,
    /// The times a pixel is halved whatever its corners (0, POV-Ray's
    /// way, looks at the pixel corners first): a feature smaller than the
    /// pixel that no corner sees is found by the finer first grid.
    pub min_depth: u32,
}

impl Default for Adaptive {
    fn default() -> Self {
        Self {
            threshold: DEFAULT_AA_THRESHOLD,
            depth: DEFAULT_AA_DEPTH,
            min_depth: 0,
        }
    }
}

/// Adaptive settings a render refuses.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum AdaptiveError {
    /// A negative, infinite or NaN threshold.
    #[error("the anti-aliasing threshold {0} is not valid: expected a number, at least 0")]
    Threshold(f64),
    /// A depth beyond [`MAX_AA_DEPTH`].
    #[error(
        "the anti-aliasing depth {0} is too large: at most {MAX_AA_DEPTH} is allowed (squares \
         1/64 of a pixel wide)"
    )]
    Depth(u32),
    /// A minimum depth beyond the depth.
    #[error("the anti-aliasing minimum depth {min_depth} is more than the depth {depth}")]
    MinDepth {
        /// The minimum depth.
        min_depth: u32,
        /// The depth.
        depth: u32,
    },
}

impl AntiAliasing {
    /// The names used in scene files and on the command line.
    pub const NAMES: [&'static str; 2] = ["stratified", "adaptive"];

    /// The method called `name`, adaptive with POV-Ray's defaults.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "stratified" => Some(Self::Stratified),
            "adaptive" => Some(Self::Adaptive(Adaptive::default())),
            _ => None,
        }
    }

    /// The name used in scene files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Stratified => Self::NAMES[0],
            Self::Adaptive(_) => Self::NAMES[1],
        }
    }

    /// Refuses adaptive parameters out of range.
    pub fn check(&self) -> Result<(), AdaptiveError> {
        match *self {
            Self::Stratified => Ok(()),
            Self::Adaptive(a) => a.check(),
        }
    }
}

impl Adaptive {
    /// Refuses a threshold that is not a number of at least 0, a depth
    /// beyond [`MAX_AA_DEPTH`] or a minimum depth beyond the depth.
    pub fn check(&self) -> Result<(), AdaptiveError> {
        if !(self.threshold.is_finite() && self.threshold >= 0.0) {
            return Err(AdaptiveError::Threshold(self.threshold));
        }
        if self.depth > MAX_AA_DEPTH {
            return Err(AdaptiveError::Depth(self.depth));
        }
        if self.min_depth > self.depth {
            return Err(AdaptiveError::MinDepth {
                min_depth: self.min_depth,
                depth: self.depth,
            });
        }
        Ok(())
    }
}

impl fmt::Display for Adaptive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "adaptive anti-aliasing (threshold {}, ", self.threshold)?;
        match self.min_depth {
            0 => write!(f, "depth {})", self.depth),
            min => write!(f, "depth {min} to {})", self.depth),
        }
    }
}

/// A traced corner: its colour and the 8-bit codes the picture shows.
#[derive(Clone, Copy)]
struct Corner {
    color: Color,
    codes: [u8; 3],
}

/// The pixels of one tile, sampled adaptively, with the corners traced so
/// far.
pub(super) struct AdaptivePixels<'a> {
    integrator: &'a Integrator<'a>,
    camera: &'a Camera,
    settings: &'a RenderSettings,
    color_space: ColorSpace,
    adaptive: Adaptive,
    /// Traced corners by their position on the fine grid of the image
    /// (`2^depth` steps per pixel). Fx hashing, cheaper than SipHash (see
    /// docs/performance-log.md, "The corner cache's hashing"): these keys
    /// need no protection from collisions chosen by an attacker.
    corners: FxHashMap<(u32, u32), Corner>,
}

/// What tracing corners cost: rays by kind, and the samples the ray budget
/// cut short by the material they were cut at.
pub(super) struct Cost<'t> {
    /// Rays traced.
    pub rays: &'t mut RayCounts,
    /// Samples cut short.
    pub cuts: &'t mut HashMap<MaterialId, u64>,
}

impl<'a> AdaptivePixels<'a> {
    /// An empty cache for the image `settings` describe.
    pub(super) fn new(
        integrator: &'a Integrator<'a>,
        camera: &'a Camera,
        settings: &'a RenderSettings,
        color_space: ColorSpace,
        adaptive: Adaptive,
    ) -> Self {
        Self {
            integrator,
            camera,
            settings,
            color_space,
            adaptive,
            corners: FxHashMap::default(),
        }
    }

    /// The colour of pixel (`x`, `y`).
    pub(super) fn pixel(&mut self, x: u32, y: u32, cost: &mut Cost<'_>) -> Color {
        let side = 1 << self.adaptive.depth;
        self.square(x * side, y * side, side, cost)
    }

    /// The colour of pixel (`x`, `y`), as [`Self::pixel`] gives it, and
    /// the corners its subdivision traced, in reading order on the fine
    /// grid (row by row, top to bottom), each with its position on the
    /// image in pixels and its colour: what `whitted explain` shows. Takes
    /// an empty cache, so the corners are this pixel's alone.
    pub(super) fn pixel_alone(
        mut self,
        x: u32,
        y: u32,
        cost: &mut Cost<'_>,
    ) -> (Color, Vec<(DVec2, Color)>) {
        debug_assert!(
            self.corners.is_empty(),
            "the cache holds other pixels' corners"
        );
        let color = self.pixel(x, y, cost);
        let scale = f64::from(1u32 << self.adaptive.depth);
        let mut corners: Vec<_> = self.corners.into_iter().collect();
        corners.sort_unstable_by_key(|&((fx, fy), _)| (fy, fx));
        let corners = corners
            .into_iter()
            .map(|((fx, fy), corner)| {
                let position = DVec2::new(f64::from(fx) / scale, f64::from(fy) / scale);
                (position, corner.color)
            })
            .collect();
        (color, corners)
    }

    /// The mean colour over the square of `side` fine steps whose top-left
    /// corner is (`fx`, `fy`) on the fine grid.
    fn square(&mut self, fx: u32, fy: u32, side: u32, cost: &mut Cost<'_>) -> Color {
        let c = [
            self.corner(fx, fy, cost),
            self.corner(fx + side, fy, cost),
            self.corner(fx, fy + side, cost),
            self.corner(fx + side, fy + side, cost),
        ];
        let forced = side > 1 << (self.adaptive.depth - self.adaptive.min_depth);
        if side == 1 || !(forced || self.differ(&c)) {
            return (c[0].color + c[1].color + c[2].color + c[3].color) * 0.25;
        }
        let half = side / 2;
        let quarters = [
            self.square(fx, fy, half, cost),
            self.square(fx + half, fy, half, cost),
            self.square(fx, fy + half, half, cost),
            self.square(fx + half, fy + half, half, cost),
        ];
        (quarters[0] + quarters[1] + quarters[2] + quarters[3]) * 0.25
    }

    /// Whether two of the corners differ by more than the threshold.
    fn differ(&self, corners: &[Corner; 4]) -> bool {
        let limit = self.adaptive.threshold * 255.0;
        (0..4).any(|i| {
            (i + 1..4).any(|j| f64::from(code_distance(corners[i].codes, corners[j].codes)) > limit)
        })
    }

    /// The corner at (`fx`, `fy`) on the fine grid, traced once.
    fn corner(&mut self, fx: u32, fy: u32, cost: &mut Cost<'_>) -> Corner {
        if let Some(&corner) = self.corners.get(&(fx, fy)) {
            return corner;
        }
        let scale = f64::from(1u32 << self.adaptive.depth);
        let position = DVec2::new(f64::from(fx) / scale, f64::from(fy) / scale);
        let ray = position_ray(self.camera, self.settings, position);
        let differential = position_differential(self.camera, self.settings, position, 1.0);
        let sample = self
            .integrator
            .trace_camera_ray(&ray, differential, cost.rays);
        if let Some(material) = sample.cut_at {
            *cost.cuts.entry(material).or_default() += 1;
        }
        let rgb = sample.color.to_f32();
        let corner = Corner {
            color: sample.color,
            codes: rgb.map(|v| self.color_space.encode8(v)),
        };
        self.corners.insert((fx, fy), corner);
        corner
    }
}

/// The sum over the channels of the differences of two colours' codes.
fn code_distance(a: [u8; 3], b: [u8; 3]) -> u32 {
    a.iter()
        .zip(&b)
        .map(|(&p, &q)| u32::from(p.abs_diff(q)))
        .sum()
}

#[cfg(test)]
mod tests;
