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

pub use scene_rays::{MAX_RAY_PIXELS, scene_ray_sets};
pub use timing::{TraceResults, time_set, trace_all};

use crate::accel::RayCoherence;
use crate::math::Ray;

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
