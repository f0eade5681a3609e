//! The invariants of a built BVH, checked against the boxes it was built
//! from.

use super::{Bvh, MAX_DEPTH, WIDTH};
use crate::math::Aabb;

/// True when `inner` lies inside `outer` (an empty `inner` always does).
fn contains(outer: &Aabb, inner: &Aabb) -> bool {
    inner.is_empty() || (outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all())
}

impl Bvh {
    /// Checks that every node is reached once, every primitive is referenced
    /// exactly once, a node's child boxes lie inside the box its parent
    /// keeps for it, every leaf's box contains its primitives' boxes, unused
    /// slots hold the empty box, and no leaf is deeper than the traversal
    /// stack allows.
    pub fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        if self.indices.len() != boxes.len() {
            return Err(format!(
                "{} primitive references for {} primitives",
                self.indices.len(),
                boxes.len()
            ));
        }
        if self.nodes.is_empty() {
            return match boxes.len() {
                0 => Ok(()),
                n => Err(format!("no nodes for {n} primitives")),
            };
        }
        let mut node_seen = vec![false; self.nodes.len()];
        let mut prim_seen = vec![false; boxes.len()];
        let mut todo = vec![(0, 0, None)];
        let mut max_depth = 0;
        while let Some((i, depth, parent_box)) = todo.pop() {
            if std::mem::replace(&mut node_seen[i], true) {
                return Err(format!("node {i} is reached twice"));
            }
            if depth > MAX_DEPTH {
                return Err(format!(
                    "node {i} at depth {depth}, beyond the stack of {MAX_DEPTH}"
                ));
            }
            max_depth = max_depth.max(depth);
            let node = &self.nodes[i];
            for slot in 0..WIDTH {
                let bounds = node.child_bounds(slot);
                if !node.is_used(slot) {
                    if !bounds.is_empty() || node.counts[slot] != 0 {
                        return Err(format!("unused slot {slot} of node {i} is not empty"));
                    }
                    continue;
                }
                if let Some(parent_box) = &parent_box
                    && !contains(parent_box, &bounds)
                {
                    return Err(format!("slot {slot} of node {i} sticks out of its parent"));
                }
                let first = node.children[slot] as usize;
                if node.counts[slot] == 0 {
                    if first >= self.nodes.len() {
                        return Err(format!("node {i} has a child beyond the node array"));
                    }
                    todo.push((first, depth + 1, Some(bounds)));
                    continue;
                }
                let Some(prims) = self.indices.get(first..first + node.counts[slot] as usize)
                else {
                    return Err(format!(
                        "leaf in node {i} lists primitives beyond the index array"
                    ));
                };
                for &p in prims {
                    let Some(seen) = prim_seen.get_mut(p as usize) else {
                        return Err(format!(
                            "a leaf in node {i} holds primitive {p}, which does not exist"
                        ));
                    };
                    if std::mem::replace(seen, true) {
                        return Err(format!("primitive {p} is referenced twice"));
                    }
                    if !contains(&bounds, &boxes[p as usize]) {
                        return Err(format!(
                            "a leaf in node {i} does not contain primitive {p}'s box"
                        ));
                    }
                }
            }
        }
        if let Some(i) = node_seen.iter().position(|&seen| !seen) {
            return Err(format!("node {i} is unreachable"));
        }
        if let Some(p) = prim_seen.iter().position(|&seen| !seen) {
            return Err(format!("primitive {p} is in no leaf"));
        }
        if max_depth != self.max_depth {
            return Err(format!(
                "deepest leaf at {max_depth}, recorded as {}",
                self.max_depth
            ));
        }
        Ok(())
    }
}
