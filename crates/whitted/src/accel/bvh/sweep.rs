//! The exact surface area heuristic for small nodes: along each axis the
//! primitives are sorted by centre and every plane between two neighbours
//! is priced.
//!
//! Binning a node costs the same number of bins to clear and sweep however
//! few primitives it holds, and most nodes of a tree are small, so nodes of
//! up to [`SWEEP_MAX`] primitives are swept exactly instead, which takes
//! fewer instructions (figures, and other limits tried, in
//! docs/performance-log.md, BVH build). The exact sweep also prices every
//! plane the bins would, so its choice is never worse.

use super::build::Halves;
use super::fbox::FBox;
use super::prims::{Prims, bounds_of};
use glam::Vec3A;

/// Nodes of at most this many primitives are swept exactly.
pub(super) const SWEEP_MAX: usize = 12;

/// Reorders `prims` (2 to [`SWEEP_MAX`] of them) by centre along the axis
/// of the cheapest plane between neighbours and returns its cost (Σ half
/// area × count over both sides) with the sides. `None`, with `prims`
/// unchanged, when no plane has a finite cost (infinite or NaN boxes).
pub(super) fn best_split(prims: &mut Prims) -> Option<(f32, Halves)> {
    let n = prims.len();
    debug_assert!((2..=SWEEP_MAX).contains(&n));
    let boxes = &prims.boxes[..n];
    if let [a, b] = boxes {
        // Every plane between two primitives parts them the same way.
        let cost = a.half_area() + b.half_area();
        let side = |p: &FBox| (*p, FBox::EMPTY.union_point(p.centre()));
        return (cost < f32::INFINITY).then(|| {
            (
                cost,
                Halves {
                    mid: 1,
                    left: side(a),
                    right: side(b),
                },
            )
        });
    }
    let mut centres = [Vec3A::ZERO; SWEEP_MAX];
    for (c, b) in centres.iter_mut().zip(boxes) {
        *c = b.centre();
    }
    let mut orders = [[0usize; SWEEP_MAX]; 3];
    let mut right_cost = [0f32; SWEEP_MAX];
    let mut best_cost = f32::INFINITY;
    let mut best: Option<(usize, usize)> = None;
    for (axis, order) in orders.iter_mut().enumerate() {
        let order = &mut order[..n];
        sort_by_centre(order, &centres, axis);
        let mut side = FBox::EMPTY;
        for i in (1..n).rev() {
            side = side.union(&boxes[order[i]]);
            right_cost[i] = side.half_area() * (n - i) as f32;
        }
        let mut side = FBox::EMPTY;
        for i in 1..n {
            side = side.union(&boxes[order[i - 1]]);
            let cost = side.half_area() * i as f32 + right_cost[i];
            if cost < best_cost {
                best_cost = cost;
                best = Some((axis, i));
            }
        }
    }
    let (axis, mid) = best?;
    prims.permute(&mut orders[axis][..n]);
    let (left, right) = prims.boxes.split_at(mid);
    Some((
        best_cost,
        Halves {
            mid,
            left: bounds_of(left),
            right: bounds_of(right),
        },
    ))
}

