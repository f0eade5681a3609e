//! The 8-byte kd-tree node, after pbrt-v4's `KdTreeNode`: one word holds
//! the split position (an `f32`) or a leaf's offset into the primitive-index
//! array; the other holds the split axis (or the leaf tag) in its low two
//! bits and, for a leaf, its primitive count in the rest. An interior node
//! has there one bit saying whether its below child is stored (right after
//! it) and its above child's index, 0 when that child is not stored: a
//! child that would be an empty leaf is left out, so the walk never steps
//! into it.

/// The largest leaf primitive count a node can hold.
pub(super) const MAX_FIELD: u32 = (1 << 30) - 1;

/// The largest above-child index a node can hold.
pub(super) const MAX_NODE: u32 = (1 << 29) - 1;

/// The bit above the axis that marks an interior node without a below
/// child.
const NO_BELOW: u32 = 4;

/// The tag in the low two bits that marks a leaf (axes are 0, 1, 2).
const LEAF_TAG: u32 = 3;

/// One node of the flattened tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct KdNode {
    /// The split position's bits (interior) or the first primitive's
    /// position in the index array (leaf).
    word: u32,
    /// Axis or leaf tag in bits 0-1; above child or primitive count above.
    flags: u32,
}

const _: () = assert!(size_of::<KdNode>() == 8);

/// A node, decoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum NodeKind {
    /// Splits its cell at `split` on `axis`; the below child, if `below`,
    /// is the next node, the above child is node `above` (none if 0). A
    /// child not stored holds nothing.
    Interior {
        /// 0, 1 or 2 for x, y, z.
        axis: usize,
        /// The plane's position on `axis`.
        split: f32,
        /// Whether the child holding the cell's part below the plane is
        /// stored (as the next node).
        below: bool,
        /// Index of the child holding the cell's part above the plane, 0
        /// when it is not stored.
        above: u32,
    },
    /// Holds primitives `indices[offset..offset + count]`.
    Leaf {
        /// Position of the first primitive in the index array.
        offset: u32,
        /// How many primitives.
        count: u32,
    },
}

impl KdNode {
    /// An interior node; `axis` is below 3 and `above` at most
    /// [`MAX_NODE`] (0: no above child); `below` says whether the below
    /// child follows.
    pub(super) fn interior(axis: usize, split: f32, below: bool, above: u32) -> Self {
        debug_assert!(axis < 3 && above <= MAX_NODE);
        let no_below = if below { 0 } else { NO_BELOW };
        Self {
            word: split.to_bits(),
            flags: (above << 3) | no_below | (axis as u32 & 3),
        }
    }

    /// A leaf; `count` is at most [`MAX_FIELD`].
    pub(super) fn leaf(offset: u32, count: u32) -> Self {
        debug_assert!(count <= MAX_FIELD);
        Self {
            word: offset,
            flags: (count << 2) | LEAF_TAG,
        }
    }

    /// What the node is.
    #[inline]
    pub(super) fn kind(self) -> NodeKind {
        let tag = self.flags & 3;
        if tag == LEAF_TAG {
            NodeKind::Leaf {
                offset: self.word,
                count: self.flags >> 2,
            }
        } else {
            NodeKind::Interior {
                axis: tag as usize,
                split: f32::from_bits(self.word),
                below: self.flags & NO_BELOW == 0,
                above: self.flags >> 3,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interior_nodes_round_trip_every_axis_and_extreme_values() {
        for axis in 0..3 {
            for split in [0.0, -0.0, 1.5, -3.25e7, f32::MAX, f32::MIN_POSITIVE] {
                for (below, above) in [(true, 0), (false, 1), (true, 12345), (false, MAX_NODE)] {
                    let node = KdNode::interior(axis, split, below, above);
                    let NodeKind::Interior {
                        axis: a,
                        split: s,
                        below: b,
                        above: c,
                    } = node.kind()
                    else {
                        panic!("decoded as a leaf");
                    };
                    assert_eq!(
                        (a, s.to_bits(), b, c),
                        (axis, split.to_bits(), below, above)
                    );
                }
            }
        }
    }

    #[test]
    fn leaves_round_trip_offsets_and_counts() {
        for offset in [0, 7, u32::MAX] {
            for count in [0, 1, 999, MAX_FIELD] {
                assert_eq!(
                    KdNode::leaf(offset, count).kind(),
                    NodeKind::Leaf { offset, count }
                );
            }
        }
    }
}
