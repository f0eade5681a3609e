//! What the renderer traces: the scene's objects prepared once for ray
//! queries. World-space bounds, an acceleration structure over the bounded
//! primitives, a short list of the unbounded ones, and the two queries every
//! integrator needs — the closest hit and any hit — plus the full surface
//! description of a final hit.
//!
//! Primitives are numbered once for the whole world: first the shapes of
//! [`Objects::primitives`] in order, then the triangles of each mesh
//! instance of [`Objects::mesh_instances`] in order. That number is what
//! [`Hit`] reports (and the `id` AOV shows).

mod hit;
mod objects;

pub use hit::{Hit, Surface};
pub use objects::{MaterialId, MeshId, MeshInstance, Objects, Primitive, TransformId};

use crate::accel::{
    AccelKind, AccelerationStructure, Accelerator, KdTree, KdTreeBuildParams, QueryContext,
};
use crate::math::{Aabb, Ray, Transform, Vec3};
use crate::mesh::TriangleMesh;
#[cfg(target_arch = "x86_64")]
use crate::shape::{Hits4, LANES, watertight4};
use crate::shape::{RayShear, Shape, ShapeHit, clipped_triangle_bounds, watertight};
use rayon::prelude::*;
use std::ops::Range;

/// Triangles per parallel task when preparing meshes: fewer are prepared
/// on the calling thread.
const PARALLEL_CHUNK: usize = 4096;

/// What a primitive number stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PrimitiveRef {
    /// Index into [`Objects::primitives`].
    Shape(u32),
    /// Triangle `triangle` of mesh instance `instance`.
    Triangle {
        /// Index into [`Objects::mesh_instances`].
        instance: u32,
        /// The triangle in that instance's mesh.
        triangle: u32,
    },
}

/// The objects of a scene, ready for ray queries.
#[derive(Debug)]
pub struct World<'a> {
    primitives: &'a [Primitive],
    instances: &'a [MeshInstance],
    meshes: &'a [TriangleMesh],
    transforms: &'a [Transform],
    refs: Vec<PrimitiveRef>,
    accel: Accelerator,
    bounds: Aabb,
    /// Each primitive the structure's queries name, in their order: per
    /// structure slot, or for a BVH or a kd-tree per entry of its index
    /// array, so that a leaf's triangles lie together. The hot case reaches
    /// its vertices without going through `refs`, the instance and the
    /// mesh's index array (same test, same result). Tried and not kept
    /// before this: renumbering the BVH's primitives to leaf order in its
    /// build, no measurable change on the bunny (10.5/3.4/2.65 Mrays/s
    /// either way), a slower build.
    entries: Vec<EntryPrimitive>,
    /// Whether some entry of `entries` is a triangle, so queries compute
    /// the ray's shear up front.
    has_triangles: bool,
    /// Whether the processor has AVX, so shadow rays test runs of a BVH's
    /// or a kd-tree's leaf triangles four at a time.
    #[cfg(target_arch = "x86_64")]
    wide_triangles: bool,
    unbounded: Vec<u32>,
}

/// The primitive of one entry of [`World::entries`]: its number, and
/// its corners when it is an untransformed triangle (of a mesh or a
/// triangle shape, which then takes the mesh triangles' path: the same
/// watertight test on the same corners). The number shares the corners'
/// 80 bytes, so a hit reads it from the line its test read. Looking it up
/// through the structure's index array and the slots' numbers, two random
/// reads, took a fifth of the dragon's triangle-test time on diffuse rays
/// (perf); without them its diffuse rays run at 1.79 against 1.67 Mrays/s
/// with the BVH and 0.94 against 0.89 with the kd-tree (1 thread, medians
/// of 10 and 8 interleaved runs; the bunny's, whose data stay in cache,
/// within noise).
#[derive(Clone, Copy, Debug)]
struct EntryPrimitive {
    /// The primitive's number (its index in `World::refs`).
    number: u32,
    /// Whether `corners` holds a triangle's.
    triangle: bool,
    /// The triangle's corners, zero for other primitives.
    corners: [Vec3; 3],
}

const _: () = assert!(size_of::<EntryPrimitive>() == 80);

impl EntryPrimitive {
    /// The entry of primitive `number`, with the corners if it is an
    /// untransformed triangle.
    fn new(number: u32, corners: Option<[Vec3; 3]>) -> Self {
        Self {
            number,
            triangle: corners.is_some(),
            corners: corners.unwrap_or([Vec3::ZERO; 3]),
        }
    }

