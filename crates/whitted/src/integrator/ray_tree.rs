//! The ray tree of one camera sample, as the Whitted integrator traced it:
//! [`RayNode`]s for the camera, reflected and refracted rays, each with
//! what it hit, the terms of the shading formula, every light's shadow
//! rays and verdict, the branches left out and why, and the colour it
//! passes up. [`RayTreeRecorder`] builds it as a [`RayObserver`]; the
//! colour of the root is the colour the integrator returned, the very
//! same bits.
//!
//! A tree is bounded: it records at most a given number of rays and light
//! verdicts ([`DEFAULT_MAX_TREE_RAYS`] unless told otherwise), the first
//! ones traced, depth first. What is traced past that still counts in
//! the colours, but is left out of the tree: the hit where it would have
//! gone says so with [`Stop::TreeLimit`] and how many were left out.
//!
//! The shading terms are recomputed from the observed values with the
//! shading layer's own functions ([`phong`], the material's textures), so
//! they are what the integrator added up; they are shown one by one, and
//! their sum may differ from the node's colour in the last bits.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::accel::{QueryContext, TraversalCounters};
use crate::integrator::observer::{RayObserver, ShadowStep};
use crate::integrator::{RayKind, RecursionLimits, Shading};
use crate::math::{DVec2, Ray, Vec3};
use crate::shading::{Color, LightSample, Material, phong};
use crate::world::{Hit, MaterialId, PrimitiveId, Surface, World};

/// One ray of the tree: a camera, reflected or refracted ray.
#[derive(Clone, Debug, PartialEq)]
pub struct RayNode {
    /// What it was traced for.
    pub kind: RayKind,
    /// Its depth: 0 for the camera ray, one more per bounce.
    pub depth: u32,
    /// Where it starts.
    pub origin: Vec3,
    /// Its unit direction.
    pub direction: Vec3,
    /// What the parent multiplies its colour by (`kr` or `kt` after
    /// opacity and Fresnel; one for the camera ray).
    pub coefficient: Color,
    /// The largest factor by which its colour reaches the pixel.
    pub weight: f64,
    /// The work of its closest-hit query in the acceleration structure.
    pub cost: TraversalCounters,
    /// What it hit; `None` when it left the scene (its colour is then the
    /// background).
    pub hit: Option<HitNode>,
    /// The colour it passes up, before the parent's coefficient.
    pub color: Color,
}

/// A ray's hit and how the surface there was shaded.
#[derive(Clone, Debug, PartialEq)]
pub struct HitNode {
    /// The primitive's number in the world.
    pub primitive: PrimitiveId,
    /// The ray parameter of the hit (the distance, the direction being
    /// unit).
    pub t: f64,
    /// The hit point.
    pub point: Vec3,
    /// The geometric normal, outward.
    pub geometric_normal: Vec3,
    /// The shading normal used, turned towards the viewer (interpolated,
    /// bumped).
    pub shading_normal: Vec3,
    /// True when the ray arrived on the outward side (entering the
    /// object's medium, for a transmissive one), false when leaving it.
    pub entering: bool,
    /// The texture coordinates there.
    pub uv: DVec2,
    /// The surface's material.
    pub material: MaterialId,
    /// The terms of the shading formula.
    pub terms: ShadingTerms,
    /// Each light's verdict, in the scene's order; empty when the material
    /// has neither diffuse nor specular reflection (or is fully
    /// dissolved), so no light was looked at.
    pub lights: Vec<LightTerm>,
    /// The indices of refraction on the incoming and the far side, when
    /// secondary rays were considered.
    pub indices: Option<[f64; 2]>,
    /// The secondary rays traced, in order (reflected, then refracted).
    pub children: Vec<RayNode>,
    /// Why the tree has no more rays here, where it could have had some.
    pub stops: Vec<Stop>,
}

/// The terms of the Phong-Whitted formula at a hit, each already
/// multiplied by what scales it (except the opacity, applied to their sum).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingTerms {
    /// `ke`: the surface's own light.
    pub emission: Color,
    /// `ka Ia`: the ambient term.
    pub ambient: Color,
    /// `α`: the opacity that weighs the local terms and the mirror.
    pub opacity: Color,
    /// `kd E`: the caustic map's irradiance `E` at the point (zero
    /// without a caustic map).
    pub caustic: Color,
}

