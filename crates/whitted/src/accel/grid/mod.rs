//! The uniform grid: the scene's box cut into equal cells, each listing the
//! primitives whose boxes overlap it, walked front to back along a ray by a
//! 3D-DDA.
//!
//! - `lattice` decides where the cells lie and which cells a box overlaps;
//! - `build` chooses the resolution and fills the cells into flat offset and
//!   index arrays;
//! - `dda` walks a ray through the cells; `traverse` answers the two queries
//!   on that walk, with the shared mailbox (`accel/mailbox.rs`) so a
//!   primitive spanning many cells is tested once per ray;
//! - `validate` checks a built grid.

mod build;
mod dda;
mod lattice;
mod traverse;
mod validate;

pub use build::GridBuildParams;

use super::AccelStats;
use crate::math::Aabb;
use lattice::Lattice;

/// A uniform grid over primitive boxes (see the [module](self) docs).
#[derive(Clone, Debug)]
pub struct Grid {
    lattice: Lattice,
    /// Cell `c` holds `indices[cell_start[c]..cell_start[c + 1]]`.
    cell_start: Vec<u32>,
    /// The primitives of every cell, cell after cell, each cell sorted.
    indices: Vec<u32>,
    /// The primitives' boxes, to cull them before calling the closure
    /// exactly as brute force does.
    bounds: Vec<Aabb>,
}

impl Grid {
    /// Cells per axis.
    pub fn resolution(&self) -> [u32; 3] {
        self.lattice.resolution()
    }

    /// The primitives listed in cell `cell` (a flat index).
    fn cell(&self, cell: usize) -> &[u32] {
        let start = self.cell_start[cell] as usize;
        let end = self.cell_start[cell + 1] as usize;
        &self.indices[start..end]
    }

    /// Cells, non-empty cells, references and memory; a grid has no SAH
    /// cost and no depth, so both are 0.
    pub fn stats(&self) -> AccelStats {
        AccelStats {
            nodes: self.lattice.cell_count(),
            leaves: self.cell_start.windows(2).filter(|w| w[0] < w[1]).count(),
            references: self.indices.len(),
            memory_bytes: std::mem::size_of::<Self>()
                + std::mem::size_of_val(self.cell_start.as_slice())
                + std::mem::size_of_val(self.indices.as_slice())
                + std::mem::size_of_val(self.bounds.as_slice()),
            sah_cost: 0.0,
            max_depth: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::math::Vec3;
    use crate::math::random::Rng;

    #[test]
    fn grid_conforms_to_brute_force() {
        crate::accel::conformance::assert_conforms(AccelKind::Grid);
    }

    #[test]
    fn stats_count_cells_references_and_memory() {
        let mut rng = Rng::new(3);
        let boxes: Vec<Aabb> = (0..1000)
            .map(|_| {
                let c = rng.point_in(Vec3::ZERO, Vec3::splat(10.0));
                Aabb::new(c, c + Vec3::splat(0.1))
            })
            .collect();
        let grid = Grid::build(&boxes);
        let stats = grid.stats();
        assert_eq!(grid.resolution(), [14, 14, 14]);
        assert_eq!(stats.nodes, 14 * 14 * 14);
        assert!(stats.leaves > 0 && stats.leaves <= stats.nodes);
        assert!(stats.references >= 1000);
        assert!(stats.memory_bytes >= 4 * (stats.nodes + 1 + stats.references));
        assert_eq!((stats.sah_cost, stats.max_depth), (0.0, 0));
    }
}
