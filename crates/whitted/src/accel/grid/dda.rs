//! The 3D digital differential analyser of Amanatides and Woo ("A Fast Voxel
//! Traversal Algorithm for Ray Tracing", Eurographics 1987): the cells a ray
//! passes through, front to back, each with the parameter interval the ray
//! spends in it. Written once, as an iterator, for both the closest-hit and
//! the any-hit query.
//!
//! Each crossing is computed afresh from the cell coordinate, as
//! `(boundary - origin) / dir`, against the same boundaries the cells were
//! filled by ([`Lattice::boundary`]), so no error accumulates along a long
//! walk.

use super::lattice::Lattice;
use crate::math::{Ray, Vec3};

/// The cells along a ray: yields `(flat cell index, t_enter, t_exit)`.
///
/// The intervals are contiguous (each `t_enter` is the previous `t_exit`) and
/// non-decreasing, start where the ray enters the grid box (or at `t_min`)
/// and end where it leaves (or at `t_max`). A cell the ray only grazes may
/// come with an empty interval.
#[derive(Clone, Debug)]
pub(crate) struct DdaCells<'a> {
    lattice: &'a Lattice,
    origin: Vec3,
    inv_dir: Vec3,
    /// Direction of travel per axis: -1, 0 or +1.
    step: [i32; 3],
    /// The current cell's coordinates.
    cell: [u32; 3],
    /// Where the ray leaves the current cell's slab, per axis (∞ when it
    /// never does inside the grid).
    t_next: [f64; 3],
    t_enter: f64,
    t_far: f64,
    done: bool,
}

impl<'a> DdaCells<'a> {
    /// The walk of `ray`, within its interval, through `lattice`.
    pub(crate) fn new(lattice: &'a Lattice, ray: &Ray) -> Self {
        let mut walk = Self {
            lattice,
            origin: ray.origin,
            inv_dir: ray.inv_dir,
            step: [0; 3],
            cell: [0; 3],
            t_next: [f64::INFINITY; 3],
            t_enter: 0.0,
            t_far: 0.0,
            done: true,
        };
        if lattice.bounds().is_empty() {
            return walk;
        }
        let Some((t_near, t_far)) = lattice.bounds().intersect_ray(ray) else {
            return walk;
        };
        for axis in 0..3 {
            let d = ray.dir[axis];
            walk.step[axis] = if d > 0.0 {
                1
            } else if d < 0.0 {
                -1
            } else {
                0
            };
            let x = if walk.step[axis] == 0 {
                ray.origin[axis]
            } else {
                ray.origin[axis] + t_near * d
            };
            // On a boundary, start in the cell the ray is heading into.
            walk.cell[axis] = if walk.step[axis] < 0 {
                lattice.first_reaching(axis, x)
            } else {
                lattice.last_reaching(axis, x)
            };
            walk.t_next[axis] = walk.crossing(axis);
        }
        walk.t_enter = t_near;
        walk.t_far = t_far;
        walk.done = false;
        walk
    }

    /// Where the ray leaves the current cell's slab on `axis`: ∞ when it does
    /// not move on that axis or the cell is the last one it meets there.
    fn crossing(&self, axis: usize) -> f64 {
        let k = self.cell[axis];
        let plane = match self.step[axis] {
            1 if k + 1 < self.lattice.resolution()[axis] => k + 1,
            -1 if k > 0 => k,
            _ => return f64::INFINITY,
        };
        (self.lattice.boundary(axis, plane) - self.origin[axis]) * self.inv_dir[axis]
    }
}

