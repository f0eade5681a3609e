//! Checking a built tree against its boxes (`validate`) and measuring it
//! (`stats`).

use super::build::{bounds_in, placed_box};
use super::node::NodeKind;
use super::traverse::STACK_CAPACITY;
use super::{Clipper, KdTree, split_cell};
use crate::accel::AccelStats;
use crate::math::Aabb;

impl KdTree {
    /// Checks the tree against the boxes it was built from:
    /// - its shape: node and primitive indices in range, every node reached
    ///   exactly once from the root, depth within the one stated (which
    ///   picks the traversal stack) and within the largest stack,
    ///   every split plane strictly inside its node's cell;
    /// - every primitive reachable: every point of its box lies in a
    ///   (closed) leaf cell that holds it. So each leaf whose cell the box
    ///   reaches into holds it, while a box that only touches a split
    ///   plane, or lies flat in it, may be held on one side of it only. A
    ///   primitive not placed in the tree is kept aside with its box,
    ///   because the box cannot be placed.
    pub fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        self.validate_impl(boxes, None)
    }

    /// Checks a tree built by [`KdTree::build_clipped`] with `clip`, as
    /// [`KdTree::validate`] does, except that a primitive must be held
    /// only where the box of its part inside a cell (by `clip`, widened
    /// as the build does) reaches.
    pub fn validate_clipped(&self, boxes: &[Aabb], clip: Clipper) -> Result<(), String> {
        self.validate_impl(boxes, Some(clip))
    }

    fn validate_impl(&self, boxes: &[Aabb], clip: Option<Clipper>) -> Result<(), String> {
        let mut aside = vec![false; boxes.len()];
        for &(i, b) in &self.loose {
            let given = boxes
                .get(i as usize)
                .ok_or_else(|| format!("primitive {i} kept aside is out of range"))?;
            if !same_box(given, &b) {
                return Err(format!("primitive {i} is kept aside with a wrong box"));
            }
            if placed_box(i as usize, given).is_some() {
                return Err(format!("primitive {i} is kept aside but fits the tree"));
            }
            if std::mem::replace(&mut aside[i as usize], true) {
                return Err(format!("primitive {i} is kept aside twice"));
            }
        }
        let tail = self.indices.len().checked_sub(self.loose.len());
        let listed = tail.map(|tail| &self.indices[tail..]);
        if !listed.is_some_and(|l| l.iter().eq(self.loose.iter().map(|(i, _)| i))) {
            return Err("the primitives kept aside do not end the index array".into());
        }
        self.check_shape(boxes.len(), &aside)?;

        let mut required = Vec::new();
        for (i, b) in boxes.iter().enumerate().filter(|&(i, _)| !aside[i]) {
            if placed_box(i, b).is_none() {
                return Err(format!(
                    "primitive {i} cannot be placed but is not kept aside"
                ));
            }
            if !(b.min.cmpge(self.bounds.min).all() && b.max.cmple(self.bounds.max).all()) {
                return Err(format!(
                    "primitive {i}'s box {b:?} is not inside the root cell"
                ));
            }
            required.push(i as u32);
        }
        self.check_coverage(Some(0), self.bounds, required, boxes, clip)
    }

    /// Checks that the nodes form a tree within the stated depth, with
    /// indices in range and every split inside its cell.
    fn check_shape(&self, primitives: usize, aside: &[bool]) -> Result<(), String> {
        if self.max_depth > STACK_CAPACITY {
            return Err(format!(
                "the tree's depth {} is beyond the stack's {STACK_CAPACITY}",
                self.max_depth
            ));
        }
        let mut reached = vec![false; self.nodes.len()];
        let mut pending = vec![(0, self.bounds, 0)];
        while let Some((index, cell, depth)) = pending.pop() {
            if depth > self.max_depth {
                return Err(format!(
                    "node {index} is at depth {depth}, beyond the tree's stated {}",
                    self.max_depth
                ));
            }
            let node = self
                .nodes
                .get(index)
                .ok_or_else(|| format!("node index {index} is out of range"))?;
            if std::mem::replace(&mut reached[index], true) {
                return Err(format!("node {index} is reached twice"));
            }
            match node.kind() {
                NodeKind::Leaf { offset, count } => {
                    let held = self.leaf_primitives(offset, count).ok_or_else(|| {
                        format!("leaf {index}'s primitives {offset}+{count} are out of range")
                    })?;
                    if let Some(p) = held
                        .iter()
                        .find(|&&p| p as usize >= primitives || aside[p as usize])
                    {
                        return Err(format!("leaf {index} holds primitive {p}, not in the tree"));
                    }
                }
                NodeKind::Interior {
                    axis,
                    split,
                    below,
                    above,
                } => {
                    if !below && above == 0 {
                        // The walk would take it for a cut whose child is
                        // the root.
                        return Err(format!("interior node {index} stores no child"));
                    }
                    let plane = f64::from(split);
                    if !(cell.min[axis] < plane && plane < cell.max[axis]) {
                        return Err(format!(
                            "node {index} splits axis {axis} at {plane}, outside its cell {cell:?}"
                        ));
                    }
                    let [below_cell, above_cell] = split_cell(&cell, axis, plane);
                    if below {
                        pending.push((index + 1, below_cell, depth + 1));
                    }
                    if above != 0 {
                        pending.push((above as usize, above_cell, depth + 1));
                    }
                }
            }
        }
        match reached.iter().position(|r| !r) {
            Some(i) => Err(format!("node {i} is unreachable")),
            None => Ok(()),
        }
    }

    /// Checks that every point of a `required` primitive's box inside
    /// `cell` (the cell of node `index`), clipped by `clip` if given, lies
    /// in a leaf of the subtree that holds it. The shape is already
    /// checked.
    fn check_coverage(
        &self,
        index: Option<usize>,
        cell: Aabb,
        required: Vec<u32>,
        boxes: &[Aabb],
        clip: Option<Clipper>,
    ) -> Result<(), String> {
        // Each primitive's box inside this cell; gone where it is clipped
        // away.
        let required = required
            .into_iter()
            .filter_map(|p| bounds_in(p, &boxes[p as usize], &cell, clip).map(|b| (p, b)));
        let Some(index) = index else {
            // A child not stored holds nothing.
            return match required.map(|(p, _)| p).next() {
                Some(p) => Err(format!(
                    "primitive {p} overlaps the cell {cell:?} of a child not stored"
                )),
                None => Ok(()),
            };
        };
        match self.nodes[index].kind() {
            NodeKind::Leaf { offset, count } => {
                let mut held = self.leaf_primitives(offset, count).unwrap_or(&[]).to_vec();
                held.sort_unstable();
                match required
                    .map(|(p, _)| p)
                    .find(|p| held.binary_search(p).is_err())
                {
                    Some(p) => Err(format!(
                        "primitive {p} overlaps leaf {index}'s cell {cell:?} but is not in it"
                    )),
                    None => Ok(()),
                }
            }
            NodeKind::Interior {
                axis,
                split,
                below,
                above,
            } => {
                let below = below.then_some(index + 1);
                let above = (above != 0).then_some(above as usize);
                let plane = f64::from(split);
                let (mut below_required, mut above_required) = (Vec::new(), Vec::new());
                for (p, b) in required {
                    let (low, high) = (b.min[axis], b.max[axis]);
                    if low == plane && high == plane {
                        // Flat in the plane: wholly on the side it was given.
                        if below.is_some_and(|below| self.subtree_holds(below, p)) {
                            below_required.push(p);
                        } else {
                            above_required.push(p);
                        }
                    } else {
                        if low < plane {
                            below_required.push(p);
                        }
                        if high > plane {
                            above_required.push(p);
                        }
                    }
                }
                let [below_cell, above_cell] = split_cell(&cell, axis, plane);
                self.check_coverage(below, below_cell, below_required, boxes, clip)?;
                self.check_coverage(above, above_cell, above_required, boxes, clip)
            }
        }
    }

    /// True when a leaf of the subtree `index` holds `primitive`.
    fn subtree_holds(&self, index: usize, primitive: u32) -> bool {
        match self.nodes[index].kind() {
            NodeKind::Leaf { offset, count } => self
                .leaf_primitives(offset, count)
                .is_some_and(|held| held.contains(&primitive)),
            NodeKind::Interior { below, above, .. } => {
                (below && self.subtree_holds(index + 1, primitive))
                    || (above != 0 && self.subtree_holds(above as usize, primitive))
            }
        }
    }

    /// A leaf's run of `indices`, if it lies before the loose primitives'.
    fn leaf_primitives(&self, offset: u32, count: u32) -> Option<&[u32]> {
        let start = offset as usize;
        let leaves = self.indices.len().checked_sub(self.loose.len())?;
        self.indices[..leaves].get(start..start + count as usize)
    }

    /// Size and quality. The SAH cost counts one per interior node and one
    /// per primitive in a leaf, each weighted by its cell's area relative
    /// to the root cell's, plus one per primitive kept aside.
    pub fn stats(&self) -> AccelStats {
        let mut stats = AccelStats {
            nodes: self.nodes.len(),
            memory_bytes: size_of_val(self.nodes.as_slice())
                + size_of_val(self.indices.as_slice())
                + size_of_val(self.loose.as_slice()),
            sah_cost: self.loose.len() as f64,
            ..AccelStats::default()
        };
        let root_area = self.bounds.surface_area();
        let probability = |cell: &Aabb| {
            if root_area > 0.0 {
                cell.surface_area() / root_area
            } else {
                1.0
            }
        };
        let mut pending = vec![(0, self.bounds, 0)];
        while let Some((index, cell, depth)) = pending.pop() {
            let Some(node) = self.nodes.get(index) else {
                continue;
            };
            stats.max_depth = stats.max_depth.max(depth);
            match node.kind() {
                NodeKind::Leaf { count, .. } => {
                    stats.leaves += 1;
                    stats.references += count as usize;
                    stats.sah_cost += probability(&cell) * f64::from(count);
                }
                NodeKind::Interior {
                    axis,
                    split,
                    below,
                    above,
                } => {
                    stats.sah_cost += probability(&cell);
                    if depth < STACK_CAPACITY {
                        let [below_cell, above_cell] = split_cell(&cell, axis, f64::from(split));
                        if below {
                            pending.push((index + 1, below_cell, depth + 1));
                        }
                        if above != 0 {
                            pending.push((above as usize, above_cell, depth + 1));
                        }
                    }
                }
            }
        }
        stats
    }
}