/// `order` becomes `0..order.len()` sorted by centre along `axis`, stably,
/// by insertion (the lists are short). Tried placing each by its rank,
/// counted without branches: slower, see docs/performance-log.md (BVH build).
fn sort_by_centre(order: &mut [usize], centres: &[Vec3A], axis: usize) {
    for i in 0..order.len() {
        let key = centres[i][axis];
        let mut j = i;
        while j > 0 && centres[order[j - 1]][axis] > key {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = i;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::conformance::random_boxes;
    use crate::math::random::Rng;
    use crate::math::{Aabb, Vec3};

    /// The cheapest cost over every axis and every prefix of the primitives
    /// sorted by centre along it, in `f64`.
    fn brute_force_cost(boxes: &[Aabb]) -> f64 {
        let half_area = |b: &Aabb| b.surface_area() / 2.0;
        let mut best = f64::INFINITY;
        for axis in 0..3 {
            let mut sorted = boxes.to_vec();
            sorted.sort_by(|a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
            for mid in 1..sorted.len() {
                let (left, right) = sorted.split_at(mid);
                let union = |s: &[Aabb]| s.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
                let cost = half_area(&union(left)) * mid as f64
                    + half_area(&union(right)) * (sorted.len() - mid) as f64;
                best = best.min(cost);
            }
        }
        best
    }

    fn swept(boxes: &[Aabb]) -> (Vec<u32>, Option<(f32, Halves)>) {
        let mut ids: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut fboxes: Vec<FBox> = boxes.iter().map(FBox::outward).collect();
        let found = best_split(&mut Prims {
            ids: &mut ids,
            boxes: &mut fboxes,
        });
        (ids, found)
    }

    #[test]
    fn the_sweep_finds_the_cheapest_plane_between_sorted_neighbours() {
        let mut rng = Rng::new(7);
        for n in 2..=SWEEP_MAX {
            for _ in 0..20 {
                // Coordinates on a coarse grid: exact in f32, so the f64
                // brute force prices the same boxes.
                let boxes: Vec<Aabb> = random_boxes(&mut rng, n, 8.0, 3.0)
                    .iter()
                    .map(|b| Aabb::new(b.min.round(), b.max.round() + Vec3::ONE))
                    .collect();
                let (ids, found) = swept(&boxes);
                let (cost, halves) = found.expect("finite boxes have a plane");
                let expected = brute_force_cost(&boxes);
                assert!(
                    (f64::from(cost) - expected).abs() <= 1e-5 * expected,
                    "{n} boxes: {cost} against {expected}"
                );
                // The sides hold what they say, and every primitive once.
                let mut seen = ids.clone();
                seen.sort_unstable();
                assert_eq!(seen, (0..n as u32).collect::<Vec<_>>());
                let side = |s: &[u32]| {
                    s.iter()
                        .fold(Aabb::EMPTY, |a, &i| a.union(&boxes[i as usize]))
                };
                assert_eq!(halves.left.0.to_aabb(), side(&ids[..halves.mid]));
                assert_eq!(halves.right.0.to_aabb(), side(&ids[halves.mid..]));
            }
        }
    }

    #[test]
    fn identical_boxes_cost_as_much_as_a_leaf() {
        for n in [2, 5, SWEEP_MAX] {
            let boxes = vec![Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)); n];
            let (_, found) = swept(&boxes);
            let (cost, halves) = found.unwrap();
            // Half area 11, whichever way they are parted: the caller's
            // leaf test (cost + area >= n area) keeps them together.
            assert_eq!(cost, 11.0 * n as f32);
            assert!(halves.mid > 0 && halves.mid < n);
        }
    }

    #[test]
    fn boxes_without_a_finite_area_have_no_plane() {
        let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let huge = Aabb::new(Vec3::splat(-1e300), Vec3::splat(1e300));
        assert!(swept(&[huge, unit]).1.is_none());
        assert!(swept(&[huge, huge, unit]).1.is_none());
        let (ids, found) = swept(&[unit, huge, unit]);
        assert!(found.is_none());
        assert_eq!(ids, [0, 1, 2], "left as it was");
    }

    #[test]
    fn two_boxes_are_parted() {
        let a = Aabb::new(Vec3::new(4.0, 0.0, 0.0), Vec3::new(5.0, 1.0, 1.0));
        let b = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 1.0));
        let (ids, found) = swept(&[a, b]);
        let (cost, halves) = found.unwrap();
        assert_eq!(cost, 3.0 + 5.0);
        assert_eq!(halves.mid, 1);
        assert_eq!(halves.left.0.to_aabb(), a);
        assert_eq!(
            halves.right.1.to_aabb(),
            Aabb::new(b.centroid(), b.centroid())
        );
        assert_eq!(ids, [0, 1]);
    }
}
