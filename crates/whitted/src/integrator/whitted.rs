//! The recursive Whitted integrator.
//!
//! For the closest hit of a ray it sums emission, ambient, direct light from
//! every light (Phong diffuse and specular, each light seen through one
//! shadow ray), and the mirror-reflected and refracted rays, recursively.
//! See [`crate::shading::material`] for the formula and the Fresnel option.
//!
//! The direct light is [`crate::shading::phong`] and the weights of the
//! secondary rays are [`Lobes::new`]: the shading layer's own answers,
//! which photon mapping will share.
//!
//! - Shading is two-sided: the normal is turned to face the incoming ray.
//!   A material's bump or normal map tilts it (see
//!   [`crate::shading::bump`]); a light behind the geometric surface then
//!   lights nothing.
//! - Shadow rays pass through transmissive and dissolved surfaces, each
//!   crossing scaling the light by what that surface lets through
//!   (`α kt + 1 - α`); an opaque surface blocks it.
//! - Refraction follows Snell's law with the index of the medium the ray is
//!   in, tracked on a small stack of the media it has entered; total
//!   internal reflection moves the refracted weight onto the reflected ray.
//! - Recursion stops at `max_depth`, and earlier when a branch's weight on
//!   the pixel falls below `min_weight` (adaptive depth control), or when
//!   the camera sample has traced its budget of secondary rays
//!   ([`super::SECONDARY_RAY_BUDGET`]); the sample then says at which
//!   material it was cut.

use std::ops::ControlFlow::{Break, Continue};

use crate::integrator::observer::{RayObserver, ShadowStep, Unobserved};
use crate::integrator::photon_map::{self, CausticMap};
use crate::integrator::visibility::{SegmentStep, Visibility, shadow_segment};
use crate::integrator::{PrimarySample, RayCounts, RayKind, RecursionLimits, Shading};
use crate::math::{DVec2, Ray, RayOrigins, Vec3};
use crate::shading::differential::Bend;
use crate::shading::optics::reflect;
use crate::shading::{
    Color, Crossing, Light, Lobes, Material, MediumStack, RayDifferential, Weights, direct_samples,
    phong, shading_normal,
};
use crate::world::{Hit, MaterialId, PrimitiveId, Surface, World};

/// What one camera sample has traced so far: its rays by kind, the
/// secondary rays it may still trace, and where it was cut; and who
/// watches it.
struct SampleTally<'c, O> {
    counts: &'c mut RayCounts,
    observer: &'c mut O,
    rays_left: u32,
    /// The material at which a secondary ray was first refused, and
    /// whether that material branches (reflects and refracts); a branching
    /// one replaces one that does not.
    cut_at: Option<(MaterialId, bool)>,
}

impl<O> SampleTally<'_, O> {
    /// Takes one secondary ray from the budget, for a surface of
    /// `material` (which `branches` or not); false when none is left.
    fn take(&mut self, material: MaterialId, branches: bool) -> bool {
        if self.rays_left > 0 {
            self.rays_left -= 1;
            return true;
        }
        if !matches!(self.cut_at, Some((_, true))) && (self.cut_at.is_none() || branches) {
            self.cut_at = Some((material, branches));
        }
        false
    }
}

/// Whitted's recursive ray tracer over a prepared world.
#[derive(Debug)]
pub struct Whitted<'a> {
    world: &'a World<'a>,
    shading: Shading<'a>,
    limits: RecursionLimits,
    /// The questions every ray asks of the world.
    visibility: Visibility<'a>,
    caustics: Option<&'a CausticMap>,
}

impl<'a> Whitted<'a> {
    /// The kinds of rays it traces.
    pub const RAY_KINDS: &'static [RayKind] = &RayKind::ALL;