    /// The corners, if the primitive is an untransformed triangle.
    #[inline(always)]
    fn corners(&self) -> Option<&[Vec3; 3]> {
        self.triangle.then_some(&self.corners)
    }
}

/// A world-space ray with what the triangle test needs of it, computed once
/// per query when the scene has untransformed triangles (a scene of other
/// shapes does not pay for it).
struct Query<'r> {
    ray: &'r Ray,
    shear: Option<RayShear>,
}

impl Query<'_> {
    /// The ray's shear for the triangle test.
    #[inline]
    fn shear(&self) -> RayShear {
        self.shear.unwrap_or_else(|| RayShear::new(self.ray))
    }
}

impl<'a> World<'a> {
    /// Prepares the objects with the default structure.
    pub fn new(objects: &'a Objects) -> Self {
        Self::build(objects, AccelKind::default())
    }

    /// Prepares the objects with the structure `kind`.
    pub fn build(objects: &'a Objects, kind: AccelKind) -> Self {
        let n = objects.primitive_count();
        let mut refs = Vec::with_capacity(n);
        let mut bounded = Vec::with_capacity(n);
        let mut unbounded = Vec::new();
        let mut boxes = Vec::with_capacity(n);
        let to_world = |transform: Option<TransformId>, local: Aabb| match transform {
            Some(id) => objects.transforms[id.0 as usize].bounds_to_world(&local),
            None => local,
        };
        for (i, p) in objects.primitives.iter().enumerate() {
            let local = p.shape.bounds();
            if local.is_finite() {
                boxes.push(to_world(p.transform, local));
                bounded.push(refs.len() as u32);
            } else {
                unbounded.push(refs.len() as u32);
            }
            refs.push(PrimitiveRef::Shape(i as u32));
        }
        // The first structure slot of each mesh instance's triangles.
        let mut instance_slots = Vec::with_capacity(objects.mesh_instances.len());
        // A mesh's triangles are prepared in parallel: on the bunny this
        // loop, and the fresh memory it touches, took a fifth of the time
        // `whitted bench` reports as the BVH build.
        for (instance, m) in objects.mesh_instances.iter().enumerate() {
            let mesh = &objects.meshes[m.mesh.0 as usize];
            let triangles = || {
                (0..mesh.len() as u32)
                    .into_par_iter()
                    .with_min_len(PARALLEL_CHUNK)
            };
            let first = refs.len() as u32;
            instance_slots.push(bounded.len() as u32);
            boxes.par_extend(triangles().map(|t| to_world(m.transform, mesh.triangle_bounds(t))));
            bounded.extend(first..first + mesh.len() as u32);
            refs.extend(
                (0..mesh.len() as u32).map(|triangle| PrimitiveRef::Triangle {
                    instance: instance as u32,
                    triangle,
                }),
            );
        }
        let bounds = boxes
            .par_chunks(PARALLEL_CHUNK)
            .map(|chunk| chunk.iter().fold(Aabb::EMPTY, |a, b| a.union(b)))
            .collect::<Vec<Aabb>>()
            .iter()
            .fold(Aabb::EMPTY, |a, b| a.union(b));
        // The corners of the primitive in structure slot `slot` if it is an
        // untransformed triangle. A triangle shape then takes the mesh
        // triangles' path: the same watertight test on the same corners.
        // Shapes take the first slots, and a shape's primitive number is
        // its index in `Objects::primitives`. A mesh triangle is found from
        // its slot's offset in its instance's run of slots: going through
        // `bounded` and `refs`, two more random reads per slot, made the
        // gather below take 60 instead of 37 ms on the dragon.
        let shape_slots = instance_slots
            .first()
            .map_or(bounded.len(), |&s| s as usize);
        let slot_corners = |slot: u32| {
            if (slot as usize) < shape_slots {
                return match &objects.primitives[bounded[slot as usize] as usize] {
                    Primitive {
                        shape: Shape::Triangle(t),
                        transform: None,
                        ..
                    } => Some(t.vertices()),
                    _ => None,
                };
            }
            let instance = instance_slots.partition_point(|&first| first <= slot) - 1;
            let m = &objects.mesh_instances[instance];
            let mesh = &objects.meshes[m.mesh.0 as usize];
            let triangle = slot - instance_slots[instance];
            m.transform.is_none().then(|| mesh.corners(triangle))
        };
        // Perfect splits for the kd-tree: an untransformed triangle's
        // bounds in a cell are those of its part inside the cell; other
        // primitives keep their box ∩ the cell.
        let clip = |slot: u32, cell: &Aabb| match slot_corners(slot) {
            Some(c) => clipped_triangle_bounds(c, cell),
            None => boxes[slot as usize].intersection(cell),
        };
        let accel = match kind {
            AccelKind::KdTree => Accelerator::KdTree(KdTree::build_clipped(
                &boxes,
                &KdTreeBuildParams::default(),
                &clip,
            )),
            _ => Accelerator::build(kind, &boxes),
        };
        // Gathered straight from the scene, in parallel, in the order the
        // queries name them: per entry of a BVH's or kd-tree's index
        // array, per slot for the other structures. Copying them in slot
        // order first, then to this order, made the dragon's BVH build 5%
        // slower (324 against 307 ms, best of 15).
        let order = accel.leaf_order();
        let count = order.map_or(bounded.len(), <[u32]>::len);
        let entries: Vec<_> = (0..count)
            .into_par_iter()
            .with_min_len(PARALLEL_CHUNK)
            .map(|entry| {
                let slot = order.map_or(entry as u32, |o| o[entry]);
                EntryPrimitive::new(bounded[slot as usize], slot_corners(slot))
            })
            .collect();
        let has_triangles = entries.par_iter().any(|e| e.triangle);
        Self {
            primitives: &objects.primitives,
            instances: &objects.mesh_instances,
            meshes: &objects.meshes,
            transforms: &objects.transforms,
            refs,
            accel,
            bounds,
            entries,
            has_triangles,
            #[cfg(target_arch = "x86_64")]
            wide_triangles: is_x86_feature_detected!("avx"),
            unbounded,
        }
    }

