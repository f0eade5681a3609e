//! The bottom level of the world: one acceleration structure per instanced
//! mesh, over its triangles in the mesh's own space, built once however
//! many times the mesh is placed. An instance is then one entry of the top
//! level with its world-space box; a ray that reaches it is carried into
//! mesh space once (unnormalised, so `t` means the same point in both) and
//! walks the mesh's structure with the same watertight test, on the same
//! corners, as a triangle placed directly: the same hits.

use super::lanes::LanesOf;
use rayon::prelude::*;

use super::entry::{Entry, Query, leaf_hit, leaf_occludes};
use super::{PARALLEL_CHUNK, build_structure};
use std::ops::Range;

use crate::accel::kernel::{self, Kernel, KernelTask};
use crate::accel::{
    AccelKind, AccelerationStructure, Accelerator, AnyLeaves, ClosestLeaves, QueryContext,
};
use crate::math::{Aabb, Ray};
use crate::mesh::TriangleMesh;
use crate::shape::{ShapeHit, clipped_triangle_bounds};

/// A mesh's triangles under their own acceleration structure, in mesh
/// space.
#[derive(Debug)]
pub(super) struct MeshStructure {
    accel: Accelerator,
    /// The triangles' corners, in the order the structure's queries name
    /// them; each entry's number is the triangle's index in the mesh.
    entries: Vec<Entry>,
    /// The box around the mesh, in mesh space.
    bounds: Aabb,
}

impl MeshStructure {
    /// Builds a structure of `kind` over the mesh's triangles (a kd-tree
    /// clips each triangle to its cells).
    pub(super) fn build(mesh: &TriangleMesh, kind: AccelKind) -> Self {
        let boxes: Vec<Aabb> = (0..mesh.len() as u32)
            .into_par_iter()
            .with_min_len(PARALLEL_CHUNK)
            .map(|t| mesh.triangle_bounds(t))
            .collect();
        let bounds = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
        let accel = build_structure(kind, &boxes, &|t, cell| {
            clipped_triangle_bounds(mesh.corners(t), cell)
        });
        let order = accel.leaf_order();
        let count = order.map_or(boxes.len(), <[u32]>::len);
        let entries = (0..count)
            .into_par_iter()
            .with_min_len(PARALLEL_CHUNK)
            .map(|entry| {
                let triangle = order.map_or(entry as u32, |o| o[entry]);
                Entry::triangle(triangle, mesh.corners(triangle))
            })
            .collect();
        Self {
            accel,
            entries,
            bounds,
        }
    }

    /// The box around the mesh, in mesh space.
    pub(super) fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The closest triangle hit by `ray` (in mesh space) closer than
    /// `t_max`: its index in the mesh and the hit. The walk runs in the
    /// kernel of `ctx`'s backend.
    #[inline]
    pub(super) fn intersect(
        &self,
        ray: &Ray,
        t_max: f64,
        ctx: &mut QueryContext,
    ) -> Option<(u32, ShapeHit)> {
        let mut clipped = *ray;
        clipped.t_max = t_max;
        let query = Query::new(&clipped, true);
        let mut best = None;
        let leaves = MeshLeaves {
            entries: &self.entries,
            query: &query,
            best: &mut best,
        };
        kernel::run(
            ctx.backend,
            Walk::<_, false>(&self.accel, &clipped, ctx, leaves),
        );
        best
    }

    /// True when a triangle lies in the interval of `ray` (in mesh space).
    /// The walk runs in the kernel of `ctx`'s backend.
    #[inline]
    pub(super) fn occluded(&self, ray: &Ray, ctx: &mut QueryContext) -> bool {
        let query = Query::new(ray, true);
        let leaves = MeshLeaves {
            entries: &self.entries,
            query: &query,
            best: &mut None,
        };
        kernel::run(ctx.backend, Walk::<_, true>(&self.accel, ray, ctx, leaves))
    }
}

/// A mesh's walk as a kernel's task: any hit with `ANY`, the closest
/// otherwise.
struct Walk<'q, L, const ANY: bool>(&'q Accelerator, &'q Ray, &'q mut QueryContext, L);

