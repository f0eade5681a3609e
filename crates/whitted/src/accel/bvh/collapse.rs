//! Collapsing the binary tree into wide nodes of [`WIDTH`] children.
//!
//! Each wide node starts from a binary node's two children and, while it has
//! fewer than [`WIDTH`], replaces the interior child of largest surface area by
//! its two children (the child most rays enter, so removing it saves the
//! most steps). Leaves stay in their parent's slots; the wide tree is never
//! deeper than the binary one. Nodes are numbered depth first, each one when
//! its parent is filled, so a subtree's nodes lie close together.
//!
//! Tried collapsing subtrees of up to four triangles into one leaf: no
//! faster, see docs/performance-log.md (eight-wide BVH).

use super::node::{BinaryNode, BvhNode, WIDTH};

/// The wide nodes, root first, and the deepest leaf's depth (the leaves in
/// the root's slots are at depth 0). `scratch` holds the binary tree, root
/// first, and must not be empty.
pub(super) fn collapse(scratch: &[BinaryNode]) -> (Vec<BvhNode>, usize) {
    // Each wide node but the root replaces at least one binary interior
    // node, and half the binary nodes at most are interior: reserving that
    // (untouched memory costs nothing) saves copying the nodes as the
    // vector grows.
    let mut nodes = Vec::with_capacity(scratch.len() / 2 + 1);
    nodes.push(BvhNode::default());
    let mut todo = vec![(0, 0, 0)];
    let mut max_depth = 0;
    while let Some((wide, binary, depth)) = todo.pop() {
        max_depth = max_depth.max(depth);
        let node = &scratch[binary];
        let mut slots = [binary; WIDTH];
        let mut used = 1;
        if !node.is_leaf() {
            let first = node.first as usize;
            slots[..2].copy_from_slice(&[first, first + 1]);
            used = 2;
            while used < WIDTH {
                let widest =
                    (0..used)
                        .filter(|&i| !scratch[slots[i]].is_leaf())
                        .max_by(|&a, &b| {
                            let area = |i: usize| scratch[slots[i]].bounds().surface_area();
                            area(a).total_cmp(&area(b))
                        });
                let Some(i) = widest else { break };
                let first = scratch[slots[i]].first as usize;
                slots[i] = first;
                slots[used] = first + 1;
                used += 1;
            }
        }
        for (slot, &index) in slots[..used].iter().enumerate() {
            let child = &scratch[index];
            if child.is_leaf() {
                nodes[wide].set_child(slot, &child.bounds(), child.first, child.count);
            } else {
                let at = nodes.len();
                nodes.push(BvhNode::default());
                nodes[wide].set_child(slot, &child.bounds(), at as u32, 0);
                todo.push((at, index, depth + 1));
            }
        }
    }
    (nodes, max_depth)
}