    fn transform(&self, id: Option<TransformId>) -> Option<&Transform> {
        id.map(|id| &self.transforms[id.0 as usize])
    }

    /// A query for `ray`, with the shear precomputed if triangles may need it.
    #[inline]
    fn query<'r>(&self, ray: &'r Ray) -> Query<'r> {
        Query {
            ray,
            shear: self.has_triangles.then(|| RayShear::new(ray)),
        }
    }

    /// Primitive `index` hit by the query's ray, closer than `t_max`.
    #[inline]
    fn intersect_primitive(&self, index: u32, query: &Query, t_max: f64) -> Option<ShapeHit> {
        let mut ray = *query.ray;
        ray.t_max = t_max;
        match self.refs[index as usize] {
            PrimitiveRef::Shape(i) => {
                let p = &self.primitives[i as usize];
                match self.transform(p.transform) {
                    Some(t) => p.shape.intersect(&t.ray_to_object(&ray)),
                    None => p.shape.intersect(&ray),
                }
            }
            PrimitiveRef::Triangle { instance, triangle } => {
                let m = &self.instances[instance as usize];
                let mesh = &self.meshes[m.mesh.0 as usize];
                match self.transform(m.transform) {
                    Some(t) => {
                        let local = t.ray_to_object(&ray);
                        mesh.intersect(triangle, &local, &RayShear::new(&local))
                    }
                    None => mesh.intersect(triangle, &ray, &query.shear()),
                }
            }
        }
    }

    /// The primitive of entry `entry` of `entries` hit by the query's ray,
    /// closer than `t_max`, recorded in `best`; returns its `t`.
    #[inline(always)]
    fn hit_entry(
        &self,
        entry: u32,
        query: &Query,
        t_max: f64,
        best: &mut Option<Hit>,
    ) -> Option<f64> {
        let e = &self.entries[entry as usize];
        let h = match e.corners() {
            Some(corners) => intersect_triangle(corners, query, t_max),
            None => self.intersect_primitive(e.number, query, t_max),
        }?;
        *best = Some(Hit {
            primitive: e.number,
            shape_hit: h,
        });
        Some(h.t)
    }

    /// The closest of the primitives of entries `entries` of
    /// [`Self::entries`] hit by the query's ray, closer than `t_max`,
    /// recorded in `best`; returns its `t`. One by one: testing runs
    /// of triangles four at a time as [`Self::leaf_occludes`] does made
    /// the bunny's primary and diffuse rays 10% and 6% slower (1 thread,
    /// best of four interleaved runs), with 5% more instructions.
    #[inline(always)]
    fn hit_leaf(
        &self,
        entries: Range<u32>,
        query: &Query,
        mut t_max: f64,
        best: &mut Option<Hit>,
    ) -> Option<f64> {
        let mut found = None;
        for entry in entries {
            if let Some(t) = self.hit_entry(entry, query, t_max, best) {
                t_max = t;
                found = Some(t);
            }
        }
        found
    }

    /// True when a primitive of entries `entries` of [`Self::entries`] lies
    /// in the query's ray interval. Where the processor has AVX, runs of
    /// two to four triangles are tested at once, with the same answers as
    /// one by one (see [`Self::triangle_run`]):
    /// the same instructions on the bunny's shadow rays (callgrind), 18%
    /// faster (5.74 against 4.84 Mrays/s, 1 thread, best of four
    /// interleaved runs), having fewer branches on the edge tests' signs.
    /// Measured again once the scalar test had lost those branches (1
    /// thread, with and without AVX, medians of the best of 6 runs in 4
    /// interleaved rounds on the bunny, of 6 in 3 on the kitchen, of 3 in
    /// 3 on the dragon): kd-tree 3.42 against 3.32 Mrays/s on the bunny,
    /// 1.72 against 1.63 on the dragon, 12.4 on the kitchen either way;
    /// BVH 5.19 against 5.36 on the bunny (noise level), 3.06 against
    /// 2.90 on the dragon, 17.4 and 17.3 on the kitchen.
    #[inline(always)]
    fn leaf_occludes(&self, entries: Range<u32>, query: &Query) -> bool {
        let mut entry = entries.start;
        while entry < entries.end {
            #[cfg(target_arch = "x86_64")]
            if let Some((run, hits)) = self.triangle_run(entry, entries.end, query) {
                if hits.mask != 0 {
                    return true;
                }
                entry += run;
                continue;
            }
            if self.entry_occludes(entry, query) {
                return true;
            }
            entry += 1;
        }
        false
    }

    /// With AVX, the run of two to [`LANES`] triangles that starts at entry
    /// `entry` of [`Self::entries`] (and ends before `end`), tested at once
    /// against the query's ray: its length and the hits, lane `i` for
    /// entry `entry + i`. `None` without AVX or such a run.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn triangle_run(&self, entry: u32, end: u32, query: &Query) -> Option<(u32, Hits4)> {
        if !self.wide_triangles {
            return None;
        }
        let available = (end - entry).min(LANES as u32) as usize;
        let entries = &self.entries[entry as usize..entry as usize + available];
        let run = entries.iter().take_while(|e| e.triangle).count();
        if run < 2 {
            return None;
        }
        // Lanes past the run repeat the first triangle; their answers are
        // masked out.
        let lane = |i: usize| &entries[if i < run { i } else { 0 }].corners;
        // SAFETY: `wide_triangles` is set only where the processor has AVX.
        let hits = unsafe {
            watertight4(
                [lane(0), lane(1), lane(2), lane(3)],
                query.ray,
                &query.shear(),
                query.ray.t_max,
            )
        };
        let mask = hits.mask & ((1 << run) - 1);
        Some((run as u32, Hits4 { mask, ..hits }))
    }

    /// True when the primitive of entry `entry` of [`Self::entries`] lies
    /// in the query's ray interval.
    #[inline(always)]
    fn entry_occludes(&self, entry: u32, query: &Query) -> bool {
        let e = &self.entries[entry as usize];
        match e.corners() {
            Some(corners) => intersect_triangle(corners, query, query.ray.t_max).is_some(),
            None => self.occluded_by(e.number, query),
        }
    }

    /// True when primitive `index` lies in the query's ray interval.
    #[inline]
    fn occluded_by(&self, index: u32, query: &Query) -> bool {
        match self.refs[index as usize] {
            PrimitiveRef::Shape(i) => {
                let p = &self.primitives[i as usize];
                match self.transform(p.transform) {
                    Some(t) => p.shape.occluded(&t.ray_to_object(query.ray)),
                    None => p.shape.occluded(query.ray),
                }
            }
            PrimitiveRef::Triangle { .. } => self
                .intersect_primitive(index, query, query.ray.t_max)
                .is_some(),
        }
    }

    /// The box around every bounded primitive.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// How many primitives (shapes and mesh triangles) there are.
    pub fn len(&self) -> usize {
        self.refs.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.refs.is_empty()
    }

    /// The acceleration structure over the bounded primitives.
    pub fn accelerator(&self) -> &Accelerator {
        &self.accel
    }

    /// The closest hit in the ray's interval.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_with(ray, &mut QueryContext::default())
    }

    /// The closest hit, walking as `ctx` says the rays relate and adding
    /// the traversal work to its counters.
    pub fn intersect_with(&self, ray: &Ray, ctx: &mut QueryContext) -> Option<Hit> {
        let query = self.query(ray);
        let mut best: Option<Hit> = None;
        let mut t_max = ray.t_max;
        for &i in &self.unbounded {
            if let Some(h) = self.intersect_primitive(i, &query, t_max) {
                t_max = h.t;
                best = Some(Hit {
                    primitive: i,
                    shape_hit: h,
                });
            }
        }
        let mut clipped = *ray;
        clipped.t_max = t_max;
        self.accel
            .intersect_in_leaf_order(&clipped, ctx, |entries, t_max| {
                self.hit_leaf(entries, &query, t_max, &mut best)
            });
        best
    }

    /// True when anything lies in the ray's interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_with(ray, &mut QueryContext::default())
    }

    /// Any hit, walking as `ctx` says the rays relate and adding the
    /// traversal work to its counters.
    pub fn occluded_with(&self, ray: &Ray, ctx: &mut QueryContext) -> bool {
        let query = self.query(ray);
        self.unbounded.iter().any(|&i| self.occluded_by(i, &query))
            || self
                .accel
                .occluded_in_leaf_order(ray, ctx, |entries| self.leaf_occludes(entries, &query))
    }

    /// The world-space surface at a hit returned for `ray`.
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        let (local, shading_normal, material, transform) = match self.refs[hit.primitive as usize] {
            PrimitiveRef::Shape(i) => {
                let p = &self.primitives[i as usize];
                let transform = self.transform(p.transform);
                let object_ray = transform.map_or(*ray, |t| t.ray_to_object(ray));
                let s = p.shape.surface(&object_ray, &hit.shape_hit);
                (s, s.normal, p.material, transform)
            }
            PrimitiveRef::Triangle { instance, triangle } => {
                let m = &self.instances[instance as usize];
                let transform = self.transform(m.transform);
                let object_ray = transform.map_or(*ray, |t| t.ray_to_object(ray));
                let s =
                    self.meshes[m.mesh.0 as usize].surface(triangle, &object_ray, &hit.shape_hit);
                (s.local, s.shading_normal, m.material, transform)
            }
        };
        match transform {
            None => Surface::from_local(local, shading_normal, material),
            Some(t) => {
                let (point, point_error) =
                    t.point_with_error_to_world(local.point, local.point_error);
                Surface {
                    point,
                    point_error,
                    normal: t.normal_to_world(local.normal).normalize(),
                    shading_normal: t.normal_to_world(shading_normal).normalize(),
                    uv: local.uv,
                    dpdu: t.vector_to_world(local.dpdu),
                    dpdv: t.vector_to_world(local.dpdv),
                    material,
                }
            }
        }
    }
}

