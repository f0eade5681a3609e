//! The binned surface area heuristic: a node's centroids go into equal
//! bins along each axis, and one sweep per axis prices the planes between
//! bins.

use super::build::Halves;
use super::fbox::FBox;
use super::prims::{Prims, centre_bounds};
use glam::Vec3A;

/// The most bins per axis.
pub(super) const MAX_BINS: usize = 64;

/// 2²³: from it up to 2²⁴, `f32` values are the integers, and an integer
/// `k` below 2¹⁶ is `2²³ + k` in the low bits.
const ROUND_BASE: f32 = (1 << 23) as f32;

/// 2²³ − ½ (exact in `f32`).
const ROUND: f32 = ROUND_BASE - 0.5;

/// How a node's centroids map to bins: the same `f32` arithmetic for the
/// binning and for the partition, so both put a primitive in the same bin.
#[derive(Clone, Copy, Debug)]
pub(super) struct Binning {
    /// The centroids' lowest corner.
    low: Vec3A,
    /// Bins per unit length, per axis; 0 on an axis without spread, where
    /// every centroid lands in bin 0.
    scale: Vec3A,
    /// 2²³ plus the last bin's index, in every lane.
    last: Vec3A,
    bins: usize,
}

impl Binning {
    fn new(centroids: &FBox, bins: usize) -> Self {
        let extent = centroids.max - centroids.min;
        let scale = Vec3A::splat(bins as f32) / extent;
        // An extent of 0, too small to divide by, infinite or NaN.
        let spread = extent.cmpgt(Vec3A::ZERO) & scale.is_finite_mask();
        Self {
            low: centroids.min,
            scale: Vec3A::select(spread, scale, Vec3A::ZERO),
            last: Vec3A::splat(ROUND_BASE + (bins - 1) as f32),
            bins,
        }
    }

    /// The bins of centroid `c` along the three axes, in one set of SIMD
    /// operations (three scalar `f64` ones per centroid took more
    /// instructions than the rest of the binning).
    #[inline]
    pub(super) fn bins_of(&self, c: Vec3A) -> [usize; 3] {
        // The position in bins, `x`, lies in `0..=bins`. Adding 2²³ − ½
        // rounds `x − ½` to an integer held in the low mantissa bits (from
        // 2²³ on, `f32` values are the integers): the integer part of `x`,
        // but for exact integers, which may fall one bin lower, so the bins
        // start half a bin early, for the binning and the partition alike.
        // Below 2²³ (`x` < ½) the sum is not rounded: the maximum makes it
        // bin 0, as it does a NaN (`maxps` keeps its second operand), from
        // an overflowed difference on an axis without spread. Tried Rust's
        // saturating float-to-integer casts, one per lane: more
        // instructions, see docs/performance-log.md (BVH build).
        let rounded = ((c - self.low) * self.scale + Vec3A::splat(ROUND))
            .max(Vec3A::splat(ROUND_BASE))
            .min(self.last);
        rounded.to_array().map(|r| (r.to_bits() & 0xFFFF) as usize)
    }
}

/// A candidate split: the bins of one axis from `first_right_bin` on go
/// right.
pub(super) struct Plane {
    /// 0, 1 or 2 for x, y, z.
    pub(super) axis: usize,
    /// How the node's centroids were binned.
    pub(super) binning: Binning,
    /// The first bin on the right.
    pub(super) first_right_bin: usize,
    /// Σ half area × count over both sides (before dividing by the parent's
    /// half area).
    pub(super) cost: f32,
    /// The box around the bins on the left.
    pub(super) left: FBox,
    /// The box around the bins on the right.
    pub(super) right: FBox,
}

/// The bins' contents and the sweep's partial sums, reused from node to node
/// of one thread: fixed arrays, so no node allocates.
pub(super) struct Bins {
    /// Per axis, the box around each bin's primitives.
    bounds: [[FBox; MAX_BINS]; 3],
    /// Per axis, how many primitives each bin holds.
    counts: [[u32; MAX_BINS]; 3],
    /// The box around bins `i..` of the axis being swept.
    right_bounds: [FBox; MAX_BINS],
    /// Half area × count of bins `i..` of the axis being swept.
    right_cost: [f32; MAX_BINS],
}

