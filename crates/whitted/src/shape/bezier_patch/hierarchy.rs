//! The subdivision hierarchy of a patch: a tree of 4-way splits in (u, v),
//! each node holding the box of its piece's control points (which contains
//! the piece, by the convex hull property) and its parameter range.
//!
//! A piece is split while it is shallower than [`MIN_DEPTH`], or shallower
//! than [`MAX_DEPTH`] and not flat: some control point lies further than
//! [`FLATNESS`] of the piece's size from a plane. Leaves are therefore
//! nearly flat, so a ray meets a leaf in at most one point unless it grazes
//! it, and Newton's iteration started at the leaf's centre converges to
//! that point.

use super::bernstein::{ControlNet, quarters};
use crate::math::{Aabb, Vec3, unit};

/// Every patch is split at least this often (16 leaves).
const MIN_DEPTH: u32 = 2;
/// No patch is split more often than this (at most 1024 leaves).
pub(super) const MAX_DEPTH: u32 = 5;
/// A piece is flat when its control points lie within this fraction of its
/// size (its box's diagonal) from a plane.
const FLATNESS: f64 = 0.02;

/// One node: a piece of the patch.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Node {
    /// The box of the piece's control points, widened for rounding.
    pub(super) bounds: Aabb,
    /// The start of the piece's parameter range, `[u0, v0]`.
    pub(super) low: [f64; 2],
    /// The end of the parameter range, `[u1, v1]`.
    pub(super) high: [f64; 2],
    /// The index of the first of the four children, or 0 for a leaf.
    pub(super) children: u32,
    /// For a leaf, the index of its piece's control net in
    /// [`Hierarchy::nets`].
    pub(super) net: u32,
}

impl Node {
    /// True when the node has no children.
    pub(super) fn is_leaf(&self) -> bool {
        self.children == 0
    }
}

/// The nodes of the tree, root first; the four children of a node are
/// contiguous.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Hierarchy {
    pub(super) nodes: Vec<Node>,
    /// The control net of each leaf's piece, over the leaf's own (s, t) in
    /// [0, 1]²: u = low[0] + s (high[0] - low[0]), and v likewise.
    pub(super) nets: Vec<ControlNet>,
}

impl Hierarchy {
    /// The hierarchy of `net`, whose boxes are widened by `margin`.
    pub(super) fn build(net: &ControlNet, margin: f64) -> Self {
        let mut tree = Self {
            nodes: vec![node(net, [0.0, 0.0], [1.0, 1.0], margin)],
            nets: Vec::new(),
        };
        tree.split(0, net, 0, margin);
        tree
    }

    /// Splits node `index` (whose piece is `net`) and its children, as
    /// deep as the rules in the module's documentation ask; keeps the nets
    /// of the leaves.
    fn split(&mut self, index: usize, net: &ControlNet, depth: u32, margin: f64) {
        if depth >= MAX_DEPTH || (depth >= MIN_DEPTH && is_flat(net)) {
            self.nodes[index].net = self.nets.len() as u32;
            self.nets.push(*net);
            return;
        }
        let (low, high) = (self.nodes[index].low, self.nodes[index].high);
        let mid = [0.5 * (low[0] + high[0]), 0.5 * (low[1] + high[1])];
        let first = self.nodes.len();
        self.nodes[index].children = first as u32;
        let parts = quarters(net);
        for (k, part) in parts.iter().enumerate() {
            let (u0, u1) = if k / 2 == 0 {
                (low[0], mid[0])
            } else {
                (mid[0], high[0])
            };
            let (v0, v1) = if k % 2 == 0 {
                (low[1], mid[1])
            } else {
                (mid[1], high[1])
            };
            self.nodes.push(node(part, [u0, v0], [u1, v1], margin));
        }
        for (k, part) in parts.iter().enumerate() {
            self.split(first + k, part, depth + 1, margin);
        }
    }

    /// The number of leaves.
    #[cfg(test)]
    pub(super) fn leaves(&self) -> usize {
        self.nodes.iter().filter(|n| n.is_leaf()).count()
    }
}

fn node(net: &ControlNet, low: [f64; 2], high: [f64; 2], margin: f64) -> Node {
    Node {
        bounds: Aabb::from_points(net.iter().flatten().copied()).expanded(margin),
        low,
        high,
        children: 0,
        net: 0,
    }
}

/// True when every control point of `net` lies within [`FLATNESS`] of the
/// piece's size from the plane through their mean, normal to the
/// diagonals of the net (a piece whose diagonals are parallel is not
/// flat). A flat piece turns its normal little, so a ray that does not
/// graze it meets it at most once.
fn is_flat(net: &ControlNet) -> bool {
    let size = Aabb::from_points(net.iter().flatten().copied())
        .extent()
        .length();
    let normal = (net[3][3] - net[0][0]).cross(net[0][3] - net[3][0]);
    let Some(normal) = unit(normal) else {
        return false;
    };
    let centre = net.iter().flatten().sum::<Vec3>() / 16.0;
    net.iter()
        .flatten()
        .all(|&p| (p - centre).dot(normal).abs() <= FLATNESS * size)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::bezier_patch::bernstein::evaluate;

    #[test]
    fn a_flat_patch_stops_at_the_least_depth_and_a_curved_one_goes_deeper() {
        let flat: ControlNet =
            std::array::from_fn(|i| std::array::from_fn(|j| Vec3::new(i as f64, j as f64, 0.0)));
        assert_eq!(Hierarchy::build(&flat, 0.0).leaves(), 16);
        let bowl: ControlNet = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let (x, y) = (i as f64 - 1.5, j as f64 - 1.5);
                Vec3::new(x, y, 3.0 * (x * x + y * y))
            })
        });
        assert!(Hierarchy::build(&bowl, 0.0).leaves() > 16);
    }

    #[test]
    fn every_leaf_box_holds_its_piece_of_the_surface() {
        let wave: ControlNet = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                Vec3::new(
                    i as f64,
                    j as f64,
                    if (i + j) % 2 == 0 { 2.0 } else { -1.0 },
                )
            })
        });
        let tree = Hierarchy::build(&wave, 1e-12);
        for leaf in tree.nodes.iter().filter(|n| n.is_leaf()) {
            for s in 0..=4 {
                for t in 0..=4 {
                    let u = leaf.low[0] + (leaf.high[0] - leaf.low[0]) * s as f64 / 4.0;
                    let v = leaf.low[1] + (leaf.high[1] - leaf.low[1]) * t as f64 / 4.0;
                    let p = evaluate(&wave, u, v).point;
                    assert!(p.cmpge(leaf.bounds.min).all() && p.cmple(leaf.bounds.max).all());
                }
            }
        }
    }
}
