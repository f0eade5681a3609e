//! A subtree's primitives during the build: their indices and their `f32`
//! boxes in two arrays reordered together, so binning and partitioning read
//! the boxes in order. Reading them through the index array instead costs
//! one scattered load per primitive per level (figures in
//! docs/performance-log.md, BVH build).

use super::fbox::FBox;

/// Parallel slices: `boxes[i]` is the box of primitive `ids[i]`.
pub(super) struct Prims<'a> {
    /// The primitives' indices.
    pub(super) ids: &'a mut [u32],
    /// Their boxes.
    pub(super) boxes: &'a mut [FBox],
}

impl<'a> Prims<'a> {
    /// How many primitives.
    pub(super) fn len(&self) -> usize {
        self.ids.len()
    }

    /// The first `mid` primitives and the rest.
    pub(super) fn split_at(self, mid: usize) -> (Prims<'a>, Prims<'a>) {
        let (left_ids, right_ids) = self.ids.split_at_mut(mid);
        let (left_boxes, right_boxes) = self.boxes.split_at_mut(mid);
        (
            Prims {
                ids: left_ids,
                boxes: left_boxes,
            },
            Prims {
                ids: right_ids,
                boxes: right_boxes,
            },
        )
    }

    /// Exchanges primitives `i` and `j`.
    #[inline]
    pub(super) fn swap(&mut self, i: usize, j: usize) {
        self.ids.swap(i, j);
        self.boxes.swap(i, j);
    }

    /// Puts the primitive at `order[i]` at `i`, in place; `order` must be
    /// a permutation of `0..len` and is used up (each cycle of the
    /// permutation is followed once, marking its entries done).
    pub(super) fn permute(&mut self, order: &mut [usize]) {
        for start in 0..order.len() {
            if order[start] == start {
                continue;
            }
            let (id, bounds) = (self.ids[start], self.boxes[start]);
            let mut at = start;
            loop {
                let from = std::mem::replace(&mut order[at], at);
                if from == start {
                    (self.ids[at], self.boxes[at]) = (id, bounds);
                    break;
                }
                self.ids[at] = self.ids[from];
                self.boxes[at] = self.boxes[from];
                at = from;
            }
        }
    }
}

/// The box around the centres of `boxes`.
pub(super) fn centre_bounds(boxes: &[FBox]) -> FBox {
    boxes
        .iter()
        .fold(FBox::EMPTY, |c, p| c.union_point(p.centre()))
}

/// The box around `boxes` and the box around their centres.
pub(super) fn bounds_of(boxes: &[FBox]) -> (FBox, FBox) {
    boxes.iter().fold((FBox::EMPTY, FBox::EMPTY), |(b, c), p| {
        (b.union(p), c.union_point(p.centre()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Aabb, Vec3};

    fn unit_at(x: f64) -> FBox {
        FBox::outward(&Aabb::new(
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x + 1.0, 1.0, 1.0),
        ))
    }

    #[test]
    fn ids_and_boxes_move_together() {
        let mut ids = [10, 11, 12, 13];
        let mut boxes = [0.0, 1.0, 2.0, 3.0].map(unit_at);
        let mut prims = Prims {
            ids: &mut ids,
            boxes: &mut boxes,
        };
        prims.swap(0, 3);
        assert_eq!(prims.ids, [13, 11, 12, 10]);
        prims.permute(&mut [1, 0, 3, 2]);
        assert_eq!(prims.ids, [11, 13, 10, 12]);
        prims.permute(&mut [2, 0, 3, 1]);
        assert_eq!(prims.ids, [10, 11, 12, 13]);
        let xs: Vec<f32> = prims.boxes.iter().map(|b| b.min.x).collect();
        assert_eq!(xs, [0.0, 1.0, 2.0, 3.0]);
        let (left, right) = prims.split_at(1);
        assert_eq!((left.len(), right.len()), (1, 3));
        let (bounds, centres) = bounds_of(right.boxes);
        assert_eq!((bounds.min.x, bounds.max.x), (1.0, 4.0));
        assert_eq!((centres.min.x, centres.max.x), (1.5, 3.5));
    }
}