impl<L: ClosestLeaves> KernelTask for Walk<'_, L, false> {
    type Output = Option<f64>;
    #[inline(always)]
    fn run<K: Kernel>(self) -> Option<f64> {
        let Walk(accel, ray, ctx, leaves) = self;
        accel.closest_with::<K>(ray, ctx, leaves)
    }
}

impl<L: AnyLeaves> KernelTask for Walk<'_, L, true> {
    type Output = bool;
    #[inline(always)]
    fn run<K: Kernel>(self) -> bool {
        let Walk(accel, ray, ctx, leaves) = self;
        accel.any_with::<K>(ray, ctx, leaves)
    }
}

/// The leaf tests of a mesh's triangles: the closest hit goes to `best`.
struct MeshLeaves<'q> {
    entries: &'q [Entry],
    query: &'q Query<'q>,
    best: &'q mut Option<(u32, ShapeHit)>,
}

impl ClosestLeaves for MeshLeaves<'_> {
    #[inline(always)]
    fn closest<K: Kernel>(&mut self, range: Range<u32>, t_max: f64) -> Option<f64> {
        let best = &mut *self.best;
        let number = best.map_or(u32::MAX, |(triangle, _)| triangle);
        leaf_hit::<LanesOf<K>>(
            self.entries,
            range,
            self.query,
            (t_max, number),
            |_, _, _| None,
            |triangle, hit| *best = Some((triangle, hit)),
        )
    }
}

impl AnyLeaves for MeshLeaves<'_> {
    #[inline(always)]
    fn occludes<K: Kernel>(&mut self, range: Range<u32>) -> bool {
        leaf_occludes::<LanesOf<K>>(self.entries, range, self.query, |_, _| false).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::math::random::Rng;

    #[test]
    fn every_structure_of_a_mesh_finds_the_triangle_brute_force_finds() {
        let mut rng = Rng::new(31);
        let positions: Vec<Vec3> = (0..300)
            .map(|_| rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0)))
            .collect();
        let triangles: Vec<[u32; 3]> = (0..100).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let mesh = TriangleMesh::new(positions, triangles).unwrap();
        let boxes: Vec<Aabb> = (0..mesh.len() as u32)
            .map(|t| mesh.triangle_bounds(t))
            .collect();
        let oracle = MeshStructure::build(&mesh, AccelKind::Linear);
        let mut hits = 0;
        for kind in AccelKind::ALL {
            let structure = MeshStructure::build(&mesh, kind);
            let valid = match &structure.accel {
                Accelerator::KdTree(tree) => tree
                    .validate_clipped(&boxes, &|t: u32, cell: &Aabb| {
                        clipped_triangle_bounds(mesh.corners(t), cell)
                    }),
                other => other.validate(&boxes),
            };
            valid.unwrap_or_else(|why| panic!("{kind:?}: {why}"));
            for _ in 0..500 {
                let origin = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
                let ray = Ray::new(origin, rng.unit_vector());
                let mut ctx = QueryContext::default();
                let expected = oracle.intersect(&ray, ray.t_max, &mut ctx);
                let actual = structure.intersect(&ray, ray.t_max, &mut ctx);
                assert_eq!(actual.map(|h| h.1.t), expected.map(|h| h.1.t), "{kind:?}");
                let direct = (0..mesh.len() as u32)
                    .filter_map(|t| mesh.intersect(t, &ray, &crate::shape::RayShear::new(&ray)))
                    .map(|h| h.t)
                    .fold(None, |a: Option<f64>, t| Some(a.map_or(t, |a| a.min(t))));
                assert_eq!(expected.map(|h| h.1.t), direct);
                for backend in crate::accel::Backend::available() {
                    let mut ctx = QueryContext {
                        backend,
                        ..QueryContext::default()
                    };
                    let hit = structure.intersect(&ray, ray.t_max, &mut ctx);
                    assert_eq!(hit.map(|h| h.1.t), expected.map(|h| h.1.t), "{kind:?}");
                    assert_eq!(
                        structure.occluded(&ray, &mut ctx),
                        expected.is_some(),
                        "{kind:?} {backend:?}"
                    );
                }
                hits += usize::from(expected.is_some());
            }
        }
        assert!(hits > 200, "{hits}");
    }
}