/// One light's contribution at a hit.
#[derive(Clone, Debug, PartialEq)]
pub struct LightTerm {
    /// The light's index in the scene.
    pub index: usize,
    /// Whether its light arrives.
    pub verdict: LightVerdict,
    /// Its diffuse term `S I kd (N·L)`.
    pub diffuse: Color,
    /// Its specular term `S I ks (R·V)^n`.
    pub specular: Color,
    /// The steps of its shadow ray, in order (several when it passes
    /// through transmissive surfaces).
    pub shadow_rays: Vec<ShadowSegment>,
}

/// Whether a light's light arrives at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightVerdict {
    /// None of its light reaches the point (outside a spot's cone).
    Unreached,
    /// The surface faces away from it: no shadow ray.
    FacesAway,
    /// Nothing is in the way.
    Lit,
    /// An opaque surface is in the way: the nearest one on the shadow ray.
    Blocked {
        /// The blocking primitive.
        by: Option<PrimitiveId>,
    },
    /// Transmissive or dissolved surfaces let this much through.
    Attenuated {
        /// The factor on the light's intensity.
        transmittance: Color,
    },
}

/// One step of a shadow ray: a segment towards the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSegment {
    /// Where it starts.
    pub origin: Vec3,
    /// Its unit direction (towards the light).
    pub direction: Vec3,
    /// Its length (infinite towards a directional light).
    pub t_max: f64,
    /// What it met first, and where (`None`: nothing, the light is seen).
    pub blocker: Option<(PrimitiveId, f64)>,
    /// The work of its query (any hit or closest hit, as the integrator
    /// asked it) in the acceleration structure.
    pub cost: TraversalCounters,
}

/// Why a node has no more rays where its material could have had some.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// The ray is at the deepest recursion allowed (`max_depth`).
    DepthLimit {
        /// The limit.
        max_depth: u32,
    },
    /// The material neither reflects nor transmits, and is opaque.
    Opaque,
    /// Total internal reflection: no refracted ray, its weight moved to
    /// the reflected one.
    TotalInternalReflection,
    /// A secondary ray whose weight on the pixel was under `min_weight`.
    WeightCutOff {
        /// The ray left out.
        kind: RayKind,
        /// Its weight on the pixel.
        weight: f64,
        /// The cut-off.
        min_weight: f64,
    },
    /// A secondary ray refused because the camera sample had traced its
    /// budget of secondary rays.
    RayBudget {
        /// The ray left out.
        kind: RayKind,
        /// The budget.
        budget: u32,
    },
    /// The tree had recorded as many rays and light verdicts as it may:
    /// these, traced from this hit (with their own rays, shadow rays and
    /// verdicts), are in the colours but not in the tree.
    TreeLimit {
        /// How many were left out here.
        left_out: u64,
        /// The tree's limit.
        max_rays: u64,
    },
}

/// How many rays and light verdicts a tree records unless told otherwise:
/// a tree of this size takes a few MB, its JSON some more.
pub const DEFAULT_MAX_TREE_RAYS: u64 = 20_000;

/// Builds the [`RayNode`] tree of one camera sample while the integrator
/// traces it; [`RayTreeRecorder::finish`] returns it.
#[derive(Debug)]
pub struct RayTreeRecorder<'a> {
    world: &'a World<'a>,
    shading: Shading<'a>,
    limits: RecursionLimits,
    /// The rays started and not yet ended, outermost first.
    open: Vec<RayNode>,
    /// The shadow steps of the light being considered.
    shadow: Vec<ShadowSegment>,
    /// The camera ray once it has ended.
    root: Option<RayNode>,
    /// How many rays and light verdicts the tree may hold (at least 1).
    max_rays: u64,
    /// How many it holds.
    recorded: u64,
    /// How many it left out.
    left_out: u64,
    /// The rays started and not yet ended that are left out, within the
    /// innermost recorded one.
    skipping: u32,
    /// Whether the verdict of the light being considered has its place
    /// counted already (taken with its first shadow ray, so that no
    /// shadow ray is held without its verdict).
    verdict_taken: bool,
    /// Set when the tree is no longer wanted ([`RayObserver::stopped`]).
    cancel: Option<&'a AtomicBool>,
}

impl<'a> RayTreeRecorder<'a> {
    /// A recorder for a sample traced in `world` with `shading` and
    /// `limits` (those the integrator was given), that records at most
    /// `max_rays` rays and light verdicts (the camera ray always).
    pub fn new(
        world: &'a World<'a>,
        shading: Shading<'a>,
        limits: RecursionLimits,
        max_rays: u64,
    ) -> Self {
        Self {
            world,
            shading,
            limits,
            open: Vec::new(),
            shadow: Vec::new(),
            root: None,
            max_rays: max_rays.max(1),
            recorded: 0,
            left_out: 0,
            skipping: 0,
            verdict_taken: false,
            cancel: None,
        }
    }

