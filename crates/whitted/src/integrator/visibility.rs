//! What an integrator asks of the world, and nothing else: three questions,
//! each answered by the fastest path the world offers, so that every
//! integrator gets every fast path by asking them.
//!
//! - **The closest hit** of a ray ([`Visibility::closest`]); of a ray
//!   leaving a surface, the rays starting inside a glass sphere tested
//!   against what reaches into it alone ([`Visibility::closest_from`],
//!   [`World::intersect_from`]).
//! - **Whether a segment is blocked** ([`Visibility::blocked`]), for
//!   shadow rays in a world where no surface lets light through: the
//!   shadow cache tries the blocker of the last shadow ray towards the
//!   same light first (`shadow_cache`).
//! - **What passes along a segment** ([`Visibility::passing`]), for shadow
//!   rays where some surfaces let light through: every surface crossed,
//!   nearest first, each once. One any-hit walk that tells the surfaces
//!   that stop light from those that let it through answers most such
//!   rays outright ([`World::shadow_path`]); where it met only surfaces
//!   letting light through, their crossings are found along the ray at
//!   once where they can be ([`World::shadow_crossings`]), and otherwise
//!   each step from one surface to the next tests only the surfaces the
//!   walk met ([`World::intersect_passed`]).
//!
//! With the fast paths off ([`Visibility::with_fast_paths`]) each question
//! takes the plain closest-hit or any-hit query, and a segment is walked
//! surface to surface through the whole structure: the reference the fast
//! paths are checked against, with the same answers and the same steps.

use std::ops::ControlFlow;

use crate::integrator::shadow_cache;
use crate::math::{DVec2, Ray, Vec3, offset_ray_origin};
use crate::shading::Material;
use crate::shape::ShapeHit;
use crate::world::{
    Hit, Interiors, MaterialId, OpaqueEntries, PassedEntries, PrimitiveId, ShadowCrossings,
    ShadowPath, World,
};

/// Longest chain of surfaces one segment is walked through, surface to
/// surface; a segment crossing more lets no light through.
const MAX_CROSSINGS: usize = 64;

// A segment answered from its crossings never meets the walk's limit.
const _: () = assert!(ShadowCrossings::CAPACITY < MAX_CROSSINGS);

/// The world as an integrator queries it.
#[derive(Debug)]
pub(super) struct Visibility<'a> {
    world: &'a World<'a>,
    /// Whether some material lets light through, so that shadow rays ask
    /// what passes rather than whether they are blocked.
    lets_light_through: bool,
    /// Where some material lets light through, which entries stop a
    /// segment outright ([`World::shadow_path`]); `None` otherwise, or for
    /// a world with instances.
    opaque: Option<OpaqueEntries>,
    /// What a ray starting inside a sphere that lets light in can meet
    /// first ([`World::interiors`]).
    interiors: Interiors,
    /// Per material, whether shading reads (u, v) ([`Material::reads_uv`]).
    reads_uv: Vec<bool>,
    /// Whether the questions take the fast paths.
    fast_paths: bool,
}

/// One step of [`Visibility::passing`] along a segment.
#[derive(Clone, Copy, Debug)]
pub(super) enum SegmentStep {
    /// The any-hit walk answered for the whole segment: blocked (no light
    /// passes), or clear (all of it does).
    Answered {
        /// True when the segment is blocked.
        blocked: bool,
    },
    /// The part of the segment from the last surface crossed (or its
    /// start) meets `hit` first, a surface of `material`, at `uv` (zero
    /// where neither the material nor the caller reads it).
    Crossed {
        /// The part of the segment walked.
        segment: Ray,
        /// The surface it meets first, `t` along `segment`.
        hit: Hit,
        /// The surface's material.
        material: MaterialId,
        /// The surface's (u, v).
        uv: DVec2,
    },
    /// The part of the segment from the last surface crossed (or its
    /// start) reaches the end.
    Reached {
        /// The part of the segment walked.
        segment: Ray,
    },
}

impl<'a> Visibility<'a> {
    /// The questions on `world`, whose surfaces have `materials`, with the
    /// fast paths; segments are walked surface to surface until
    /// [`Visibility::with_stops`] says which surfaces stop them outright.
    pub(super) fn new(world: &'a World<'a>, materials: &[Material]) -> Self {
        Self {
            world,
            lets_light_through: materials.iter().any(Material::is_transmissive),
            opaque: None,
            interiors: world.interiors(|m| materials[m.0 as usize].is_transmissive()),
            reads_uv: materials.iter().map(Material::reads_uv).collect(),
            fast_paths: true,
        }
    }

