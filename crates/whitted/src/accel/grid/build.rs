//! Building a grid: choosing how many cells, then filling them in two passes
//! (count each cell's primitives, then place them) into flat offset and index
//! arrays.

use super::Grid;
use super::lattice::Lattice;
use crate::math::Aabb;

/// Options for building a [`Grid`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridBuildParams {
    /// About how many cells per primitive: the longest axis gets
    /// `∛(density · N)` cells for `N` primitives, the others as many as keep
    /// the cells roughly cubic.
    pub density: f64,
    /// Most cells along one axis.
    pub max_resolution: u32,
    /// Most cells in all.
    pub max_cells: usize,
    /// Most primitive references (a primitive is stored once per cell it
    /// overlaps). When big overlapping primitives would exceed it, the
    /// resolution is lowered until they fit; a grid of one cell stores each
    /// primitive once, whatever this says.
    pub max_references: usize,
}

impl Default for GridBuildParams {
    /// Three cells per primitive, at most 512 cells per axis, 4 Mi cells
    /// (16 MiB of offsets) and 64 Mi references (256 MiB of indices).
    fn default() -> Self {
        Self {
            density: 3.0,
            max_resolution: 512,
            max_cells: 1 << 22,
            max_references: 1 << 26,
        }
    }
}

impl Grid {
    /// A grid over primitives `0..boxes.len()` with the default options.
    pub fn build(boxes: &[Aabb]) -> Self {
        Self::build_with(boxes, &GridBuildParams::default())
    }

    /// A grid over primitives `0..boxes.len()` (at most `u32::MAX` of them,
    /// as for every structure) built with `params`. A primitive is stored in
    /// every cell its box, grown by a hair, touches; one with an empty box is
    /// stored nowhere.
    pub fn build_with(boxes: &[Aabb], params: &GridBuildParams) -> Self {
        let bounds = boxes
            .iter()
            .filter(|b| !b.is_empty())
            .fold(Aabb::EMPTY, |a, b| a.union(b));
        let mut lattice = Lattice::new(bounds, resolution(&bounds, boxes.len(), params));
        let max_references = params.max_references.min(u32::MAX as usize) as u64;
        while references(&lattice, boxes) > max_references && lattice.cell_count() > 1 {
            let coarser = lattice.resolution().map(|r| (r * 3 / 4).max(1));
            lattice = Lattice::new(bounds, coarser);
        }
        let (cell_start, indices) = fill(&lattice, boxes);
        Self {
            lattice,
            cell_start,
            indices,
            bounds: boxes.to_vec(),
        }
    }
}

/// Cells per axis for `primitives` primitives within `bounds`: about
/// `∛(density · N)` along the longest axis, proportionally fewer along the
/// others, one on flat or unbounded axes, within the caps.
fn resolution(bounds: &Aabb, primitives: usize, params: &GridBuildParams) -> [u32; 3] {
    let extent = bounds.extent();
    let usable = |axis: usize| extent[axis].is_finite() && extent[axis] > 0.0;
    let longest = (0..3)
        .filter(|&a| usable(a))
        .map(|a| extent[a])
        .fold(0.0, f64::max);
    if longest == 0.0 {
        return [1; 3];
    }
    let along_longest = (params.density * primitives as f64).cbrt();
    let max_resolution = params.max_resolution.max(1);
    let mut res = [1u32; 3];
    for (axis, r) in res.iter_mut().enumerate() {
        if usable(axis) {
            // Saturating cast: NaN gives 0, which the clamp lifts to 1.
            let cells = (extent[axis] / longest * along_longest).round() as u32;
            *r = cells.clamp(1, max_resolution);
        }
    }
    let budget = params.max_cells.max(1) as u128;
    let total = |res: [u32; 3]| res.iter().map(|&r| u128::from(r)).product::<u128>();
    while total(res) > budget {
        // Rounding down makes every axis above one cell shrink by at least one.
        let scale = (budget as f64 / total(res) as f64).cbrt();
        res = res.map(|r| ((f64::from(r) * scale) as u32).max(1));
    }
    res
}

/// How many references a grid on `lattice` would store.
fn references(lattice: &Lattice, boxes: &[Aabb]) -> u64 {
    boxes
        .iter()
        .filter_map(|b| lattice.membership(b))
        .fold(0, |sum, r| sum.saturating_add(r.len()))
}

