//! The world's closest-hit and any-hit walks as kernel tasks
//! ([`crate::accel::kernel`]): a query enters its kernel once, and the
//! structure's walk and the leaf tests here (triangles, spheres and the
//! other entries' tests in place) are compiled together under its target
//! features. What is left to the world's tables (a shape's whole test, an
//! instance's own walk) stays a call.

use super::lanes::LanesOf;
use std::ops::Range;

use super::entry::{Query, leaf_hit, leaf_occludes};
use super::{Hit, PrimitiveId, World};
use crate::accel::kernel::{self, Kernel, KernelTask};
use crate::accel::{AnyLeaves, ClosestLeaves, QueryContext};
use crate::math::Ray;

impl<'a> World<'a> {
    /// The closest hit in this level, its instances placing `definitions`.
    pub(super) fn closest(
        &self,
        definitions: &[World<'a>],
        ray: &Ray,
        ctx: &mut QueryContext,
    ) -> Option<Hit> {
        let backend = ctx.backend;
        let task = Task::<false> {
            world: self,
            definitions,
            ray,
            ctx,
        };
        kernel::run(backend, task)
    }

    /// [`World::closest`] with kernel `K`.
    #[inline(always)]
    fn closest_with<K: Kernel>(
        &self,
        definitions: &[World<'a>],
        ray: &Ray,
        ctx: &mut QueryContext,
    ) -> Option<Hit> {
        let query = Query::new(ray, self.has_triangles);
        let mut best: Option<Hit> = None;
        let mut t_max = ray.t_max;
        let mut inner = ctx.fresh();
        for e in &self.unbounded {
            if let Some((primitive, h)) = self.intersect_other(
                definitions,
                e,
                (&query, t_max, super::entry::Rest::Test),
                &mut inner,
            ) {
                t_max = h.t;
                best = Some(Hit {
                    primitive: PrimitiveId(primitive),
                    shape_hit: h,
                });
            }
        }
        let mut clipped = *ray;
        clipped.t_max = t_max;
        let leaves = ClosestInLeaves {
            world: self,
            definitions,
            query: &query,
            best: &mut best,
            inner: &mut inner,
        };
        self.accel.closest_with::<K>(&clipped, ctx, leaves);
        ctx.counters += inner.counters;
        best
    }

    /// True when anything lies in the ray's interval in this level, its
    /// instances placing `definitions`.
    pub(super) fn any(&self, definitions: &[World<'a>], ray: &Ray, ctx: &mut QueryContext) -> bool {
        let backend = ctx.backend;
        let task = Task::<true> {
            world: self,
            definitions,
            ray,
            ctx,
        };
        kernel::run(backend, task)
    }

    /// [`World::any`] with kernel `K`.
    #[inline(always)]
    fn any_with<K: Kernel>(
        &self,
        definitions: &[World<'a>],
        ray: &Ray,
        ctx: &mut QueryContext,
    ) -> bool {
        let query = Query::new(ray, self.has_triangles);
        let mut inner = ctx.fresh();
        if self.unbounded.iter().any(|e| {
            self.other_occludes(
                definitions,
                e,
                (&query, super::entry::Rest::Test),
                &mut inner,
            )
        }) {
            ctx.counters += inner.counters;
            return true;
        }
        if self.instance_count == 0 {
            // One level, no instance walk to count apart (tried one path for
            // both: slower, see docs/performance-log.md).
            let leaves = AnyInLeaves::<false> {
                world: self,
                definitions,
                query: &query,
                inner: &mut inner,
                blocker: &mut 0,
            };
            return self.accel.any_with::<K>(ray, ctx, leaves);
        }
        let leaves = AnyInLeaves::<true> {
            world: self,
            definitions,
            query: &query,
            inner: &mut inner,
            blocker: &mut 0,
        };
        let occluded = self.accel.any_with::<K>(ray, ctx, leaves);
        ctx.counters += inner.counters;
        occluded
    }
}

/// A query of one level as a kernel's task: any hit with `ANY`, the
/// closest otherwise.
struct Task<'q, 'a, const ANY: bool> {
    world: &'q World<'a>,
    definitions: &'q [World<'a>],
    ray: &'q Ray,
    ctx: &'q mut QueryContext,
}

impl KernelTask for Task<'_, '_, false> {
    type Output = Option<Hit>;
    #[inline(always)]
    fn run<K: Kernel>(self) -> Option<Hit> {
        self.world
            .closest_with::<K>(self.definitions, self.ray, self.ctx)
    }
}

impl KernelTask for Task<'_, '_, true> {
    type Output = bool;
    #[inline(always)]
    fn run<K: Kernel>(self) -> bool {
        self.world
            .any_with::<K>(self.definitions, self.ray, self.ctx)
    }
}

/// The closest-hit test of a leaf of the world's entries: the hits nearer
/// than the walk's go to `best`, instances' work to `inner`.
struct ClosestInLeaves<'q, 'a> {
    world: &'q World<'a>,
    definitions: &'q [World<'a>],
    query: &'q Query<'q>,
    best: &'q mut Option<Hit>,
    inner: &'q mut QueryContext,
}

impl ClosestLeaves for ClosestInLeaves<'_, '_> {
    #[inline(always)]
    fn closest<K: Kernel>(&mut self, range: Range<u32>, t_max: f64) -> Option<f64> {
        let (world, definitions, query) = (self.world, self.definitions, self.query);
        let inner = &mut *self.inner;
        let best = &mut *self.best;
        let number = best.map_or(u32::MAX, |h| h.primitive.0);
        leaf_hit::<LanesOf<K>>(
            &world.entries,
            range,
            query,
            (t_max, number),
            |e, t_max, rest| world.intersect_other(definitions, e, (query, t_max, rest), inner),
            |primitive, shape_hit| {
                *best = Some(Hit {
                    primitive: PrimitiveId(primitive),
                    shape_hit,
                })
            },
        )
    }
}

/// The any-hit test of a leaf of the world's entries, which leaves the
/// entry found in `blocker`; with `INSTANCES`, entries walked as instances
/// count their work in `inner`.
pub(super) struct AnyInLeaves<'q, 'a, const INSTANCES: bool> {
    pub(super) world: &'q World<'a>,
    pub(super) definitions: &'q [World<'a>],
    pub(super) query: &'q Query<'q>,
    pub(super) inner: &'q mut QueryContext,
    /// The position in the world's entries of the entry found, if one was.
    pub(super) blocker: &'q mut u32,
}

impl<const INSTANCES: bool> AnyLeaves for AnyInLeaves<'_, '_, INSTANCES> {
    #[inline(always)]
    fn occludes<K: Kernel>(&mut self, range: Range<u32>) -> bool {
        let (world, definitions, query) = (self.world, self.definitions, self.query);
        let inner = &mut *self.inner;
        let found = leaf_occludes::<LanesOf<K>>(&world.entries, range, query, |e, rest| {
            if INSTANCES {
                world.other_occludes(definitions, e, (query, rest), inner)
            } else {
                world.rest_occludes(e.number, query, rest)
            }
        });
        if let Some(entry) = found {
            *self.blocker = entry;
        }
        found.is_some()
    }
}

#[cfg(test)]
mod tests {
    use crate::accel::{AccelKind, Backend, Isa, QueryContext};
    use crate::math::random::Rng;
    use crate::math::{Ray, Transform, Vec3};
    use crate::mesh::TriangleMesh;
    use crate::world::packet::tests::closed_form_scene;
    use crate::world::{MaterialId, Objects, ShadowHint, World};