/// Bit-for-bit equality, so a NaN box equals itself.
fn same_box(a: &Aabb, b: &Aabb) -> bool {
    let bits = |b: &Aabb| [b.min, b.max].map(|v| v.to_array().map(f64::to_bits));
    bits(a) == bits(b)
}

#[cfg(test)]
mod tests {
    use super::super::node::KdNode;
    use super::*;
    use crate::math::Vec3;

    /// Two unit cubes meeting at x = 1.
    fn boxes() -> Vec<Aabb> {
        vec![
            Aabb::new(Vec3::ZERO, Vec3::ONE),
            Aabb::new(Vec3::X, Vec3::new(2.0, 1.0, 1.0)),
        ]
    }

    #[test]
    fn stats_of_a_single_split_count_nodes_references_and_sah_cost() {
        let tree = KdTree::build(&boxes());
        assert_eq!(tree.validate(&boxes()), Ok(()));
        let stats = tree.stats();
        assert_eq!(
            (stats.nodes, stats.leaves, stats.references, stats.max_depth),
            (3, 2, 2, 1)
        );
        assert_eq!(stats.memory_bytes, 3 * 8 + 2 * 4);
        // The root, then each half (area 6 of 10) with one cube.
        assert!((stats.sah_cost - 2.2).abs() < 1e-12, "{stats:?}");
    }