    /// The recorder, stopping the sample once `cancel` is set.
    pub fn with_cancel(self, cancel: &'a AtomicBool) -> Self {
        Self {
            cancel: Some(cancel),
            ..self
        }
    }

    /// The tree, once the camera ray has ended, and how many rays and light
    /// verdicts were left out of it.
    pub fn finish(self) -> Option<(RayNode, u64)> {
        Some((self.root?, self.left_out))
    }

    /// Takes `count` more places in the tree if it has room for them and
    /// is not within a ray left out; else counts one ray or verdict as
    /// left out.
    fn take(&mut self, count: u64) -> bool {
        if self.skipping == 0 && self.max_rays - self.recorded >= count {
            self.recorded += count;
            return true;
        }
        self.left_out += 1;
        let max_rays = self.max_rays;
        // The innermost recorded ray is the one it comes from, whether it
        // is its own or that of a ray left out below it.
        if let Some(hit) = self.hit() {
            match hit.stops.iter_mut().find_map(|stop| match stop {
                Stop::TreeLimit { left_out, .. } => Some(left_out),
                _ => None,
            }) {
                Some(left_out) => *left_out += 1,
                None => hit.stops.push(Stop::TreeLimit {
                    left_out: 1,
                    max_rays,
                }),
            }
        }
        false
    }

    fn node(&mut self) -> Option<&mut RayNode> {
        self.open.last_mut()
    }

    fn hit(&mut self) -> Option<&mut HitNode> {
        self.open.last_mut()?.hit.as_mut()
    }

    fn material(&self, id: MaterialId) -> Option<&'a Material> {
        self.shading.materials.get(id.0 as usize)
    }
}

