//! Checking a built grid against the boxes it was built from.

use super::Grid;
use crate::math::Aabb;

impl Grid {
    /// Checks the invariants: it holds the primitives' boxes, the grid box is the union of the primitives'
    /// boxes, the offsets run from 0 to the number of references without
    /// going back, each cell lists valid primitives in increasing order, only
    /// primitives whose (slightly grown) box touches it, and every primitive
    /// is listed in every cell its box overlaps.
    pub fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        if self.bounds != boxes {
            return Err(format!(
                "the {} stored boxes differ from the {} primitives' boxes",
                self.bounds.len(),
                boxes.len()
            ));
        }
        let bounds = boxes
            .iter()
            .filter(|b| !b.is_empty())
            .fold(Aabb::EMPTY, |a, b| a.union(b));
        if bounds != *self.lattice.bounds() {
            return Err(format!(
                "grid box {:?} is not the union of the boxes {bounds:?}",
                self.lattice.bounds()
            ));
        }
        self.validate_offsets()?;
        self.validate_cells(boxes)?;
        self.validate_coverage(boxes)
    }

    fn validate_offsets(&self) -> Result<(), String> {
        let cells = self.lattice.cell_count();
        if self.cell_start.len() != cells + 1 {
            return Err(format!(
                "{} offsets for {cells} cells",
                self.cell_start.len()
            ));
        }
        if self.cell_start.first() != Some(&0) {
            return Err("the first cell does not start at 0".to_string());
        }
        if self.cell_start.last().map(|&end| end as usize) != Some(self.indices.len()) {
            return Err(format!(
                "the last cell does not end at the {} references",
                self.indices.len()
            ));
        }
        match self.cell_start.windows(2).position(|w| w[0] > w[1]) {
            Some(c) => Err(format!("cell {c} ends before it starts")),
            None => Ok(()),
        }
    }

    fn validate_cells(&self, boxes: &[Aabb]) -> Result<(), String> {
        for (flat, cell) in self.lattice.all_cells().coordinates().enumerate() {
            let listed = self.cell(flat);
            if listed.windows(2).any(|w| w[0] >= w[1]) {
                return Err(format!("cell {cell:?} is not sorted: {listed:?}"));
            }
            for &i in listed {
                let member = boxes.get(i as usize).ok_or_else(|| {
                    format!("cell {cell:?} lists primitive {i} of {}", boxes.len())
                })?;
                if !self
                    .lattice
                    .membership(member)
                    .is_some_and(|r| r.contains(cell))
                {
                    return Err(format!(
                        "cell {cell:?} lists primitive {i}, whose box {member:?} is elsewhere"
                    ));
                }
            }
        }
        Ok(())
    }

    fn validate_coverage(&self, boxes: &[Aabb]) -> Result<(), String> {
        for (i, b) in boxes.iter().enumerate() {
            let Some(range) = self.lattice.overlapped(b) else {
                continue;
            };
            for cell in range.coordinates() {
                let listed = self.cell(self.lattice.flat_index(cell));
                if listed.binary_search(&(i as u32)).is_err() {
                    return Err(format!(
                        "primitive {i} overlaps cell {cell:?} but is not listed there"
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::conformance::random_boxes;
    use crate::math::Vec3;
    use crate::math::random::Rng;

    fn degenerate_inputs() -> Vec<(&'static str, Vec<Aabb>)> {
        let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let mut huge = random_boxes(&mut Rng::new(4), 300, 5.0, 1.0);
        huge.push(Aabb::new(Vec3::splat(-1000.0), Vec3::splat(1000.0)));
        let flat_mesh = (0..400)
            .map(|i| {
                let (x, y) = (f64::from(i % 20), f64::from(i / 20));
                Aabb::new(Vec3::new(x, y, 2.0), Vec3::new(x + 1.0, y + 1.0, 2.0))
            })
            .collect();
        vec![
            ("random", random_boxes(&mut Rng::new(1), 2000, 5.0, 1.0)),
            ("identical", vec![unit; 500]),
            ("one huge among small", huge),
            ("flat mesh", flat_mesh),
            ("empty", Vec::new()),
            ("only empty boxes", vec![Aabb::EMPTY; 3]),
            ("one point", vec![Aabb::new(Vec3::ONE, Vec3::ONE)]),
            ("empty among others", vec![unit, Aabb::EMPTY, unit]),
        ]
    }

    #[test]
    fn grids_built_from_random_and_degenerate_boxes_are_valid() {
        for (name, boxes) in degenerate_inputs() {
            let grid = Grid::build(&boxes);
            assert_eq!(grid.validate(&boxes), Ok(()), "{name}");
        }
    }

    #[test]
    fn identical_boxes_share_the_cells_they_fill() {
        let boxes = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 500];
        let grid = Grid::build(&boxes);
        let stats = grid.stats();
        assert_eq!(stats.references, 500 * stats.nodes);
    }

    #[test]
    fn validate_finds_a_missing_reference() {
        let boxes = random_boxes(&mut Rng::new(2), 500, 5.0, 1.0);
        let mut grid = Grid::build(&boxes);
        let first = grid
            .cell_start
            .windows(2)
            .position(|w| w[0] < w[1])
            .unwrap();
        let missing = grid.indices.remove(grid.cell_start[first] as usize);
        for start in &mut grid.cell_start[first + 1..] {
            *start -= 1;
        }
        let why = grid.validate(&boxes).unwrap_err();
        assert!(why.contains(&format!("primitive {missing} ")), "{why}");
    }

    #[test]
    fn validate_finds_broken_offsets_and_stray_indices() {
        let boxes = random_boxes(&mut Rng::new(3), 500, 5.0, 1.0);
        let grid = Grid::build(&boxes);

        let mut backwards = grid.clone();
        backwards.cell_start[1] = backwards.cell_start[2] + 1;
        assert!(
            backwards
                .validate(&boxes)
                .unwrap_err()
                .contains("ends before")
        );

        let mut out_of_range = grid.clone();
        out_of_range.indices[0] = 500;
        assert!(out_of_range.validate(&boxes).is_err());

        let mut elsewhere = grid.clone();
        let last = elsewhere.indices.len() - 1;
        elsewhere.indices.swap(0, last);
        assert!(elsewhere.validate(&boxes).is_err());

        assert!(grid.validate(&boxes[1..]).is_err());
    }
}