/// The cells' contents in compressed sparse row form: cell `c` holds
/// `indices[cell_start[c]..cell_start[c + 1]]`, in increasing order.
fn fill(lattice: &Lattice, boxes: &[Aabb]) -> (Vec<u32>, Vec<u32>) {
    let cells = lattice.cell_count();
    let mut cell_start = vec![0u32; cells + 1];
    for range in boxes.iter().filter_map(|b| lattice.membership(b)) {
        for cell in range.coordinates() {
            cell_start[lattice.flat_index(cell)] += 1;
        }
    }
    // Running sums: each entry becomes the end of its cell ...
    let mut total = 0;
    for entry in &mut cell_start[..cells] {
        total += *entry;
        *entry = total;
    }
    cell_start[cells] = total;
    // ... and placing the primitives from the last backwards moves it down
    // to the start, leaving each cell sorted.
    let mut indices = vec![0u32; total as usize];
    for (i, b) in boxes.iter().enumerate().rev() {
        let Some(range) = lattice.membership(b) else {
            continue;
        };
        for cell in range.coordinates() {
            let slot = &mut cell_start[lattice.flat_index(cell)];
            *slot -= 1;
            indices[*slot as usize] = i as u32;
        }
    }
    (cell_start, indices)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn cube(size: f64) -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::splat(size))
    }

    #[test]
    fn cells_are_roughly_cubic_and_scale_with_the_primitive_count() {
        let params = GridBuildParams::default();
        assert_eq!(resolution(&cube(1.0), 9000, &params), [30, 30, 30]);
        let slab = Aabb::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
        assert_eq!(resolution(&slab, 8000 / 3, &params), [20, 10, 5]);
        assert_eq!(resolution(&cube(1.0), 1, &params), [1, 1, 1]);
        assert_eq!(resolution(&cube(1.0), 0, &params), [1, 1, 1]);
    }

    #[test]
    fn flat_and_empty_extents_get_one_cell() {
        let params = GridBuildParams::default();
        let flat = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(resolution(&flat, 9000, &params), [30, 30, 1]);
        let point = Aabb::new(Vec3::ONE, Vec3::ONE);
        assert_eq!(resolution(&point, 9000, &params), [1, 1, 1]);
        assert_eq!(resolution(&Aabb::EMPTY, 9000, &params), [1, 1, 1]);
    }

    #[test]
    fn resolution_respects_the_caps() {
        let params = GridBuildParams {
            max_resolution: 16,
            max_cells: 1000,
            ..GridBuildParams::default()
        };
        let long = Aabb::new(Vec3::ZERO, Vec3::new(100.0, 1.0, 1.0));
        assert_eq!(resolution(&long, 1_000_000, &params), [16, 1, 1]);
        let res = resolution(&cube(1.0), 1_000_000, &params);
        assert!(res.iter().product::<u32>() <= 1000, "{res:?}");
        assert!(res.iter().all(|&r| r >= 8), "{res:?}");
    }

    #[test]
    fn overlapping_primitives_lower_the_resolution_to_fit_the_reference_budget() {
        let boxes: Vec<Aabb> = (0..1000).map(|_| cube(1.0)).collect();
        let params = GridBuildParams {
            max_references: 20_000,
            ..GridBuildParams::default()
        };
        let grid = Grid::build_with(&boxes, &params);
        assert!(grid.stats().references <= 20_000);
        assert!(grid.lattice.cell_count() > 1);
        let tight = GridBuildParams {
            max_references: 10,
            ..GridBuildParams::default()
        };
        let grid = Grid::build_with(&boxes, &tight);
        assert_eq!(grid.lattice.resolution(), [1, 1, 1]);
        assert_eq!(grid.stats().references, 1000);
    }

    #[test]
    fn cells_hold_their_primitives_in_increasing_order() {
        let boxes = [
            Aabb::new(Vec3::ZERO, Vec3::splat(2.0)),
            Aabb::EMPTY,
            Aabb::new(Vec3::splat(1.5), Vec3::splat(2.0)),
            Aabb::new(Vec3::ZERO, Vec3::splat(0.5)),
        ];
        let lattice = Lattice::new(cube(2.0), [2, 2, 2]);
        let (cell_start, indices) = fill(&lattice, &boxes);
        assert_eq!(cell_start, [0, 2, 3, 4, 5, 6, 7, 8, 10]);
        assert_eq!(indices, [0, 3, 0, 0, 0, 0, 0, 0, 0, 2]);
    }
}
