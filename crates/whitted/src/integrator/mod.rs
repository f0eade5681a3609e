//! Integrators: what colour arrives along a camera ray. The renderer calls
//! one through the closed enum [`Integrator`], so a new algorithm (photon
//! mapping, a reference path tracer) is one more variant beside
//! [`Whitted`], dispatched by `match`.
//!
//! An integrator traces in a prepared [`World`] and shades with what the
//! scene says of light and surfaces ([`Shading`]). It counts the rays it
//! traces by kind ([`RayCounts`]); [`Integrator::ray_kinds`] says which
//! kinds it can trace.

mod observer;
pub mod photon_map;
mod ray_counts;
mod ray_tree;
mod shadow_cache;
mod visibility;
mod whitted;

pub use observer::{Cancellable, FirstHit, RayObserver, ShadowStep, Unobserved};
pub use photon_map::{CausticMap, PhotonSettings};
pub use ray_counts::{RayCounts, RayKind};
pub use ray_tree::{
    DEFAULT_MAX_TREE_RAYS, HitNode, LightTerm, LightVerdict, RayNode, RayTreeRecorder,
    ShadingTerms, ShadowSegment, Stop,
};
pub use whitted::Whitted;

use crate::accel::{QueryContext, TraversalCounters};
use crate::math::Ray;
use crate::shading::{Color, Light, Material, RayDifferential};
use crate::world::{Hit, MaterialId, Surface, World};

/// The most secondary rays (reflected and refracted) one camera sample
/// traces. A material that both reflects and refracts strongly doubles the
/// ray tree at each bounce, and its weights need not decay below
/// `min_weight` (a glass ball with `reflection = 1, transmission = 1` in a
/// mirror box): past this many rays the sample's remaining branches stop
/// with their surfaces' own light. A full binary tree of depth 11 (4094
/// rays) fits, so a normal scene never meets it. The tree is walked in a
/// fixed order, so where it is cut does not depend on the threads.
pub const SECONDARY_RAY_BUDGET: u32 = 4096;

/// What the scene says of light and surfaces, borrowed for shading.
#[derive(Clone, Copy, Debug)]
pub struct Shading<'a> {
    /// Materials, indexed by [`crate::world::MaterialId`].
    pub materials: &'a [Material],
    /// Light sources.
    pub lights: &'a [Light],
    /// Colour of rays that hit nothing.
    pub background: Color,
    /// Global ambient light `Ia`.
    pub ambient: Color,
}

/// How deep an integrator's recursion may go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecursionLimits {
    /// Deepest reflection/refraction recursion; 0 traces primary rays only.
    pub max_depth: u32,
    /// A branch whose weight on the pixel falls below this stops early
    /// (adaptive depth control, Hall and Greenberg 1983).
    pub min_weight: f64,
    /// The most secondary rays one camera sample traces (normally
    /// [`SECONDARY_RAY_BUDGET`]).
    pub ray_budget: u32,
}

/// Which integrator to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum IntegratorKind {
    /// Whitted's recursive ray tracing ([`Whitted`]).
    #[default]
    Whitted,
}

/// The result of tracing one camera ray. Small, so that returning it
/// copies a few words: the first hit, which the per-pixel data needs, is
/// kept by a [`FirstHit`] observer when asked for, not copied out of
/// every sample (see docs/performance-log.md, the `FirstHit` observer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimarySample {
    /// The colour seen.
    pub color: Color,
    /// Where the ray budget cut this sample's tree short, if it did: the
    /// material whose rays were refused (one that both reflects and
    /// refracts, where one did).
    pub cut_at: Option<MaterialId>,
}

/// An integrator ready to trace: the closed set of algorithms.
#[derive(Debug)]
pub enum Integrator<'a> {
    /// Whitted's recursive ray tracing.
    Whitted(Whitted<'a>),
}

