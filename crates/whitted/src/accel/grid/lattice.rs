//! Where the grid's cells lie in space: the grid box cut into a number of
//! equal slabs per axis, and the one definition of every cell boundary that
//! building, walking and validating all share, so they can never disagree
//! about which side of a boundary a point is on.

use crate::math::{Aabb, Vec3};

/// How far a primitive's box is grown, relative to the magnitude of the grid's
/// coordinates, before it is sorted into cells. Rounding makes the walk's
/// idea of where the ray is err by a few ulps of the coordinates (more for
/// far-away origins); this margin, a million times larger, keeps a primitive
/// in every cell the walk may believe its surface to be in.
const MEMBERSHIP_MARGIN: f64 = 1e-9;

/// The grid box and its cells.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Lattice {
    bounds: Aabb,
    resolution: [u32; 3],
    width: Vec3,
    margin: Vec3,
}

/// The cells a box overlaps: an inclusive range of cell coordinates per axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CellRange {
    /// Smallest cell coordinate per axis.
    pub(crate) low: [u32; 3],
    /// Largest cell coordinate per axis.
    pub(crate) high: [u32; 3],
}

impl CellRange {
    /// How many cells it holds.
    pub(crate) fn len(&self) -> u64 {
        (0..3)
            .map(|a| u64::from(self.high[a] - self.low[a]) + 1)
            .product()
    }

    /// Its cells as (x, y, z) coordinates, x fastest.
    pub(crate) fn coordinates(&self) -> impl Iterator<Item = [u32; 3]> + use<> {
        let (low, high) = (self.low, self.high);
        (low[2]..=high[2]).flat_map(move |z| {
            (low[1]..=high[1]).flat_map(move |y| (low[0]..=high[0]).map(move |x| [x, y, z]))
        })
    }

    /// True when it holds the cell at `cell`.
    pub(crate) fn contains(&self, cell: [u32; 3]) -> bool {
        (0..3).all(|a| self.low[a] <= cell[a] && cell[a] <= self.high[a])
    }
}

impl Lattice {
    /// `bounds` cut into `resolution` cells per axis. An axis whose extent is
    /// not a positive finite number gets one cell whatever is asked.
    pub(crate) fn new(bounds: Aabb, resolution: [u32; 3]) -> Self {
        let extent = bounds.extent();
        let mut cells = [1; 3];
        let mut width = Vec3::ZERO;
        let mut margin = Vec3::ZERO;
        for axis in 0..3 {
            if extent[axis].is_finite() && extent[axis] > 0.0 {
                cells[axis] = resolution[axis].max(1);
                width[axis] = extent[axis] / f64::from(cells[axis]);
                let magnitude = bounds.min[axis].abs().max(bounds.max[axis].abs());
                margin[axis] = MEMBERSHIP_MARGIN * magnitude.max(extent[axis]);
            }
        }
        Self {
            bounds,
            resolution: cells,
            width,
            margin,
        }
    }

    /// The grid box.
    pub(crate) fn bounds(&self) -> &Aabb {
        &self.bounds
    }

    /// Cells per axis.
    pub(crate) fn resolution(&self) -> [u32; 3] {
        self.resolution
    }

    /// How many cells in all.
    pub(crate) fn cell_count(&self) -> usize {
        self.resolution.iter().map(|&r| r as usize).product()
    }

    /// Every cell.
    pub(crate) fn all_cells(&self) -> CellRange {
        CellRange {
            low: [0; 3],
            high: self.resolution.map(|r| r - 1),
        }
    }

    /// The position in the flat cell arrays of the cell at `cell`.
    pub(crate) fn flat_index(&self, cell: [u32; 3]) -> usize {
        let [rx, ry, _] = self.resolution.map(|r| r as usize);
        cell[0] as usize + rx * (cell[1] as usize + ry * cell[2] as usize)
    }

    /// The plane between cells `k - 1` and `k` on `axis` (`k = 0` and
    /// `k = resolution` are the grid's faces). Rays and boxes are sorted
    /// against these values and no others.
    pub(crate) fn boundary(&self, axis: usize, k: u32) -> f64 {
        if k == 0 {
            self.bounds.min[axis]
        } else if k >= self.resolution[axis] {
            self.bounds.max[axis]
        } else {
            self.bounds.min[axis] + f64::from(k) * self.width[axis]
        }
    }

    /// A first guess at the cell holding `x` on `axis`, in range.
    fn guess(&self, axis: usize, x: f64) -> u32 {
        let last = self.resolution[axis] - 1;
        if self.width[axis] == 0.0 {
            return 0;
        }
        // Saturating cast: NaN gives 0, huge values the last cell.
        let k = ((x - self.bounds.min[axis]) / self.width[axis]).floor() as u32;
        k.min(last)
    }

    /// The first cell on `axis` whose closed slab reaches up to `x`: the
    /// smallest `k` with `boundary(k + 1) >= x`, or the last cell if none.
    pub(crate) fn first_reaching(&self, axis: usize, x: f64) -> u32 {
        let last = self.resolution[axis] - 1;
        let mut k = self.guess(axis, x);
        while k > 0 && self.boundary(axis, k) >= x {
            k -= 1;
        }
        while k < last && self.boundary(axis, k + 1) < x {
            k += 1;
        }
        k
    }