    #[test]
    fn validate_finds_a_missing_primitive() {
        let mut tree = KdTree::build(&boxes());
        tree.indices[1] = 0;
        let why = tree.validate(&boxes()).unwrap_err();
        assert!(why.contains("primitive 1 overlaps leaf"), "{why}");
    }

    #[test]
    fn validate_finds_a_primitive_in_the_cell_of_a_child_not_stored() {
        let mut tree = KdTree::build(&boxes());
        assert_eq!(tree.indices, [0, 1]);
        // The root's above child, holding cube 1, left out.
        tree.nodes = vec![KdNode::interior(0, 1.0, true, 0), KdNode::leaf(0, 1)];
        let why = tree.validate(&boxes()).unwrap_err();
        assert!(why.contains("primitive 1 overlaps the cell"), "{why}");
        assert!(why.contains("child not stored"), "{why}");
    }

    #[test]
    fn validate_finds_bad_indices_and_misplaced_planes() {
        let mut tree = KdTree::build(&boxes());
        tree.nodes[0] = KdNode::interior(0, 1.0, true, 7);
        assert!(
            tree.validate(&boxes())
                .unwrap_err()
                .contains("out of range")
        );
        tree.nodes[0] = KdNode::interior(0, 3.0, true, 2);
        assert!(
            tree.validate(&boxes())
                .unwrap_err()
                .contains("outside its cell")
        );
        tree.nodes[0] = KdNode::interior(0, 1.0, true, 1);
        assert!(
            tree.validate(&boxes())
                .unwrap_err()
                .contains("reached twice")
        );
        tree.nodes[0] = KdNode::interior(0, 1.0, false, 0);
        assert!(
            tree.validate(&boxes())
                .unwrap_err()
                .contains("stores no child")
        );
        tree.nodes[0] = KdNode::leaf(1, 5);
        assert!(
            tree.validate(&boxes())
                .unwrap_err()
                .contains("out of range")
        );
    }

    #[test]
    fn validate_finds_a_box_kept_aside_that_fits_the_tree() {
        let mut tree = KdTree::build(&boxes());
        tree.loose.push((0, boxes()[0]));
        tree.indices.push(0);
        let why = tree.validate(&boxes()).unwrap_err();
        assert!(why.contains("fits the tree"), "{why}");
    }

    #[test]
    fn validate_finds_primitives_kept_aside_missing_from_the_index_array() {
        let mut with_loose = boxes().to_vec();
        with_loose.push(Aabb::INFINITE);
        let mut tree = KdTree::build(&with_loose);
        assert_eq!(tree.validate(&with_loose), Ok(()));
        assert_eq!(tree.indices.last(), Some(&2));
        tree.indices.pop();
        let why = tree.validate(&with_loose).unwrap_err();
        assert!(why.contains("do not end the index array"), "{why}");
    }
}