    /// The same questions, a surface of material `m` stopping a segment
    /// outright when `stops[m]` (those that let no light through, and any
    /// others whose light the integrator carries otherwise).
    pub(super) fn with_stops(self, stops: &[bool]) -> Self {
        Self {
            opaque: self
                .lets_light_through
                .then(|| self.world.opaque_entries(stops))
                .flatten(),
            ..self
        }
    }

    /// The same questions, taking the fast paths or, with `fast` false,
    /// the plain queries.
    pub(super) fn with_fast_paths(self, fast: bool) -> Self {
        Self {
            fast_paths: fast,
            ..self
        }
    }

    /// The world it asks.
    pub(super) fn world(&self) -> &'a World<'a> {
        self.world
    }

    /// Per material, whether a surface's (u, v) is needed, as
    /// [`World::surface_for`] takes it: where the materials' shading reads
    /// it or, when `observer_reads_uv`, everywhere.
    pub(super) fn reads_uv(&self, observer_reads_uv: bool) -> &[bool] {
        if observer_reads_uv {
            &[]
        } else {
            &self.reads_uv
        }
    }

    /// Whether some surface lets light through: shadow rays then ask
    /// [`Visibility::passing`], otherwise [`Visibility::blocked`].
    pub(super) fn lets_light_through(&self) -> bool {
        self.lets_light_through
    }

    /// The closest hit of `ray`.
    #[inline]
    pub(super) fn closest(&self, ray: &Ray) -> Option<Hit> {
        self.world.intersect(ray)
    }

    /// The closest hit of `ray`, which leaves primitive `from`.
    #[inline]
    pub(super) fn closest_from(&self, ray: &Ray, from: PrimitiveId) -> Option<Hit> {
        if self.fast_paths {
            self.world.intersect_from(ray, from, &self.interiors)
        } else {
            self.world.intersect(ray)
        }
    }

    /// True when anything lies on the segment `ray`, a shadow ray towards
    /// light number `light`.
    #[inline]
    pub(super) fn blocked(&self, ray: &Ray, light: usize) -> bool {
        if self.fast_paths {
            shadow_cache::occluded(self.world, ray, light)
        } else {
            self.world.occluded(ray)
        }
    }

    /// Tells `step` the steps of the segment `ray`, a shadow ray towards
    /// light number `light` that ends as [`shadow_segment`] says with
    /// `end`: either one [`SegmentStep::Answered`], or the surfaces
    /// crossed, nearest first, each once, then [`SegmentStep::Reached`];
    /// until `step` breaks, whose value it returns. `None` when `step`
    /// never breaks, or past [`MAX_CROSSINGS`] surfaces. A surface's
    /// (u, v) is found where its material reads it or `observer_reads_uv`
    /// ([`Visibility::reads_uv`]); crossings found at once, which have no
    /// (u, v), serve only segments whose surfaces' materials do not read
    /// it. A visitor rather than an iterator: an iterator's state (the
    /// crossings, the entries met) copied out per shadow ray was slower
    /// (docs/performance-log.md, figures moved out of doc comments).
    #[inline]
    pub(super) fn passing<B>(
        &self,
        ray: &Ray,
        light: usize,
        end: (Option<Vec3>, f64),
        observer_reads_uv: bool,
        mut step: impl FnMut(SegmentStep) -> ControlFlow<B>,
    ) -> Option<B> {
        let reads_uv = self.reads_uv(observer_reads_uv);
        let Some(opaque) = self.opaque.as_ref().filter(|_| self.fast_paths) else {
            return self.walk(ray, &PassedEntries::UNLISTED, (end, reads_uv), step);
        };
        let passed = match shadow_cache::shadow_path(self.world, ray, opaque, light) {
            ShadowPath::Clear => {
                return step(SegmentStep::Answered { blocked: false }).break_value();
            }
            ShadowPath::Blocked => {
                return step(SegmentStep::Answered { blocked: true }).break_value();
            }
            ShadowPath::Crossed(passed) => passed,
        };
        let no_uv = |c: &ShadowCrossings| c.iter().all(|c| !self.reads_uv[c.material.0 as usize]);
        let Some(crossings) = self.world.shadow_crossings(ray, &passed).filter(no_uv) else {
            return self.walk(ray, &passed, (end, reads_uv), step);
        };
        // Told as the walk would have made its steps: from each crossing on
        // (starting on the surface, not at an offset origin), each meeting
        // the next crossing.
        let from = |t: f64| Ray::segment(ray.at(t), ray.dir, ray.t_max - t);
        let mut last = 0.0;
        for c in crossings.iter() {
            let crossed = SegmentStep::Crossed {
                segment: from(last),
                hit: Hit {
                    primitive: c.primitive,
                    shape_hit: ShapeHit::at(c.t - last),
                },
                material: c.material,
                uv: DVec2::ZERO,
            };
            if let ControlFlow::Break(b) = step(crossed) {
                return Some(b);
            }
            last = c.t;
        }
        step(SegmentStep::Reached {
            segment: from(last),
        })
        .break_value()
    }