    /// Every backend this processor runs finds the same closest hits (the
    /// primitive and `t` bit for bit), the same any-hit answers and the
    /// same work as the portable one, on every structure, in worlds of
    /// spheres, polygons, moved cylinders, a triangle soup, a mesh placed
    /// twice (instances) and a floor plane; the shadow cache's answers
    /// are the any-hit query's.
    #[test]
    fn every_backend_answers_as_the_portable_one() {
        let mut rng = Rng::new(46);
        let portable = Backend::new(Isa::Sse2).unwrap();
        let mut compared = 0;
        for floor in [false, true] {
            let mut objects = closed_form_scene(&mut rng, floor);
            let positions: Vec<Vec3> = (0..90)
                .map(|_| rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0)))
                .collect();
            let triangles: Vec<[u32; 3]> = (0..30).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
            let mesh = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
            for offset in [Vec3::new(2.0, 0.0, 1.0), Vec3::new(-2.0, 1.0, 0.0)] {
                let moved = Transform::translate(offset).unwrap();
                objects.add_mesh_instance(mesh, MaterialId(0), moved);
            }
            for kind in AccelKind::ALL {
                let world = World::build(&objects, kind);
                let mut hint = ShadowHint::NONE;
                for _ in 0..400 {
                    let origin = rng.point_in(Vec3::splat(-6.0), Vec3::splat(6.0));
                    let towards = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
                    let mut ray = Ray::new(origin, towards - origin);
                    if rng.below(2) == 0 {
                        ray.t_max = rng.range(0.2, 1.0);
                    }
                    let answers = |backend: Backend| {
                        let mut ctx = QueryContext {
                            backend,
                            ..QueryContext::default()
                        };
                        let hit = world.intersect_with(&ray, &mut ctx);
                        let hit = hit.map(|h| (h.primitive, h.t().to_bits()));
                        (hit, world.occluded_with(&ray, &mut ctx), ctx.counters)
                    };
                    let expected = answers(portable);
                    for backend in Backend::available() {
                        assert_eq!(answers(backend), expected, "{kind:?} {backend:?} {ray:?}");
                        compared += 1;
                    }
                    assert_eq!(world.occluded_hinted(&ray, &mut hint), expected.1);
                }
            }
        }
        assert!(compared >= 8 * 400, "{compared}");
    }

    /// Primitives hit at exactly the same parameter (the same sphere twice,
    /// the same triangle three times over, scattered among others): every
    /// structure, the single walk and the packet walk alike, name the
    /// lowest-numbered of them.
    #[test]
    fn a_tie_goes_to_the_lowest_number_on_every_structure() {
        use crate::shape::{Shape, Sphere};
        let mut rng = Rng::new(7);
        let mut objects = Objects::default();
        // The first of each group of copies, and the later ones.
        let (mut firsts, mut later) = (Vec::new(), Vec::new());
        let m = MaterialId(0);
        for _ in 0..40 {
            let centre = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
            let sphere = Sphere::new(centre, rng.range(0.1, 0.6)).unwrap();
            let number = objects.primitives.len() as u32;
            objects.add_primitive(Shape::Sphere(sphere), m, Transform::IDENTITY);
            if rng.below(3) == 0 {
                // A twin a few numbers later, another sphere between.
                let lone = Sphere::new(centre + Vec3::X * 9.0, 0.2).unwrap();
                objects.add_primitive(Shape::Sphere(lone), m, Transform::IDENTITY);
                objects.add_primitive(Shape::Sphere(sphere), m, Transform::IDENTITY);
                firsts.push(number);
                later.push(number + 2);
            }
        }
        let shapes = objects.primitives.len() as u32;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..60 {
            let corners = [0, 1, 2].map(|_| rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0)));
            let base = positions.len() as u32;
            positions.extend(corners);
            let copies = if i % 5 == 0 { 3 } else { 1 };
            let number = shapes + triangles.len() as u32;
            if copies > 1 {
                firsts.push(number);
                later.extend([number + 1, number + 2]);
            }
            for _ in 0..copies {
                triangles.push([base, base + 1, base + 2]);
            }
        }
        let mesh = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
        objects.add_mesh_instance(mesh, m, Transform::IDENTITY);
        let mut ties = 0;
        for kind in AccelKind::ALL {
            let world = World::build(&objects, kind);
            for _ in 0..2000 {
                let origin = rng.point_in(Vec3::splat(-9.0), Vec3::splat(9.0));
                let towards = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0)) - origin;
                let rays: Vec<Ray> = (0..8)
                    .map(|_| {
                        let wobble = rng.point_in(Vec3::splat(-0.3), Vec3::splat(0.3));
                        Ray::new(origin, towards + wobble)
                    })
                    .collect();
                let mut packed = [None; 8];
                world.intersect_packet(&rays, &mut QueryContext::default(), &mut packed);
                for (ray, packed) in rays.iter().zip(packed) {
                    let hit = world.intersect(ray);
                    let key =
                        |h: Option<crate::world::Hit>| h.map(|h| (h.primitive.0, h.t().to_bits()));
                    assert_eq!(key(packed), key(hit), "{kind:?} packet {ray:?}");
                    if let Some((number, _)) = key(hit) {
                        assert!(!later.contains(&number), "{kind:?}: {number} {ray:?}");
                        ties += usize::from(firsts.contains(&number));
                    }
                }
            }
        }
        assert!(ties > 400, "{ties}");
    }
}