impl<'a> Integrator<'a> {
    /// Prepares an integrator of `kind` over `world`, shading with
    /// `shading`, within `limits`.
    pub fn new(
        kind: IntegratorKind,
        world: &'a World<'a>,
        shading: Shading<'a>,
        limits: RecursionLimits,
    ) -> Self {
        match kind {
            IntegratorKind::Whitted => Integrator::Whitted(Whitted::new(world, shading, limits)),
        }
    }

    /// Adds the caustic map's light at every diffuse point it shades, if
    /// there is a map (see [`photon_map`]).
    pub fn with_caustics(self, caustics: Option<&'a CausticMap>) -> Self {
        match self {
            Integrator::Whitted(w) => Integrator::Whitted(w.with_caustics(caustics)),
        }
    }

    /// Takes the fast paths or, with `fast` false, the plain closest-hit
    /// and any-hit queries for every ray: the same picture, the reference
    /// the fast paths are checked against ([`Whitted::with_fast_paths`]).
    pub fn with_fast_paths(self, fast: bool) -> Self {
        match self {
            Integrator::Whitted(w) => Integrator::Whitted(w.with_fast_paths(fast)),
        }
    }

    /// The world it traces in.
    pub fn world(&self) -> &'a World<'a> {
        match self {
            Integrator::Whitted(w) => w.world(),
        }
    }

    /// The kinds of rays it traces, in report order.
    pub fn ray_kinds(&self) -> &'static [RayKind] {
        match self {
            Integrator::Whitted(_) => Whitted::RAY_KINDS,
        }
    }

    /// The colour seen along a camera ray (unit direction); the rays
    /// traced are added to `counts`.
    #[inline]
    pub fn trace_primary(&self, ray: &Ray, counts: &mut RayCounts) -> PrimarySample {
        match self {
            Integrator::Whitted(w) => w.trace_primary(ray, counts),
        }
    }

    /// [`Integrator::trace_primary`] with the camera ray's differential,
    /// if textures are filtered (see [`crate::shading::differential`]).
    #[inline]
    pub fn trace_camera_ray(
        &self,
        ray: &Ray,
        differential: Option<RayDifferential>,
        counts: &mut RayCounts,
    ) -> PrimarySample {
        match self {
            Integrator::Whitted(w) => {
                w.trace_primary_observed(ray, differential, counts, &mut Unobserved)
            }
        }
    }

    /// [`Integrator::trace_camera_ray`], telling `observer` every step
    /// (see [`RayObserver`]).
    pub fn trace_primary_observed<O: RayObserver>(
        &self,
        ray: &Ray,
        differential: Option<RayDifferential>,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> PrimarySample {
        match self {
            Integrator::Whitted(w) => w.trace_primary_observed(ray, differential, counts, observer),
        }
    }

    /// [`Integrator::trace_primary_observed`] for a camera ray whose
    /// closest hit `hit` is already found (by
    /// [`World::intersect_packet`](crate::world::World::intersect_packet)).
    #[inline]
    pub fn shade_camera_hit<O: RayObserver>(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        differential: Option<RayDifferential>,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> PrimarySample {
        match self {
            Integrator::Whitted(w) => w.shade_camera_hit(ray, hit, differential, counts, observer),
        }
    }

    /// What [`Integrator::shade_camera_hit`] gives an unobserved camera
    /// ray that hits nothing (the renderer's rows off the world's image).
    #[inline]
    pub fn camera_miss(&self, counts: &mut RayCounts) -> PrimarySample {
        match self {
            Integrator::Whitted(w) => w.camera_miss(counts),
        }
    }

    /// The first hit along a ray and its surface, without shading.
    pub fn first_hit(&self, ray: &Ray) -> Option<(Hit, Surface)> {
        let world = self.world();
        let hit = world.intersect(ray)?;
        Some((hit, world.surface(ray, &hit)))
    }

    /// The traversal work of the closest-hit query for `ray`.
    pub fn traversal_cost(&self, ray: &Ray) -> TraversalCounters {
        let mut ctx = QueryContext::default();
        self.world().intersect_with(ray, &mut ctx);
        ctx.counters
    }
}
