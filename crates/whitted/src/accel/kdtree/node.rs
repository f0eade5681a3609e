//! The 8-byte kd-tree node, after pbrt-v4's `KdTreeNode`: one word holds
//! the split position (an `f32`) or a leaf's offset into the primitive-index
//! array; the other holds the split axis (or the leaf tag) in its low two
//! bits and the above child's index (or the leaf's primitive count) in the
//! rest. The below child always follows its parent.

/// The largest above-child index or leaf primitive count a node can hold.
pub(super) const MAX_FIELD: u32 = (1 << 30) - 1;

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
    /// Splits its cell at `split` on `axis`; the below child is the next
    /// node, the above child is node `above`.
    Interior {
        /// 0, 1 or 2 for x, y, z.
        axis: usize,
        /// The plane's position on `axis`.
        split: f32,
        /// Index of the child holding the cell's part above the plane.
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
    /// [`MAX_FIELD`].
    pub(super) fn interior(axis: usize, split: f32, above: u32) -> Self {
        debug_assert!(axis < 3 && above <= MAX_FIELD);
        Self {
            word: split.to_bits(),
            flags: (above << 2) | (axis as u32 & 3),
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
                above: self.flags >> 2,
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
                for above in [0, 1, 12345, MAX_FIELD] {
                    let node = KdNode::interior(axis, split, above);
                    let NodeKind::Interior {
                        axis: a,
                        split: s,
                        above: b,
                    } = node.kind()
                    else {
                        panic!("decoded as a leaf");
                    };
                    assert_eq!((a, s.to_bits(), b), (axis, split.to_bits(), above));
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
