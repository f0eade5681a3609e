//! The slab test of a node's [`WIDTH`] child boxes against one ray, in
//! `f32` SIMD: two four-lane halves with glam's `Vec4` (SSE on x86-64,
//! NEON or scalar elsewhere), or one eight-lane AVX register where the
//! processor has AVX (`slabs_avx`). Both compute the same operations in
//! the same order, so they agree bit for bit (the AVX set-up computes the
//! [`Planes`] its own way, tested against [`Planes::new`]); the argument
//! that the test is conservative is in the documentation of `traverse`.

use glam::Vec4;

use super::node::{BvhNode, WIDTH, round_down, round_up};
use crate::math::Ray;

/// `1 − 8u` and `1 + 8u` with `u = 2⁻²⁴`: the widening factors (see the
/// documentation of `traverse`), exact in `f32`.
pub(super) const SHRINK: f32 = 1.0 - 1.0 / (1 << 21) as f32;
pub(super) const GROW: f32 = 1.0 + 1.0 / (1 << 21) as f32;

/// The inverse direction of an axis that must not cull (see the
/// documentation of `traverse`).
pub(super) const NEVER_CULLS: f32 = (1u128 << 100) as f32;

/// What the slab test needs of a ray, per axis, computed once per ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Planes {
    /// The origin rounded for the entry parameter.
    pub entry_origin: [f32; 3],
    /// The origin rounded for the exit parameter.
    pub exit_origin: [f32; 3],
    /// The inverse direction in `f32`.
    pub inv_dir: [f32; 3],
    /// The rows of `BvhNode::bounds` the ray enters and leaves through,
    /// per axis: the max face first where the direction is negative.
    pub rows: [(usize, usize); 3],
    /// The start of the interval, rounded down.
    pub t_min: f32,
}

impl Planes {
    /// The planes of `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let mut planes = Self {
            entry_origin: [0.0; 3],
            exit_origin: [0.0; 3],
            inv_dir: [0.0; 3],
            rows: [(0, 3), (1, 4), (2, 5)],
            t_min: round_down(ray.t_min),
        };
        for axis in 0..3 {
            let (o, i) = (ray.origin[axis], ray.inv_dir[axis]);
            let (down, up, negative) = (round_down(o), round_up(o), i.is_sign_negative());
            let (entry, exit, inv) = if i.is_finite() && i.abs() > f64::from(f32::MAX) {
                // Beyond `f32`: an axis that culls only the empty box.
                (f32::MAX, -f32::MAX, NEVER_CULLS)
            } else if negative {
                (down, up, i as f32)
            } else {
                (up, down, i as f32)
            };
            planes.entry_origin[axis] = entry;
            planes.exit_origin[axis] = exit;
            planes.inv_dir[axis] = inv;
            if negative && inv < 0.0 {
                planes.rows[axis] = (axis + 3, axis);
            }
        }
        planes
    }
}

/// A way to run the slab test of a node's children for one ray.
pub(crate) trait SlabTest {
    /// Prepares the test for `ray` (its [`Planes`]).
    fn new(ray: &Ray) -> Self;

    /// Which of the node's children the ray may meet within
    /// `(t_min, t_max]` (bit `i` for slot `i`), and lower bounds on where
    /// it enters them.
    fn test(&self, node: &BvhNode, t_max: f32) -> (u32, [f32; WIDTH]);
}

/// `a > b ? a : b` per lane: `b` when `a` is NaN. On x86-64 glam's `max`
/// is `maxps`, which is exactly that (and its scalar fallback returns the
/// number too); a `select` written out was not turned into `maxps`.
#[inline(always)]
fn max_keeping(a: Vec4, b: Vec4) -> Vec4 {
    if cfg!(target_arch = "x86_64") {
        a.max(b)
    } else {
        Vec4::select(a.cmpgt(b), a, b)
    }
}

/// `a < b ? a : b` per lane: `b` when `a` is NaN (`minps` on x86-64).
#[inline(always)]
fn min_keeping(a: Vec4, b: Vec4) -> Vec4 {
    if cfg!(target_arch = "x86_64") {
        a.min(b)
    } else {
        Vec4::select(a.cmplt(b), a, b)
    }
}

/// The test on two halves of four lanes.
pub(crate) struct Halves {
    entry_origin: [Vec4; 3],
    exit_origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    rows: [(usize, usize); 3],
    t_min: Vec4,
}

impl Halves {
    /// Half `half` (0 or 1) of the test.
    #[inline(always)]
    fn half(&self, node: &BvhNode, t_max: Vec4, half: usize) -> (u32, Vec4) {
        let lanes = |row: usize| Vec4::from_slice(&node.bounds[row][4 * half..]);
        let mut near = self.t_min;
        let mut far = t_max;
        for axis in 0..3 {
            let (enter, exit) = self.rows[axis];
            let t_enter = (lanes(enter) - self.entry_origin[axis]) * self.inv_dir[axis];
            let t_exit = (lanes(exit) - self.exit_origin[axis]) * self.inv_dir[axis];
            near = max_keeping(t_enter, near);
            far = min_keeping(t_exit, far);
        }
        let near = (near * SHRINK).min(near * GROW);
        let far = (far * SHRINK).max(far * GROW);
        (near.cmple(far).bitmask(), near)
    }
}