    /// The last cell on `axis` whose closed slab reaches down to `x`: the
    /// largest `k` with `boundary(k) <= x`, or the first cell if none.
    pub(crate) fn last_reaching(&self, axis: usize, x: f64) -> u32 {
        let last = self.resolution[axis] - 1;
        let mut k = self.guess(axis, x);
        while k < last && self.boundary(axis, k + 1) <= x {
            k += 1;
        }
        while k > 0 && self.boundary(axis, k) > x {
            k -= 1;
        }
        k
    }

    /// The cells whose closed boxes meet `b` (a box touching a cell's face
    /// is in that cell), or `None` for an empty box. Unknown (NaN) corners
    /// count as unbounded.
    pub(crate) fn overlapped(&self, b: &Aabb) -> Option<CellRange> {
        if b.is_empty() {
            return None;
        }
        let mut low = [0; 3];
        let mut high = [0; 3];
        for axis in 0..3 {
            let lo = if b.min[axis].is_nan() {
                f64::NEG_INFINITY
            } else {
                b.min[axis]
            };
            let hi = if b.max[axis].is_nan() {
                f64::INFINITY
            } else {
                b.max[axis]
            };
            low[axis] = self.first_reaching(axis, lo);
            high[axis] = self.last_reaching(axis, hi);
            if low[axis] > high[axis] {
                return None;
            }
        }
        Some(CellRange { low, high })
    }

    /// The cells a primitive with box `b` is stored in: those `b` overlaps
    /// once grown by the membership margin.
    pub(crate) fn membership(&self, b: &Aabb) -> Option<CellRange> {
        if b.is_empty() {
            return None;
        }
        self.overlapped(&Aabb {
            min: b.min - self.margin,
            max: b.max + self.margin,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cells() -> Lattice {
        Lattice::new(Aabb::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0)), [4, 2, 1])
    }

    #[test]
    fn boundaries_are_evenly_spaced_and_end_on_the_faces() {
        let l = unit_cells();
        let xs: Vec<f64> = (0..=4).map(|k| l.boundary(0, k)).collect();
        assert_eq!(xs, [0.0, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(l.boundary(2, 1), 1.0);
        assert_eq!(l.cell_count(), 8);
        assert_eq!(l.flat_index([3, 1, 0]), 7);
    }

    #[test]
    fn a_box_touching_a_cell_face_is_in_both_cells() {
        let l = unit_cells();
        let b = Aabb::new(Vec3::new(1.0, 0.2, 0.2), Vec3::new(2.0, 0.5, 0.5));
        let r = l.overlapped(&b).unwrap();
        assert_eq!((r.low, r.high), ([0, 0, 0], [2, 0, 0]));
        let point = Aabb::new(Vec3::new(3.0, 1.0, 0.0), Vec3::new(3.0, 1.0, 0.0));
        let r = l.overlapped(&point).unwrap();
        assert_eq!((r.low, r.high), ([2, 0, 0], [3, 1, 0]));
        assert_eq!(r.len(), 4);
        assert_eq!(r.coordinates().count(), 4);
    }

    #[test]
    fn membership_is_a_superset_of_overlap() {
        let l = unit_cells();
        let b = Aabb::new(Vec3::new(1.5, 0.5, 0.5), Vec3::new(2.0 - 1e-12, 0.6, 0.6));
        let overlap = l.overlapped(&b).unwrap();
        let member = l.membership(&b).unwrap();
        assert_eq!((overlap.low, overlap.high), ([1, 0, 0], [1, 0, 0]));
        assert_eq!((member.low, member.high), ([1, 0, 0], [2, 0, 0]));
        assert!(l.membership(&Aabb::EMPTY).is_none());
    }

    #[test]
    fn flat_and_unbounded_axes_get_one_cell() {
        let flat = Lattice::new(Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)), [8, 8, 8]);
        assert_eq!(flat.resolution(), [8, 8, 1]);
        let wide = Aabb::new(Vec3::new(f64::NEG_INFINITY, 0.0, 0.0), Vec3::ONE);
        let l = Lattice::new(wide, [8, 8, 8]);
        assert_eq!(l.resolution(), [1, 8, 8]);
        let r = l
            .overlapped(&Aabb::new(Vec3::splat(0.5), Vec3::ONE))
            .unwrap();
        assert_eq!((r.low, r.high), ([0, 3, 3], [0, 7, 7]));
    }

    #[test]
    fn points_outside_the_grid_clamp_to_the_edge_cells() {
        let l = unit_cells();
        assert_eq!(l.first_reaching(0, -5.0), 0);
        assert_eq!(l.last_reaching(0, 9.0), 3);
        assert_eq!(l.last_reaching(0, f64::NAN), 0);
        assert_eq!(l.first_reaching(0, f64::INFINITY), 3);
    }
}