impl Bins {
    /// Empty bins.
    pub(super) fn new() -> Self {
        Self {
            bounds: [[FBox::EMPTY; MAX_BINS]; 3],
            counts: [[0; MAX_BINS]; 3],
            right_bounds: [FBox::EMPTY; MAX_BINS],
            right_cost: [0.0; MAX_BINS],
        }
    }

    /// The cheapest plane between bins that leaves primitives on both sides,
    /// if the centroids are spread along any axis.
    /// `bins` is at most [`MAX_BINS`]; `centroid_bounds` is the box around
    /// the centres of `boxes`.
    pub(super) fn best_plane(
        &mut self,
        bins: usize,
        boxes: &[FBox],
        centroid_bounds: &FBox,
    ) -> Option<Plane> {
        // Small nodes need fewer bins to find their planes: fewer bins
        // save build time and barely change the SAH cost (figures in
        // docs/performance-log.md, BVH build).
        let bins = bins.min(2 * boxes.len());
        let binning = Binning::new(centroid_bounds, bins);
        self.fill(boxes, &binning);
        let n = boxes.len() as u32;
        let mut best: Option<Plane> = None;
        for axis in 0..3 {
            let mut plane = Plane {
                axis,
                binning,
                first_right_bin: 0,
                cost: f32::INFINITY,
                left: FBox::EMPTY,
                right: FBox::EMPTY,
            };
            let bounds = &self.bounds[axis][..bins];
            let counts = &self.counts[axis][..bins];
            // Right to left: the box and cost of everything from bin i on.
            let (mut area_box, mut count) = (FBox::EMPTY, 0);
            for i in (1..bins).rev() {
                area_box = area_box.union(&bounds[i]);
                count += counts[i];
                self.right_bounds[i] = area_box;
                self.right_cost[i] = area_box.half_area() * count as f32;
            }
            // Left to right, pairing with the right side of each plane.
            let (mut area_box, mut count) = (FBox::EMPTY, 0);
            for i in 1..bins {
                area_box = area_box.union(&bounds[i - 1]);
                count += counts[i - 1];
                if count == 0 || count == n {
                    continue;
                }
                let cost = area_box.half_area() * count as f32 + self.right_cost[i];
                if cost < plane.cost {
                    plane.cost = cost;
                    plane.first_right_bin = i;
                    plane.left = area_box;
                    plane.right = self.right_bounds[i];
                }
            }
            if plane.first_right_bin > 0 && best.as_ref().is_none_or(|b| plane.cost < b.cost) {
                best = Some(plane);
            }
        }
        best
    }

    /// Puts every primitive in its bin along each axis, in one pass (one
    /// pass per axis took more instructions).
    ///
    /// Tried binning large nodes in parallel chunks: no faster, see
    /// docs/performance-log.md (BVH build).
    fn fill(&mut self, boxes: &[FBox], binning: &Binning) {
        let bins = binning.bins;
        for axis in 0..3 {
            self.bounds[axis][..bins].fill(FBox::EMPTY);
            self.counts[axis][..bins].fill(0);
        }
        for b in boxes {
            let bin = binning.bins_of(b.centre());
            for ((bounds, counts), bin) in self.bounds.iter_mut().zip(&mut self.counts).zip(bin) {
                bounds[bin] = bounds[bin].union(b);
                counts[bin] += 1;
            }
        }
    }
}