    /// Prepares to trace in `world`, shading with `shading`, within
    /// `limits`.
    pub fn new(world: &'a World<'a>, shading: Shading<'a>, limits: RecursionLimits) -> Self {
        let stops = stops_shadow_rays(shading.materials, None);
        Self {
            world,
            shading,
            limits,
            visibility: Visibility::new(world, shading.materials).with_stops(&stops),
            caustics: None,
        }
    }

    /// Takes the fast paths or, with `fast` false, the plain closest-hit
    /// and any-hit queries for every secondary and shadow ray: the same
    /// picture and ray counts, the reference the fast paths are checked
    /// against.
    pub fn with_fast_paths(self, fast: bool) -> Self {
        Self {
            visibility: self.visibility.with_fast_paths(fast),
            ..self
        }
    }

    /// Adds the caustic map's irradiance at every diffuse point it shades
    /// and stops shadow rays at surfaces that bend light (the map carries
    /// that light); `None` leaves it as it was.
    pub fn with_caustics(self, caustics: Option<&'a CausticMap>) -> Self {
        // Which entries stop shadow rays depends only on whether there is
        // a map: kept when that does not change (a pass over every entry).
        let visibility = if caustics.is_some() == self.caustics.is_some() {
            self.visibility
        } else {
            let stops = stops_shadow_rays(self.shading.materials, caustics);
            self.visibility.with_stops(&stops)
        };
        Self {
            caustics,
            visibility,
            ..self
        }
    }

    /// The world it traces in.
    pub fn world(&self) -> &'a World<'a> {
        self.world
    }

    /// The colour seen along a camera ray (unit direction).
    pub fn trace_primary(&self, ray: &Ray, counts: &mut RayCounts) -> PrimarySample {
        self.trace_primary_observed(ray, None, counts, &mut Unobserved)
    }

