//! Measuring acceleration structures: the same rays traced through each
//! structure, timed on one thread and on all, with the work per ray
//! counted. `whitted bench` prints what this module measures.
//!
//! Three kinds of rays, as in the Embree anchor harness: primary rays
//! through every pixel centre (coherent), one shadow ray per primary hit
//! towards a light (any-hit), and one cosine-distributed diffuse bounce per
//! primary hit (incoherent).

pub mod obj_positions;
pub mod ray_files;
mod scene_rays;
mod timing;

pub use scene_rays::scene_ray_sets;
pub use timing::{TraceResults, Walk, time_set, trace_all};

use crate::accel::RayCoherence;
use crate::limits::{MemoryBudget, MemoryError};
use crate::math::Ray;

/// Bytes `rays` rays of one set take while measured: the rays, and the
/// results of one structure and of the reference.
pub fn ray_set_bytes(rays: u64) -> u64 {
    let per_ray = std::mem::size_of::<Ray>() + 2 * std::mem::size_of::<Option<(f64, u32)>>();
    rays.saturating_mul(per_ray as u64)
}

/// Refuses, before any ray is made, a bench image of `width` × `height`
/// whose three ray sets (one ray per pixel each, at most) would exceed the
/// memory budget.
pub fn check_bench_size(width: u32, height: u32) -> Result<(), MemoryError> {
    let pixels = u64::from(width) * u64::from(height);
    MemoryBudget::current().check(
        &format!("benchmarking a {width}x{height} image (3 sets of up to {pixels} rays)"),
        ray_set_bytes(pixels).saturating_mul(3),
        "use a smaller --width and --height",
    )
}

/// The kinds of rays measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayKind {
    /// Camera rays through pixel centres: closest hit.
    Primary,
    /// Rays from primary hits towards a light: any hit.
    Shadow,
    /// Cosine-distributed bounces from primary hits: closest hit.
    Diffuse,
}

impl RayKind {
    /// Every kind, in report order.
    pub const ALL: [RayKind; 3] = [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse];

    /// The name used in reports and in ray file names.
    pub fn name(&self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Shadow => "shadow",
            RayKind::Diffuse => "diffuse",
        }
    }

    /// True for kinds that ask for any hit rather than the closest.
    pub fn is_any_hit(&self) -> bool {
        matches!(self, RayKind::Shadow)
    }

    /// How the directions of one ray and the next relate: camera rays
    /// through neighbouring pixels and shadow rays from neighbouring hits
    /// towards one light go about the same way, diffuse bounces every way.
    pub fn coherence(&self) -> RayCoherence {
        match self {
            RayKind::Primary | RayKind::Shadow => RayCoherence::Coherent,
            RayKind::Diffuse => RayCoherence::Incoherent,
        }
    }
}

/// A set of rays of one kind.
#[derive(Clone, Debug, PartialEq)]
pub struct RaySet {
    /// What the rays are for.
    pub kind: RayKind,
    /// The rays.
    pub rays: Vec<Ray>,
}