impl Iterator for DdaCells<'_> {
    type Item = (usize, f64, f64);

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let axis = if self.t_next[0] <= self.t_next[1] && self.t_next[0] <= self.t_next[2] {
            0
        } else if self.t_next[1] <= self.t_next[2] {
            1
        } else {
            2
        };
        let t_enter = self.t_enter;
        // Rounding may put a crossing a hair before the entry; never go back.
        let t_exit = self.t_next[axis].min(self.t_far).max(t_enter);
        let item = (self.lattice.flat_index(self.cell), t_enter, t_exit);
        match self.cell[axis].checked_add_signed(self.step[axis]) {
            Some(next) if self.t_next[axis] < self.t_far => {
                self.cell[axis] = next;
                self.t_enter = t_exit;
                self.t_next[axis] = self.crossing(axis);
            }
            _ => self.done = true,
        }
        Some(item)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Aabb;
    use crate::math::random::Rng;

    /// Cells one unit wide over [0, 4] x [0, 4] x [0, 4].
    fn cubes() -> Lattice {
        Lattice::new(Aabb::new(Vec3::ZERO, Vec3::splat(4.0)), [4, 4, 4])
    }

    fn flat(x: u32, y: u32, z: u32) -> usize {
        (x + 4 * (y + 4 * z)) as usize
    }

    fn walk(lattice: &Lattice, ray: &Ray) -> Vec<(usize, f64, f64)> {
        DdaCells::new(lattice, ray).collect()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    fn assert_walk(actual: &[(usize, f64, f64)], expected: &[(usize, f64, f64)]) {
        assert_eq!(actual.len(), expected.len(), "{actual:?}");
        for (a, e) in actual.iter().zip(expected) {
            assert!(
                a.0 == e.0 && close(a.1, e.1) && close(a.2, e.2),
                "{actual:?} != {expected:?}"
            );
        }
    }

    #[test]
    fn ray_along_an_axis_visits_each_cell_in_order() {
        let ray = Ray::new(Vec3::new(-1.0, 0.5, 2.5), Vec3::X);
        let expected: Vec<_> = (0..4)
            .map(|x| (flat(x, 0, 2), f64::from(x) + 1.0, f64::from(x) + 2.0))
            .collect();
        assert_walk(&walk(&cubes(), &ray), &expected);

        let back = Ray::new(Vec3::new(0.5, 3.5, 9.0), -2.0 * Vec3::Z);
        let expected: Vec<_> = (0..4)
            .rev()
            .map(|z| {
                (
                    flat(0, 3, z),
                    4.0 - 0.5 * f64::from(z),
                    4.5 - 0.5 * f64::from(z),
                )
            })
            .collect();
        assert_walk(&walk(&cubes(), &back), &expected);
    }

    #[test]
    fn diagonal_ray_steps_the_axis_crossed_first() {
        // Crosses x = 1, 2, 3 at t = 1, 2, 3 and y = 1, 2 at t = 1.5, 3.5.
        let ray = Ray::new(Vec3::new(0.0, 0.25, 0.5), Vec3::new(1.0, 0.5, 0.0));
        let expected = [
            (flat(0, 0, 0), 0.0, 1.0),
            (flat(1, 0, 0), 1.0, 1.5),
            (flat(1, 1, 0), 1.5, 2.0),
            (flat(2, 1, 0), 2.0, 3.0),
            (flat(3, 1, 0), 3.0, 3.5),
            (flat(3, 2, 0), 3.5, 4.0),
        ];
        assert_walk(&walk(&cubes(), &ray), &expected);
    }

    #[test]
    fn ray_starting_inside_begins_at_t_min_in_its_own_cell() {
        let ray = Ray::new(Vec3::new(1.5, 2.5, 3.5), Vec3::new(0.0, -1.0, 0.0));
        let expected = [
            (flat(1, 2, 3), 0.0, 0.5),
            (flat(1, 1, 3), 0.5, 1.5),
            (flat(1, 0, 3), 1.5, 2.5),
        ];
        assert_walk(&walk(&cubes(), &ray), &expected);
    }

    #[test]
    fn ray_starting_on_a_boundary_starts_in_the_cell_ahead() {
        let forward = Ray::new(Vec3::new(2.0, 0.5, 0.5), Vec3::X);
        let expected = [(flat(2, 0, 0), 0.0, 1.0), (flat(3, 0, 0), 1.0, 2.0)];
        assert_walk(&walk(&cubes(), &forward), &expected);
        let backward = Ray::new(Vec3::new(2.0, 0.5, 0.5), -Vec3::X);
        let expected = [(flat(1, 0, 0), 0.0, 1.0), (flat(0, 0, 0), 1.0, 2.0)];
        assert_walk(&walk(&cubes(), &backward), &expected);
    }

    #[test]
    fn ray_in_a_boundary_plane_walks_one_side_of_it() {
        // y = 1 and z = 3 are both boundaries; the walk keeps to the cells
        // above them (boxes touching the plane are stored on both sides).
        let ray = Ray::new(Vec3::new(-1.0, 1.0, 3.0), Vec3::X);
        let expected: Vec<_> = (0..4)
            .map(|x| (flat(x, 1, 3), f64::from(x) + 1.0, f64::from(x) + 2.0))
            .collect();
        assert_walk(&walk(&cubes(), &ray), &expected);
        let on_face = Ray::new(Vec3::new(-1.0, 4.0, 4.0), Vec3::X);
        assert_eq!(walk(&cubes(), &on_face).len(), 4);
        assert!(
            walk(&cubes(), &on_face)
                .iter()
                .all(|c| c.0 >= flat(0, 3, 3))
        );
    }

    #[test]
    fn rays_that_miss_the_grid_yield_nothing() {
        let l = cubes();
        let misses = [
            Ray::new(Vec3::new(-1.0, 5.0, 0.5), Vec3::X),
            Ray::new(Vec3::new(-1.0, 0.5, 0.5), -Vec3::X),
            Ray::new(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, -1.0, 1.0)),
            Ray::segment(Vec3::new(-2.0, 0.5, 0.5), Vec3::X, 1.5),
        ];
        for ray in misses {
            assert!(walk(&l, &ray).is_empty(), "{ray:?}");
        }
        let nothing = Lattice::new(Aabb::EMPTY, [1, 1, 1]);
        assert!(walk(&nothing, &Ray::new(Vec3::ZERO, Vec3::X)).is_empty());
    }

    #[test]
    fn zero_direction_components_never_step_and_segments_stop_early() {
        let ray = Ray::segment(Vec3::new(0.5, -1.0, 1.5), Vec3::new(0.0, 2.0, -0.0), 1.25);
        let expected = [(flat(0, 0, 1), 0.5, 1.0), (flat(0, 1, 1), 1.0, 1.25)];
        assert_walk(&walk(&cubes(), &ray), &expected);
    }

    #[test]
    fn flat_grid_is_crossed_in_one_cell() {
        let l = Lattice::new(Aabb::new(Vec3::ZERO, Vec3::new(2.0, 2.0, 0.0)), [2, 2, 1]);
        let cells = walk(&l, &Ray::new(Vec3::new(1.5, 0.5, 1.0), -Vec3::Z));
        assert_eq!(cells.len(), 1);
        assert_eq!(cells[0].0, 1);
        assert!(close(cells[0].1, 1.0) && close(cells[0].2, 1.0));
    }

    #[test]
    fn random_walks_are_contiguous_and_each_interval_lies_in_its_cell() {
        let mut rng = Rng::new(11);
        let bounds = Aabb::new(Vec3::new(-3.0, 1.0, 2.0), Vec3::new(5.0, 2.0, 9.0));
        let l = Lattice::new(bounds, [7, 3, 11]);
        for _ in 0..2000 {
            let origin = rng.point_in(Vec3::splat(-10.0), Vec3::splat(15.0));
            let ray = Ray::new(origin, rng.point_in(bounds.min, bounds.max) - origin);
            let cells = walk(&l, &ray);
            let (near, far) = bounds.intersect_ray(&ray).unwrap();
            assert_eq!(cells[0].1, near);
            assert_eq!(cells.last().unwrap().2, far);
            for pair in cells.windows(2) {
                assert_eq!(pair[0].2, pair[1].1, "{ray:?}");
                assert_ne!(pair[0].0, pair[1].0);
            }
            for &(cell, t_enter, t_exit) in &cells {
                assert!(t_enter <= t_exit);
                let p = ray.at(0.5 * (t_enter + t_exit));
                let r = l.overlapped(&Aabb::new(p, p).expanded(1e-9)).unwrap();
                assert!(
                    r.coordinates().any(|c| l.flat_index(c) == cell),
                    "{ray:?} in {cell}"
                );
            }
            // Every point of the ray inside the grid is in the cell whose
            // interval holds its parameter.
            for _ in 0..20 {
                let t = rng.range(near, far);
                let (cell, _, _) = cells
                    .iter()
                    .find(|c| c.1 <= t && t <= c.2)
                    .copied()
                    .unwrap();
                let p = ray.at(t);
                let r = l.overlapped(&Aabb::new(p, p).expanded(1e-9)).unwrap();
                assert!(r.coordinates().any(|c| l.flat_index(c) == cell));
            }
        }
    }
}