impl Plane {
    /// Moves the primitives left of the plane to the front; returns how
    /// many, with the sides' boxes from the bins and their centroid boxes.
    ///
    /// The loop has no branch on the side: every primitive is swapped
    /// with the first one known to go right (or with itself), and only the
    /// count of those going left moves on its side. Which side a primitive
    /// goes to is as good as random, so the usual two-ended partition's
    /// branch on it is mispredicted (figures in docs/performance-log.md,
    /// BVH build). The centroid boxes are gathered after, in order.
    pub(super) fn partition(&self, prims: &mut Prims) -> Halves {
        let mut mid = 0;
        for i in 0..prims.len() {
            let bin = self.binning.bins_of(prims.boxes[i].centre())[self.axis];
            prims.swap(i, mid);
            mid += usize::from(bin < self.first_right_bin);
        }
        let (left, right) = prims.boxes.split_at(mid);
        Halves {
            mid,
            left: (self.left, centre_bounds(left)),
            right: (self.right, centre_bounds(right)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::conformance::random_boxes;
    use crate::math::random::Rng;

    fn fboxes(seed: u64, n: usize) -> Vec<FBox> {
        random_boxes(&mut Rng::new(seed), n, 100.0, 2.0)
            .iter()
            .map(FBox::outward)
            .collect()
    }

    #[test]
    fn bins_are_in_range_and_ordered_like_the_centres() {
        let boxes = fboxes(1, 2000);
        let centres = centre_bounds(&boxes);
        for bins in [2, 7, 16, MAX_BINS] {
            let binning = Binning::new(&centres, bins);
            assert_eq!(binning.bins_of(centres.min), [0; 3]);
            assert_eq!(binning.bins_of(centres.max), [bins - 1; 3]);
            let mut by_x: Vec<Vec3A> = boxes.iter().map(FBox::centre).collect();
            by_x.sort_by(|a, b| a.x.total_cmp(&b.x));
            let x_bins: Vec<usize> = by_x.iter().map(|&c| binning.bins_of(c)[0]).collect();
            assert!(x_bins.windows(2).all(|w| w[0] <= w[1]));
            assert!(x_bins.iter().all(|&b| b < bins));
            // Every bin gets some of 2000 uniform centres.
            assert_eq!(x_bins.last(), Some(&(bins - 1)));
            assert!((0..bins).all(|b| x_bins.contains(&b)), "{bins} bins");
        }
    }

    #[test]
    fn an_axis_without_spread_puts_everything_in_bin_0() {
        let mut centres = centre_bounds(&fboxes(2, 50));
        centres.max.y = centres.min.y;
        let binning = Binning::new(&centres, 16);
        assert_eq!(binning.bins_of(centres.max)[1], 0);
        assert_eq!(binning.bins_of(centres.max)[0], 15);
    }

    #[test]
    fn the_partition_moves_exactly_the_bins_left_of_the_plane() {
        for (seed, n) in [(3, 13), (4, 100), (5, 5000)] {
            let boxes = fboxes(seed, n);
            let mut bins = Bins::new();
            let centres = centre_bounds(&boxes);
            let plane = bins.best_plane(16, &boxes, &centres).unwrap();
            let goes_left =
                |b: &FBox| plane.binning.bins_of(b.centre())[plane.axis] < plane.first_right_bin;
            let mut ids: Vec<u32> = (0..n as u32).collect();
            let mut moved = boxes.clone();
            let halves = plane.partition(&mut Prims {
                ids: &mut ids,
                boxes: &mut moved,
            });
            assert_eq!(halves.mid, boxes.iter().filter(|b| goes_left(b)).count());
            let mut seen = ids.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>());
            for (i, (&id, b)) in ids.iter().zip(&moved).enumerate() {
                assert_eq!(b.to_aabb(), boxes[id as usize].to_aabb());
                assert_eq!(goes_left(b), i < halves.mid);
            }
            let (left, right) = moved.split_at(halves.mid);
            let union = |s: &[FBox]| s.iter().fold(FBox::EMPTY, |a, b| a.union(b)).to_aabb();
            assert_eq!(halves.left.0.to_aabb(), union(left));
            assert_eq!(halves.right.0.to_aabb(), union(right));
            assert_eq!(halves.left.1.to_aabb(), centre_bounds(left).to_aabb());
            assert_eq!(halves.right.1.to_aabb(), centre_bounds(right).to_aabb());
        }
    }
}