/// The mesh triangle with these corners hit by the query's ray, closer than
/// `t_max`.
#[inline(always)]
fn intersect_triangle([p0, p1, p2]: &[Vec3; 3], query: &Query, t_max: f64) -> Option<ShapeHit> {
    let mut ray = *query.ray;
    ray.t_max = t_max;
    watertight(*p0, *p1, *p2, &ray, &query.shear())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec2;
    use crate::math::random::Rng;
    use crate::shape::{Plane, Shape, Sphere, Triangle};

    fn scene_with(shape: Shape, transform: Transform) -> Objects {
        let mut objects = Objects::default();
        objects.add_primitive(shape, MaterialId(0), transform);
        objects
    }

    #[test]
    fn scaled_rotated_translated_sphere_is_hit_where_expected_with_correct_normals() {
        // A unit sphere stretched to an ellipsoid with semi-axes (2, 1, 1),
        // turned 90° about z (long axis now along y), moved to (5, 0, 0).
        let transform = Transform::translate(Vec3::new(5.0, 0.0, 0.0))
            .unwrap()
            .then_after(&Transform::rotate(Vec3::Z, 90.0).unwrap())
            .then_after(&Transform::scale(Vec3::new(2.0, 1.0, 1.0)).unwrap());
        let sphere = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap());
        let scene = scene_with(sphere, transform);
        let world = World::new(&scene);

        let down = Ray::new(Vec3::new(5.0, 10.0, 0.0), -Vec3::Y);
        let hit = world.intersect(&down).unwrap();
        assert!((hit.t() - 8.0).abs() < 1e-12);
        let s = world.surface(&down, &hit);
        assert!((s.point - Vec3::new(5.0, 2.0, 0.0)).length() < 1e-12);
        assert!((s.normal - Vec3::Y).length() < 1e-12);

        let across = Ray::new(Vec3::new(0.0, 0.0, 0.0), Vec3::X);
        let hit = world.intersect(&across).unwrap();
        assert!((hit.t() - 4.0).abs() < 1e-12);
        assert!((world.surface(&across, &hit).normal + Vec3::X).length() < 1e-12);

        // Off-axis: the ellipsoid x'² + (y/2)² + z² = 1 around (5, 0, 0) has
        // its normal along (x', y/4, z) at (x', y, z).
        let y = 3f64.sqrt();
        let oblique = Ray::new(Vec3::new(10.0, y, 0.0), -Vec3::X);
        let hit = world.intersect(&oblique).unwrap();
        let s = world.surface(&oblique, &hit);
        assert!((s.point - Vec3::new(5.5, y, 0.0)).length() < 1e-12);
        let expected = Vec3::new(0.5, y / 4.0, 0.0).normalize();
        assert!((s.normal - expected).length() < 1e-12);
        assert!(world.occluded(&oblique));
    }

    #[test]
    fn transformed_bounds_contain_the_transformed_shape() {
        let transform = Transform::rotate(Vec3::new(1.0, 1.0, 1.0), 30.0)
            .unwrap()
            .then_after(&Transform::scale(Vec3::new(3.0, 0.5, 1.0)).unwrap());
        let sphere = Shape::Sphere(Sphere::new(Vec3::new(1.0, 0.0, 0.0), 1.0).unwrap());
        let scene = scene_with(sphere, transform);
        let world = World::new(&scene);
        assert_eq!(world.accel.stats().references, 1);
        let bounds = transform.bounds_to_world(&scene.primitives[0].shape.bounds());
        let mut rng = crate::math::random::Rng::new(5);
        let mut hits = 0;
        for _ in 0..500 {
            let target = rng.unit_vector() * 3.0;
            let ray = Ray::new(Vec3::splat(20.0), target - Vec3::splat(20.0));
            if let Some(hit) = world.intersect(&ray) {
                let p = world.surface(&ray, &hit).point;
                assert!(p.cmpge(bounds.min - 1e-9).all() && p.cmple(bounds.max + 1e-9).all());
                hits += 1;
            }
        }
        assert!(hits > 50);
    }

    #[test]
    fn tangents_stay_derivatives_of_uv_and_perpendicular_to_the_normal_under_a_transform() {
        use crate::shape::{AxisBox, Cylinder};
        let transform = Transform::translate(Vec3::new(0.5, -1.0, 2.0))
            .unwrap()
            .then_after(&Transform::rotate(Vec3::new(1.0, 2.0, 0.5), 40.0).unwrap())
            .then_after(&Transform::scale(Vec3::new(3.0, 0.5, -1.5)).unwrap());
        let shapes = [
            Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap()),
            Shape::Cylinder(Cylinder::new(1.0, 2.0, true).unwrap()),
            Shape::AxisBox(AxisBox::new(Vec3::splat(-1.0), Vec3::ONE).unwrap()),
        ];
        let mut rng = crate::math::random::Rng::new(8);
        for shape in shapes {
            let scene = scene_with(shape, transform);
            let world = World::new(&scene);
            let mut checked = 0;
            for _ in 0..300 {
                let target =
                    transform.point_to_world(rng.point_in(Vec3::splat(-0.9), Vec3::splat(0.9)));
                let origin = target + 20.0 * rng.unit_vector();
                let ray = Ray::new(origin, target - origin);
                let Some(hit) = world.intersect(&ray) else {
                    continue;
                };
                let s = world.surface(&ray, &hit);
                for (tangent, along) in [(s.dpdu, DVec2::X), (s.dpdv, DVec2::Y)] {
                    assert!(tangent.dot(s.normal).abs() < 1e-12 * tangent.length());
                    if tangent.length() < 1e-3 {
                        continue;
                    }
                    let h = 1e-6;
                    let back_origin = s.point + h * tangent + 0.01 * s.normal;
                    let back = Ray::new(back_origin, -s.normal);
                    let Some(moved) = world.intersect(&back) else {
                        continue;
                    };
                    let change = world.surface(&back, &moved).uv - s.uv;
                    if moved.shape_hit.part != hit.shape_hit.part
                        || change.abs().max_element() > 0.5
                    {
                        continue;
                    }
                    assert!((change / h - along).abs().max_element() < 1e-3, "{change}");
                    checked += 1;
                }
            }
            assert!(checked > 200, "{checked}");
        }
    }

    #[test]
    fn every_structure_finds_the_same_hits_in_a_scene_of_shapes_meshes_and_instances() {
        // Spheres and triangle shapes (one moved) among a random triangle
        // soup, the soup again as a moved and scaled instance, and a
        // plane: the BVH and the kd-tree hand their queries the corners in
        // leaf order, the others per slot; all must agree with brute force
        // on the primitive, `t` and the barycentrics, and the surface
        // rebuilt from the primitive itself must lie where the ray is at
        // `t` (which the corners, shared by all, cannot fake).
        let mut rng = Rng::new(5);
        let mut scene = Objects::default();
        let m = MaterialId(0);
        for _ in 0..40 {
            let centre = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
            let sphere = Sphere::new(centre, rng.range(0.05, 0.4)).unwrap();
            scene.add_primitive(Shape::Sphere(sphere), m, Transform::IDENTITY);
        }
        for transform in [
            Transform::IDENTITY,
            Transform::scale(Vec3::splat(0.5)).unwrap(),
        ] {
            let [a, b, c] = [0; 3].map(|_| rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0)));
            let triangle = Shape::Triangle(Triangle::new(a, b, c).unwrap());
            scene.add_primitive(triangle, m, transform);
        }
        let positions: Vec<Vec3> = (0..600)
            .map(|_| rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0)))
            .collect();
        let triangles: Vec<[u32; 3]> = (0..200)
            .map(|i| {
                let near = |k: u32| (3 * i + k) % 600;
                [near(0), near(1), near(2)]
            })
            .collect();
        let mesh = scene.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
        scene.add_mesh_instance(mesh, m, Transform::IDENTITY);
        let moved = Transform::translate(Vec3::new(1.0, -2.0, 0.5))
            .unwrap()
            .then_after(&Transform::scale(Vec3::new(0.5, 1.5, 1.0)).unwrap());
        scene.add_mesh_instance(mesh, m, moved);
        let plane = Plane::new(Vec3::new(0.0, -6.0, 0.0), Vec3::Y).unwrap();
        scene.add_primitive(Shape::Plane(plane), m, Transform::IDENTITY);

        let oracle = World::build(&scene, AccelKind::Linear);
        let rays: Vec<Ray> = (0..2000)
            .map(|i| {
                let origin = rng.point_in(Vec3::splat(-6.0), Vec3::splat(6.0));
                let dir = rng.unit_vector();
                if i % 2 == 0 {
                    Ray::new(origin, dir)
                } else {
                    Ray::segment(origin, dir, rng.range(0.5, 6.0))
                }
            })
            .collect();
        for kind in AccelKind::ALL {
            let world = World::build(&scene, kind);
            let mut hits = 0;
            for ray in &rays {
                let expected = oracle.intersect(ray);
                assert_eq!(world.intersect(ray), expected, "{kind:?} {ray:?}");
                assert_eq!(world.occluded(ray), expected.is_some(), "{kind:?}");
                if let Some(hit) = expected {
                    let point = world.surface(ray, &hit).point;
                    assert!(
                        (point - ray.at(hit.t())).length() < 1e-9,
                        "{kind:?} {ray:?}"
                    );
                }
                // Primitive 42 is the plane, which every downward ray meets.
                hits += usize::from(expected.is_some_and(|h| h.primitive != 42));
            }
            assert!(hits > rays.len() / 4, "{kind:?}: {hits} hits");
        }
    }

    #[test]
    fn unbounded_planes_are_tested_beside_the_structure() {
        let plane = Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Y).unwrap());
        let scene = scene_with(plane, Transform::IDENTITY);
        let world = World::new(&scene);
        assert_eq!(world.accel.stats().references, 0);
        let ray = Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, -1.0, 0.0));
        assert_eq!(world.intersect(&ray).unwrap().t(), 1.0);
        assert!(world.occluded(&ray));
        let up = Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
        assert!(world.intersect(&up).is_none() && !world.occluded(&up));
    }
}