    /// [`Visibility::passing`] surface to surface from `ray` on, the hits
    /// among `passed`, each next part ending as `end` says, the surfaces'
    /// (u, v) found where `reads_uv` says.
    fn walk<B>(
        &self,
        ray: &Ray,
        passed: &PassedEntries,
        (end, reads_uv): ((Option<Vec3>, f64), &[bool]),
        mut step: impl FnMut(SegmentStep) -> ControlFlow<B>,
    ) -> Option<B> {
        let mut segment = *ray;
        for _ in 0..MAX_CROSSINGS {
            let Some(hit) = self.world.intersect_passed(&segment, passed) else {
                return step(SegmentStep::Reached { segment }).break_value();
            };
            let s = self.world.surface_for(&segment, &hit, reads_uv);
            let crossed = SegmentStep::Crossed {
                segment,
                hit,
                material: s.material,
                uv: s.uv,
            };
            if let ControlFlow::Break(b) = step(crossed) {
                return Some(b);
            }
            let origin = offset_ray_origin(s.point, s.point_error, s.normal, segment.dir);
            segment = shadow_segment(origin, segment.dir, end);
        }
        None
    }
}

/// The shadow ray from `origin` along `to_light` (unit) towards a light at
/// `target`, or `distance` away where there is none (a directional
/// light).
#[inline(always)]
pub(super) fn shadow_segment(
    origin: Vec3,
    to_light: Vec3,
    (target, distance): (Option<Vec3>, f64),
) -> Ray {
    let t_max = target.map_or(distance, |p| (p - origin).dot(to_light));
    Ray::segment(origin, to_light, t_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::math::Transform;
    use crate::math::random::Rng;
    use crate::mesh::TriangleMesh;
    use crate::shading::{Color, Texture};
    use crate::shape::{Plane, Shape, Sphere};
    use crate::world::Objects;

    /// Matte (stops shadow rays), clear glass, and matte half dissolved.
    fn materials() -> Vec<Material> {
        let glass = Material {
            diffuse: Texture::Constant(Color::ZERO),
            transmission: Texture::Constant(Color::ONE),
            ior: 1.5,
            ..Material::default()
        };
        let dissolved = Material {
            opacity: Texture::Constant(Color::splat(0.5)),
            ..Material::default()
        };
        vec![Material::default(), glass, dissolved]
    }

    /// Overlapping spheres (numbered first) and scattered triangles of the
    /// three materials and a glass floor plane; with `twice`, the
    /// triangles placed a second time, moved (a world with instances).
    /// Also the spheres, by number.
    fn scene(rng: &mut Rng, twice: bool) -> (Objects, Vec<Sphere>) {
        let mut objects = Objects::default();
        let mut spheres = Vec::new();
        for i in 0..120 {
            let centre = 8.0 * (rng.unit_vector() * rng.uniform());
            let sphere = Sphere::new(centre, 0.3 + 1.2 * rng.uniform()).unwrap();
            spheres.push(sphere);
            objects.add_primitive(
                Shape::Sphere(sphere),
                MaterialId(i % 3),
                Transform::IDENTITY,
            );
        }
        for material in 0..3 {
            let mut positions = Vec::new();
            for _ in 0..60 {
                let corner = 8.0 * (rng.unit_vector() * rng.uniform());
                positions.extend([
                    corner,
                    corner + rng.unit_vector(),
                    corner + rng.unit_vector(),
                ]);
            }
            let triangles = (0..60).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
            let mesh = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
            objects.add_mesh_instance(mesh, MaterialId(material), Transform::IDENTITY);
            if twice {
                let moved = Transform::translate(Vec3::new(1.0, 0.5, -1.0)).unwrap();
                objects.add_mesh_instance(mesh, MaterialId(material), moved);
            }
        }
        let floor = Plane::new(Vec3::new(0.0, -9.0, 0.0), Vec3::Y).unwrap();
        objects.add_primitive(Shape::Plane(floor), MaterialId(1), Transform::IDENTITY);
        (objects, spheres)
    }

    /// What a segment meets, as [`Visibility::passing`] tells it: blocked,
    /// or the surfaces it passes, nearest first.
    #[derive(Debug, PartialEq)]
    enum Verdict {
        Blocked,
        Passes(Vec<(PrimitiveId, MaterialId)>),
    }

    /// The [`Verdict`] on `ray`, and whether the any-hit walk answered it.
    fn verdict(v: &Visibility, ray: &Ray, light: usize, stops: &[bool]) -> (Verdict, bool) {
        let mut passed = Vec::new();
        let mut answered = false;
        let end = (Some(ray.at(ray.t_max)), ray.t_max);
        let answer = v.passing(ray, light, end, false, |step| match step {
            SegmentStep::Answered { blocked } => {
                answered = true;
                ControlFlow::Break(!blocked)
            }
            SegmentStep::Crossed { hit, material, .. } => {
                if stops[material.0 as usize] {
                    return ControlFlow::Break(false);
                }
                passed.push((hit.primitive, material));
                ControlFlow::Continue(())
            }
            SegmentStep::Reached { .. } => ControlFlow::Break(true),
        });
        match answer {
            Some(true) => (Verdict::Passes(passed), answered),
            _ => (Verdict::Blocked, answered),
        }
    }

    #[test]
    fn segments_pass_the_same_surfaces_with_the_fast_paths_as_without() {
        let materials = materials();
        let stops = [true, false, false];
        let mut rng = Rng::new(23);
        for twice in [false, true] {
            let (objects, _) = scene(&mut rng, twice);
            for kind in [AccelKind::Bvh, AccelKind::KdTree, AccelKind::Grid] {
                let world = World::build(&objects, kind);
                let fast = Visibility::new(&world, &materials).with_stops(&stops);
                let plain = Visibility::new(&world, &materials)
                    .with_stops(&stops)
                    .with_fast_paths(false);
                // Segments answered by the any-hit walk, and told step by
                // step.
                let mut told = [0; 2];
                let mut passing = 0;
                for i in 0..1500 {
                    let from = 9.0 * rng.unit_vector() * rng.uniform();
                    // Lights above and below the floor.
                    let y = if i % 2 == 0 { 20.0 } else { -20.0 };
                    let light = Vec3::new(3.0, y, -4.0) + 4.0 * rng.unit_vector();
                    let ray =
                        Ray::segment(from, (light - from).normalize(), (light - from).length());
                    let (expected, answered) = verdict(&plain, &ray, 0, &stops);
                    assert!(!answered, "without fast paths every segment is walked");
                    // Light 99 has no shadow cache.
                    for light in [0, 99] {
                        let (found, answered) = verdict(&fast, &ray, light, &stops);
                        assert_eq!(found, expected, "{kind:?} {ray:?}");
                        told[usize::from(!answered)] += 1;
                    }
                    passing +=
                        usize::from(matches!(&expected, Verdict::Passes(p) if !p.is_empty()));
                }
                assert!(passing > 100, "{kind:?}: {passing} segments pass surfaces");
                if twice {
                    // A world with instances walks every segment.
                    assert_eq!(told[0], 0, "{kind:?}");
                } else {
                    assert!(told.iter().all(|&n| n > 50), "{kind:?}: {told:?}");
                }
            }
        }
    }

    #[test]
    fn rays_leaving_a_glass_sphere_meet_what_the_plain_query_meets() {
        let materials = materials();
        let mut rng = Rng::new(29);
        let (objects, spheres) = scene(&mut rng, false);
        let world = World::build(&objects, AccelKind::Bvh);
        let fast = Visibility::new(&world, &materials);
        let plain = Visibility::new(&world, &materials).with_fast_paths(false);
        let mut inside = 0;
        for _ in 0..3000 {
            let number = rng.below(120);
            let sphere = &spheres[number as usize];
            let origin = sphere.center() + 0.99 * sphere.radius() * rng.unit_vector();
            let ray = Ray::new(origin, rng.unit_vector());
            let from = PrimitiveId(number);
            let expected = plain.closest_from(&ray, from);
            let found = fast.closest_from(&ray, from);
            assert_eq!(found.map(|h| h.primitive), expected.map(|h| h.primitive));
            assert_eq!(
                found.map(|h| h.t().to_bits()),
                expected.map(|h| h.t().to_bits())
            );
            inside += usize::from(number % 3 == 1);
        }
        assert!(inside > 500);
    }
}