impl SlabTest for Halves {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let planes = Planes::new(ray);
        Self {
            entry_origin: planes.entry_origin.map(Vec4::splat),
            exit_origin: planes.exit_origin.map(Vec4::splat),
            inv_dir: planes.inv_dir.map(Vec4::splat),
            rows: planes.rows,
            t_min: Vec4::splat(planes.t_min),
        }
    }

    #[inline(always)]
    fn test(&self, node: &BvhNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        let far = Vec4::splat(t_max);
        let (low_mask, low) = self.half(node, far, 0);
        let (high_mask, high) = self.half(node, far, 1);
        let mut near = [0.0; WIDTH];
        low.write_to_slice(&mut near[..4]);
        high.write_to_slice(&mut near[4..]);
        (low_mask | high_mask << 4, near)
    }
}

const _: () = assert!(WIDTH == 8, "the tests are written for eight lanes");

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::math::{Aabb, Vec3};

    /// A node of eight random boxes (some empty), and rays from all around
    /// it, some starting inside boxes or with zero direction components.
    pub(in crate::accel::bvh) fn random_cases(seed: u64) -> Vec<(BvhNode, Ray, f32)> {
        let mut rng = Rng::new(seed);
        let mut cases = Vec::new();
        for _ in 0..2000 {
            let mut node = BvhNode::default();
            for slot in 0..WIDTH {
                if rng.range(0.0, 1.0) < 0.15 {
                    continue;
                }
                let c = rng.point_in(Vec3::splat(-5.0), Vec3::splat(5.0));
                let half = rng.point_in(Vec3::ZERO, Vec3::splat(2.0));
                node.set_child(slot, &Aabb::new(c - half, c + half), slot as u32, 1);
            }
            let origin = rng.point_in(Vec3::splat(-8.0), Vec3::splat(8.0));
            let mut dir = rng.unit_vector();
            if rng.range(0.0, 1.0) < 0.2 {
                dir[rng.below(3) as usize] = 0.0;
            }
            let t_max = if rng.range(0.0, 1.0) < 0.5 {
                f32::INFINITY
            } else {
                rng.range(0.0, 10.0) as f32
            };
            cases.push((node, Ray::new(origin, dir), t_max));
        }
        cases
    }

    /// Whether the test `S` keeps every child of `node` that the `f64`
    /// test meets, with a near end not past the `f64` entry; returns how
    /// many children it kept. Boxes the `f64` test enters or leaves within
    /// `2⁻¹⁰⁰` of the origin are not judged: there the `f32` parameters are
    /// subnormal, the one case the documentation of `traverse` leaves
    /// aside.
    pub(in crate::accel::bvh) fn assert_conservative<S: SlabTest>(
        node: &BvhNode,
        ray: &Ray,
        t_max: f32,
    ) -> u32 {
        let (mask, near) = S::new(ray).test(node, t_max);
        let mut bounded = *ray;
        bounded.t_max = f64::from(t_max);
        let tiny = |t: f64| t != 0.0 && t.abs() < 2f64.powi(-100);
        for slot in (0..WIDTH).filter(|&s| node.is_used(s)) {
            if let Some((enter, exit)) = node.child_bounds(slot).intersect_ray(&bounded)
                && !tiny(enter)
                && !tiny(exit)
            {
                assert!(mask & 1 << slot != 0, "{ray:?} slot {slot} t_max {t_max}");
                assert!(
                    f64::from(near[slot]) <= enter,
                    "{ray:?} slot {slot}: near {} after {enter}",
                    near[slot]
                );
            }
        }
        mask
    }

    /// One box, and a ray that starts on one of its faces, a step of the
    /// bits inside or outside it: at seven scales from 1e-20 to 1e30, some
    /// rays grazing the face, some parallel to it, some with a direction
    /// 1e30 times too short or too long; intervals from zero, from `-0`,
    /// from just after zero and from before it.
    pub(in crate::accel::bvh) fn face_cases(seed: u64) -> Vec<(BvhNode, Ray, f32)> {
        let mut rng = Rng::new(seed);
        (0..20_000)
            .map(|case| {
                let scale = [1e-20, 1e-3, 1.0, 1e3, 1e7, 1e15, 1e30][case % 7];
                let centre = rng.point_in(Vec3::splat(-scale), Vec3::splat(scale));
                let half = rng.point_in(Vec3::splat(scale * 1e-7), Vec3::splat(scale * 0.5));
                let mut node = BvhNode::default();
                node.set_child(0, &Aabb::new(centre - half, centre + half), 0, 1);
                let stored = node.child_bounds(0);
                let mut origin = rng.point_in(stored.min, stored.max);
                let axis = rng.below(3) as usize;
                let face = if rng.below(2) == 0 {
                    stored.min[axis]
                } else {
                    stored.max[axis]
                };
                origin[axis] = [face, face.next_up(), face.next_down()][rng.below(3) as usize];
                let mut dir = rng.unit_vector();
                match rng.below(4) {
                    0 => dir[axis] *= 1e-9,
                    1 => dir[axis] = 0.0,
                    _ => {}
                }
                if rng.below(5) == 0 {
                    dir *= [1e-30, 1e30][rng.below(2) as usize];
                }
                let mut ray = Ray::new(origin, dir);
                ray.t_min = [0.0, -0.0, 1e-9, -1e-3][rng.below(4) as usize];
                let t_max = [f32::INFINITY, 1e-6, 1.0][rng.below(3) as usize];
                (node, ray, t_max)
            })
            .collect()
    }

    #[test]
    fn a_box_the_ray_meets_is_never_culled() {
        let kept: u32 = random_cases(3)
            .iter()
            .chain(&face_cases(47))
            .map(|(node, ray, t_max)| assert_conservative::<Halves>(node, ray, *t_max).count_ones())
            .sum();
        assert!(kept > 10_000, "{kept}");
    }
}