    /// [`Whitted::trace_primary`] with the ray's differential, if textures
    /// are filtered, telling `observer` every step.
    pub fn trace_primary_observed<O: RayObserver>(
        &self,
        ray: &Ray,
        differential: Option<RayDifferential>,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> PrimarySample {
        self.shade_camera_hit(
            ray,
            self.visibility.closest(ray),
            differential,
            counts,
            observer,
        )
    }

    /// [`Whitted::trace_primary_observed`] for a camera ray whose closest
    /// hit `hit` is already found (by a packet of camera rays walked
    /// together, see [`World::intersect_packet`]). A miss is answered
    /// inline, so that its colour reaches the caller in registers (a
    /// result returned through memory field by field and read back whole
    /// waited on failed store forwarding, see docs/performance-log.md).
    #[inline]
    pub fn shade_camera_hit<O: RayObserver>(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        differential: Option<RayDifferential>,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> PrimarySample {
        counts[RayKind::Primary] += 1;
        observer.ray_start(RayKind::Primary, ray, Color::ONE, 1.0);
        match hit {
            None => {
                observer.ray_hit(ray, None);
                observer.ray_end(self.shading.background);
                PrimarySample {
                    color: self.shading.background,
                    cut_at: None,
                }
            }
            Some(hit) => self.shade_camera_ray(ray, &hit, differential.as_ref(), counts, observer),
        }
    }

    /// What [`Self::shade_camera_hit`] gives an unobserved camera ray that
    /// hits nothing: the background, the ray counted.
    #[inline]
    pub fn camera_miss(&self, counts: &mut RayCounts) -> PrimarySample {
        counts[RayKind::Primary] += 1;
        PrimarySample {
            color: self.shading.background,
            cut_at: None,
        }
    }

    /// The colour of a camera ray that hits `hit` (counted and started by
    /// the caller).
    fn shade_camera_ray<O: RayObserver>(
        &self,
        ray: &Ray,
        hit: &Hit,
        differential: Option<&RayDifferential>,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> PrimarySample {
        let surface = self.surface::<O>(ray, hit);
        observer.ray_hit(ray, Some((hit, &surface)));
        let mut tally = SampleTally {
            counts,
            observer,
            rays_left: self.limits.ray_budget,
            cut_at: None,
        };
        let media = &MediumStack::default();
        let color = self.shade(
            ray,
            differential,
            &surface,
            hit.primitive,
            0,
            1.0,
            media,
            &mut tally,
        );
        tally.observer.ray_end(color);
        PrimarySample {
            color,
            cut_at: tally.cut_at.map(|(material, _)| material),
        }
    }

    /// The surface at `hit`, with (u, v) and tangents only where the
    /// material or the observer reads them.
    fn surface<O: RayObserver>(&self, ray: &Ray, hit: &Hit) -> Surface {
        let reads_uv = self.visibility.reads_uv(O::READS_UV);
        self.world.surface_for(ray, hit, reads_uv)
    }

    /// The colour seen along a secondary ray (unit direction) leaving
    /// primitive `from` (a ray into a glass sphere is tested against what
    /// lies inside it alone: [`World::intersect_from`]).
    #[allow(clippy::too_many_arguments)]
    fn trace<O: RayObserver>(
        &self,
        ray: &Ray,
        from: PrimitiveId,
        differential: Option<&RayDifferential>,
        depth: u32,
        weight: f64,
        media: &MediumStack,
        tally: &mut SampleTally<'_, O>,
    ) -> Color {
        match self.visibility.closest_from(ray, from) {
            None => {
                tally.observer.ray_hit(ray, None);
                self.shading.background
            }
            Some(hit) => {
                let surface = self.surface::<O>(ray, &hit);
                tally.observer.ray_hit(ray, Some((&hit, &surface)));
                self.shade(
                    ray,
                    differential,
                    &surface,
                    hit.primitive,
                    depth,
                    weight,
                    media,
                    tally,
                )
            }
        }
    }

    /// The colour leaving `s` back along `ray`. `weight` is the largest
    /// factor by which this colour reaches the pixel.
    #[allow(clippy::too_many_arguments)]
    fn shade<O: RayObserver>(
        &self,
        ray: &Ray,
        differential: Option<&RayDifferential>,
        s: &Surface,
        primitive: PrimitiveId,
        depth: u32,
        weight: f64,
        media: &MediumStack,
        tally: &mut SampleTally<'_, O>,
    ) -> Color {
        let m = &self.shading.materials[s.material.0 as usize];
        let incident = ray.dir;
        let view = -incident;
        let entering = incident.dot(s.normal) < 0.0;
        let facing = if entering { s.normal } else { -s.normal };
        // The shading normal (interpolated on meshes, tilted by a bump or
        // normal map) on the viewer's side.
        let n = shading_normal(m.bump.as_ref(), s, facing, view);
        // A tilted normal may see a light that is behind the surface itself.
        let bumped = m.bump.is_some();
        tally.observer.shading(n, entering);

        // The opacity weighs the surface's own light and mirror; the
        // dissolved rest joins the transmitted ray.
        let at_hit = differential.and_then(|d| d.at_hit(ray, s));
        let footprint = at_hit.as_ref().map(|h| &h.footprint);
        let alpha = m.opacity.filtered(s.uv, footprint);
        let ambient = m.ambient.filtered(s.uv, footprint);
        let mut local = m.emission.filtered(s.uv, footprint) + ambient * self.shading.ambient;

        let diffuse = m.diffuse.filtered(s.uv, footprint);
        let specular = m.specular.filtered(s.uv, footprint);
        // The shadow rays and the secondary rays leave from the same two
        // origins, one per side of the surface.
        let mut origins = RayOrigins::new(s.point, s.point_error, s.normal);
        if alpha != Color::ZERO && (diffuse != Color::ZERO || specular != Color::ZERO) {
            for (index, light, sample) in direct_samples(self.shading.lights, s.point).ahead() {
                if tally.observer.stopped() {
                    break;
                }
                let n_dot_l = n.dot(sample.to_light);
                if n_dot_l <= 0.0 || (bumped && facing.dot(sample.to_light) <= 0.0) {
                    tally.observer.light(index, Some(&sample), None);
                    continue;
                }
                let shadow = self.transmittance(
                    s,
                    &mut origins,
                    (index, light),
                    sample.to_light,
                    sample.distance,
                    tally,
                );
                tally.observer.light(index, Some(&sample), Some(shadow));
                if shadow == Color::ZERO {
                    continue;
                }
                let direct = phong(diffuse, specular, m.shininess, n, sample.to_light, view);
                local += shadow * sample.intensity * direct;
            }
        }
        if let Some(caustics) = self.caustics
            && alpha != Color::ZERO
            && diffuse != Color::ZERO
        {
            let caustic = diffuse * caustics.irradiance(s.point, n);
            tally.observer.caustic(caustic);
            local += caustic;
        }
        let mut color = alpha * local;

        if depth >= self.limits.max_depth {
            tally.observer.depth_limit();
            return color;
        }
        if tally.observer.stopped() {
            return color;
        }
        let kr = m.reflection.filtered(s.uv, footprint);
        let kt = m.transmission.filtered(s.uv, footprint);
        if kr == Color::ZERO && kt == Color::ZERO && alpha == Color::ONE {
            return color;
        }

        let crossing = media.cross(
            s.medium,
            self.shading.materials[s.medium.0 as usize].ior,
            entering,
        );
        let Crossing { n_from, n_to, .. } = crossing;
        let lobes = Lobes::new(
            Weights {
                opacity: alpha,
                diffuse,
                reflection: kr,
                transmission: kt,
            },
            m.fresnel,
            incident,
            n,
            n_from,
            n_to,
        );
        tally.observer.lobes(
            lobes.mirror,
            lobes.refraction,
            lobes.refracted.is_some(),
            [n_from, n_to],
        );
        let Lobes {
            mirror: reflected_weight,
            refraction: transmitted_weight,
            refracted,
            ..
        } = lobes;

        let bend = differential
            .zip(at_hit)
            .map(|(d, h)| Bend::new(self.world, ray, d, h, s, facing, n));
        let branches = reflected_weight != Color::ZERO && refracted.is_some();
        let child = weight * reflected_weight.max_element();
        if child >= self.limits.min_weight
            && reflected_weight != Color::ZERO
            && tally.take(s.material, branches)
        {
            tally.counts[RayKind::Reflected] += 1;
            let dir = reflect(incident, n);
            let origin = origins.towards(dir);
            let reflected = Ray::new(origin, dir);
            let kind = RayKind::Reflected;
            tally
                .observer
                .ray_start(kind, &reflected, reflected_weight, child);
            let differential = bend.map(|b| b.reflected());
            let differential = differential.as_ref();
            let c = self.trace(
                &reflected,
                primitive,
                differential,
                depth + 1,
                child,
                media,
                tally,
            );
            tally.observer.ray_end(c);
            color += reflected_weight * c;
        } else if reflected_weight != Color::ZERO {
            let kind = RayKind::Reflected;
            tally.observer.branch_skipped(kind, reflected_weight, child);
        }
        if let Some(dir) = refracted {
            let child = weight * transmitted_weight.max_element();
            if child >= self.limits.min_weight && tally.take(s.material, branches) {
                tally.counts[RayKind::Refracted] += 1;
                let origin = origins.towards(dir);
                let refracted = Ray::new(origin, dir);
                let kind = RayKind::Refracted;
                tally
                    .observer
                    .ray_start(kind, &refracted, transmitted_weight, child);
                let differential = bend.map(|b| b.refracted(dir, n_from / n_to));
                let differential = differential.as_ref();
                let media = &crossing.after();
                let c = self.trace(
                    &refracted,
                    primitive,
                    differential,
                    depth + 1,
                    child,
                    media,
                    tally,
                );
                tally.observer.ray_end(c);
                color += transmitted_weight * c;
            } else {
                let kind = RayKind::Refracted;
                tally
                    .observer
                    .branch_skipped(kind, transmitted_weight, child);
            }
        }
        color
    }

    /// How much of `light` (number `index`) reaches `s` along `to_light` (unit) over
    /// `distance`: 0 behind an opaque surface, the product of what every
    /// transmissive or dissolved surface crossed lets through otherwise
    /// ([`Material::pass_through`]). The shadow ray leaves from `s`'s
    /// `origins`.
    #[inline(always)]
    fn transmittance<O: RayObserver>(
        &self,
        s: &Surface,
        origins: &mut RayOrigins,
        (index, light): (usize, &Light),
        to_light: Vec3,
        distance: f64,
        tally: &mut SampleTally<'_, O>,
    ) -> Color {
        tally.counts[RayKind::Shadow] += 1;
        let origin = origins.towards(to_light);
        let target = match light {
            Light::Directional { .. } => None,
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(*position),
            Light::Area(_) => Some(s.point + distance * to_light),
        };
        let ray = shadow_segment(origin, to_light, (target, distance));
        if !self.visibility.lets_light_through() {
            let blocked = self.visibility.blocked(&ray, index);
            tally
                .observer
                .shadow_ray(&ray, ShadowStep::AnyHit { blocked });
            return if blocked { Color::ZERO } else { Color::ONE };
        }
        self.light_through(&ray, index, (target, distance), tally)
    }

    /// How much light passes along the shadow ray `ray` towards light
    /// number `index` (ending as [`shadow_segment`] says with `end`), in a
    /// world where some surfaces let light through: the product of what
    /// each surface crossed lets through, each crossing a shadow ray
    /// counted. Kept out of line: the shadow rays of worlds without such
    /// surfaces then take a short path.
    #[inline(never)]
    fn light_through<O: RayObserver>(
        &self,
        ray: &Ray,
        index: usize,
        end: (Option<Vec3>, f64),
        tally: &mut SampleTally<'_, O>,
    ) -> Color {
        let mut through = Color::ONE;
        let answer = self
            .visibility
            .passing(ray, index, end, O::READS_UV, |step| match step {
                SegmentStep::Answered { blocked } => {
                    let step = ShadowStep::AnyHit { blocked };
                    tally.observer.shadow_ray(ray, step);
                    Break(if blocked { Color::ZERO } else { Color::ONE })
                }
                SegmentStep::Reached { segment } => {
                    let step = ShadowStep::Closest { blocker: None };
                    tally.observer.shadow_ray(&segment, step);
                    Break(through)
                }
                SegmentStep::Crossed {
                    segment,
                    hit,
                    material,
                    uv,
                } => {
                    let step = ShadowStep::Closest {
                        blocker: Some(&hit),
                    };
                    tally.observer.shadow_ray(&segment, step);
                    through *= self.pass_through(material, uv);
                    if through.max_element() <= 0.0 {
                        return Break(Color::ZERO);
                    }
                    tally.counts[RayKind::Shadow] += 1;
                    Continue(())
                }
            });
        // Past the longest chain of crossings, no light arrives.
        answer.unwrap_or(Color::ZERO)
    }

    /// What a shadow ray lets through a surface of `material` at `uv`.
    fn pass_through(&self, material: MaterialId, uv: DVec2) -> Color {
        let m = &self.shading.materials[material.0 as usize];
        match self.caustics {
            Some(_) => photon_map::shadow_pass_through(m, uv),
            None => m.pass_through(uv),
        }
    }
}

/// Per material, whether its surfaces stop shadow rays outright: those
/// that let no light through and, with `caustics`, those that bend light,
/// whose light the map carries.
fn stops_shadow_rays(materials: &[Material], caustics: Option<&CausticMap>) -> Vec<bool> {
    let stops =
        |m: &Material| !m.is_transmissive() || (caustics.is_some() && photon_map::bends_light(m));
    materials.iter().map(stops).collect()
}