impl RayObserver for RayTreeRecorder<'_> {
    fn stopped(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }

    fn ray_start(&mut self, kind: RayKind, ray: &Ray, coefficient: Color, weight: f64) {
        if !self.take(1) {
            self.skipping += 1;
            return;
        }
        let depth = self.open.len() as u32;
        let mut ctx = QueryContext::default();
        self.world.intersect_with(ray, &mut ctx);
        self.open.push(RayNode {
            kind,
            depth,
            origin: ray.origin,
            direction: ray.dir,
            coefficient,
            weight,
            cost: ctx.counters,
            hit: None,
            color: Color::ZERO,
        });
    }

    fn ray_hit(&mut self, _ray: &Ray, hit: Option<(&Hit, &Surface)>) {
        let Some((hit, surface)) = hit else {
            return;
        };
        if self.skipping > 0 {
            return;
        }
        let terms = match self.material(surface.material) {
            Some(m) => ShadingTerms {
                emission: m.emission.at(surface.uv),
                ambient: m.ambient.at(surface.uv) * self.shading.ambient,
                opacity: m.opacity.at(surface.uv),
                caustic: Color::ZERO,
            },
            None => ShadingTerms {
                emission: Color::ZERO,
                ambient: Color::ZERO,
                opacity: Color::ONE,
                caustic: Color::ZERO,
            },
        };
        if let Some(node) = self.node() {
            node.hit = Some(HitNode {
                primitive: hit.primitive,
                t: hit.t(),
                point: surface.point,
                geometric_normal: surface.normal,
                shading_normal: surface.shading_normal,
                entering: true,
                uv: surface.uv,
                material: surface.material,
                terms,
                lights: Vec::new(),
                indices: None,
                children: Vec::new(),
                stops: Vec::new(),
            });
        }
    }

    fn shading(&mut self, normal: Vec3, entering: bool) {
        if self.skipping == 0
            && let Some(hit) = self.hit()
        {
            hit.shading_normal = normal;
            hit.entering = entering;
        }
    }

    fn shadow_ray(&mut self, ray: &Ray, step: ShadowStep<'_>) {
        // The first shadow ray of a light takes its verdict's place too.
        if !self.take(if self.verdict_taken { 1 } else { 2 }) {
            return;
        }
        self.verdict_taken = true;
        let mut ctx = QueryContext::default();
        let blocker = match step {
            ShadowStep::AnyHit { blocked } => {
                self.world.occluded_with(ray, &mut ctx);
                // The any-hit query stops at any occluder; name the nearest.
                blocked
                    .then(|| self.world.intersect(ray))
                    .flatten()
                    .map(|hit| (hit.primitive, hit.t()))
            }
            ShadowStep::Closest { blocker } => {
                self.world.intersect_with(ray, &mut ctx);
                blocker.map(|hit| (hit.primitive, hit.t()))
            }
        };
        self.shadow.push(ShadowSegment {
            origin: ray.origin,
            direction: ray.dir,
            t_max: ray.t_max,
            blocker,
            cost: ctx.counters,
        });
    }

    fn caustic(&mut self, term: Color) {
        if self.skipping == 0
            && let Some(hit) = self.hit()
        {
            hit.terms.caustic = term;
        }
    }

    fn light(&mut self, index: usize, sample: Option<&LightSample>, transmittance: Option<Color>) {
        let shadow_rays = std::mem::take(&mut self.shadow);
        if !(std::mem::take(&mut self.verdict_taken) || self.take(1)) {
            return;
        }
        let view = self.node().map_or(Vec3::ZERO, |node| -node.direction);
        let Some(hit) = self.hit() else {
            return;
        };
        let (n, uv, material) = (hit.shading_normal, hit.uv, hit.material);
        let mut term = LightTerm {
            index,
            verdict: LightVerdict::Unreached,
            diffuse: Color::ZERO,
            specular: Color::ZERO,
            shadow_rays,
        };
        match (sample, transmittance) {
            (None, _) => {}
            (Some(_), None) => term.verdict = LightVerdict::FacesAway,
            (Some(sample), Some(through)) => {
                term.verdict = if through == Color::ZERO {
                    LightVerdict::Blocked {
                        by: term
                            .shadow_rays
                            .iter()
                            .find_map(|s| s.blocker.map(|(p, _)| p)),
                    }
                } else if through == Color::ONE {
                    LightVerdict::Lit
                } else {
                    LightVerdict::Attenuated {
                        transmittance: through,
                    }
                };
                if through != Color::ZERO
                    && let Some(m) = self.material(material)
                {
                    let (kd, ks) = (m.diffuse.at(uv), m.specular.at(uv));
                    let scale = through * sample.intensity;
                    let l = sample.to_light;
                    term.diffuse = scale * phong(kd, Color::ZERO, m.shininess, n, l, view);
                    term.specular = scale * phong(Color::ZERO, ks, m.shininess, n, l, view);
                }
            }
        }
        if let Some(hit) = self.hit() {
            hit.lights.push(term);
        }
    }

    fn depth_limit(&mut self) {
        if self.skipping > 0 {
            return;
        }
        let max_depth = self.limits.max_depth;
        let Some(hit) = self.hit() else {
            return;
        };
        let (uv, material) = (hit.uv, hit.material);
        let branches = self.material(material).is_some_and(|m| {
            m.reflection.at(uv) != Color::ZERO
                || m.transmission.at(uv) != Color::ZERO
                || m.opacity.at(uv) != Color::ONE
        });
        if branches && let Some(hit) = self.hit() {
            hit.stops.push(Stop::DepthLimit { max_depth });
        }
    }

    fn lobes(&mut self, _mirror: Color, refraction: Color, refracted: bool, indices: [f64; 2]) {
        if self.skipping > 0 {
            return;
        }
        let Some(hit) = self.hit() else {
            return;
        };
        hit.indices = Some(indices);
        let (uv, material) = (hit.uv, hit.material);
        let transmits = self.material(material).is_some_and(|m| {
            m.transmission.at(uv) != Color::ZERO || m.opacity.at(uv) != Color::ONE
        });
        if transmits
            && !refracted
            && refraction == Color::ZERO
            && let Some(hit) = self.hit()
        {
            hit.stops.push(Stop::TotalInternalReflection);
        }
    }

    fn branch_skipped(&mut self, kind: RayKind, _coefficient: Color, weight: f64) {
        if self.skipping > 0 {
            return;
        }
        let limits = self.limits;
        let stop = if weight < limits.min_weight {
            Stop::WeightCutOff {
                kind,
                weight,
                min_weight: limits.min_weight,
            }
        } else {
            Stop::RayBudget {
                kind,
                budget: limits.ray_budget,
            }
        };
        if let Some(hit) = self.hit() {
            hit.stops.push(stop);
        }
    }

    fn ray_end(&mut self, color: Color) {
        if self.skipping > 0 {
            self.skipping -= 1;
            return;
        }
        let Some(mut node) = self.open.pop() else {
            return;
        };
        node.color = color;
        if let Some(hit) = &mut node.hit
            && hit.children.is_empty()
            && hit.stops.is_empty()
            && hit.indices.is_none()
        {
            hit.stops.push(Stop::Opaque);
        }
        match self.open.last_mut().and_then(|parent| parent.hit.as_mut()) {
            Some(parent) => parent.children.push(node),
            None => self.root = Some(node),
        }
    }
}
