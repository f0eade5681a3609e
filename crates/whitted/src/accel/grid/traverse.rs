//! The two queries on a grid, both on the same walk ([`DdaCells`]): the
//! closest hit, which may stop once its best hit lies within the cells
//! walked, and any hit, which stops at the first occluder.
//!
//! A primitive met in a cell is first culled by its own box against the ray
//! (clipped to the closest hit so far), exactly as brute force does, so both
//! pick among the same candidates: a shape may report a hit an ulp outside
//! its box, as at a vertex shared by many triangles, and skipping the box
//! test would return that hit where brute force does not.

use super::Grid;
use super::dda::DdaCells;
use crate::accel::QueryContext;
use crate::accel::mailbox::Mailbox;
use crate::math::Ray;

impl Grid {
    /// The closest hit (see [`crate::accel`]): the cells along the ray are
    /// visited front to back, and a hit is final once the walk has passed it.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64> {
        let counters = &mut ctx.counters;
        let mut closest = None;
        let mut clipped = *ray;
        let mut mailbox = Mailbox::new();
        for (cell, _, t_exit) in DdaCells::new(&self.lattice, ray) {
            counters.nodes += 1;
            for &i in self.cell(cell) {
                if !mailbox.first_visit(i) || self.culled(i, &clipped) {
                    continue;
                }
                counters.primitives += 1;
                if let Some(t) = hit(i, clipped.t_max) {
                    clipped.t_max = t;
                    closest = Some(t);
                }
            }
            // A primitive of this cell may be hit beyond it, where a
            // primitive of a later cell may be hit closer still; one hit
            // at the cell's very end may tie with one of the next cell,
            // which the caller may prefer (a lower number).
            if clipped.t_max < t_exit {
                break;
            }
        }
        closest
    }

    /// Any hit (see [`crate::accel`]).
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut occludes: impl FnMut(u32) -> bool,
    ) -> bool {
        let counters = &mut ctx.counters;
        let mut mailbox = Mailbox::new();
        for (cell, _, _) in DdaCells::new(&self.lattice, ray) {
            counters.nodes += 1;
            for &i in self.cell(cell) {
                if mailbox.first_visit(i) && !self.culled(i, ray) {
                    counters.primitives += 1;
                    if occludes(i) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// True when `ray` misses primitive `i`'s box.
    #[inline]
    fn culled(&self, i: u32, ray: &Ray) -> bool {
        self.bounds[i as usize].intersect_ray(ray).is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::math::{Aabb, Vec3};

    /// Ten slabs crossing the whole scene along x, among small boxes.
    fn slabs_among_small_boxes() -> Vec<Aabb> {
        let mut rng = Rng::new(9);
        let mut boxes: Vec<Aabb> = (0..10)
            .map(|i| {
                let y = f64::from(i);
                Aabb::new(Vec3::new(0.0, y, 0.0), Vec3::new(10.0, y + 0.5, 10.0))
            })
            .collect();
        boxes.extend((0..2000).map(|_| {
            let c = rng.point_in(Vec3::ZERO, Vec3::splat(10.0));
            Aabb::new(c, c + Vec3::splat(0.05))
        }));
        boxes
    }

    #[test]
    fn mailboxing_tests_a_primitive_spanning_many_cells_once() {
        let boxes = slabs_among_small_boxes();
        let grid = Grid::build(&boxes);
        let ray = Ray::new(Vec3::new(-1.0, 5.25, 5.0), Vec3::X);
        let memberships: usize = DdaCells::new(&grid.lattice, &ray)
            .map(|(cell, _, _)| grid.cell(cell).len())
            .sum();
        let mut tested = vec![0; boxes.len()];
        let mut ctx = QueryContext::default();
        let found = grid.occluded(&ray, &mut ctx, |i| {
            tested[i as usize] += 1;
            false
        });
        assert!(!found);
        assert!(tested.iter().all(|&n| n <= 1));
        assert_eq!(ctx.counters.primitives, tested.iter().sum::<u64>());
        // The slab at y = 5 lies along the whole walk: one test instead of
        // one per cell.
        assert_eq!(tested[5], 1);
        assert!(ctx.counters.nodes >= u64::from(grid.resolution()[0]));
        assert!(ctx.counters.primitives + ctx.counters.nodes - 1 <= memberships as u64);
    }

    #[test]
    fn closest_hit_keeps_walking_past_a_hit_beyond_its_cell() {
        // A long box starting in the first cell whose surface is hit far
        // away, and a small one hit nearer, in a later cell.
        let boxes = [
            Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(10.0, 1.0, 1.0)),
            Aabb::new(Vec3::new(5.0, 0.0, 0.0), Vec3::new(5.5, 1.0, 1.0)),
            Aabb::new(Vec3::splat(9.0), Vec3::splat(10.0)),
        ];
        let params = crate::accel::GridBuildParams {
            density: 1000.0,
            ..Default::default()
        };
        let grid = Grid::build_with(&boxes, &params);
        assert!(grid.resolution()[0] > 4);
        let ray = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        let hit_at = [10.0, 6.0, f64::INFINITY];
        let mut ctx = QueryContext::default();
        let t = grid.intersect(&ray, &mut ctx, |i, t_max| {
            let t = hit_at[i as usize];
            (t < t_max).then_some(t)
        });
        assert_eq!(t, Some(6.0));
        assert_eq!(ctx.counters.primitives, 2);
        // Up to the cell that starts at the hit, where a tie may lie.
        let cells_to_the_hit = DdaCells::new(&grid.lattice, &ray)
            .take_while(|c| c.1 <= 6.0)
            .count();
        assert_eq!(ctx.counters.nodes, cells_to_the_hit as u64);
    }
}
