//! A kd-tree built with the surface area heuristic in O(N log N) (Wald and
//! Havran 2006), stored as 8-byte nodes (pbrt-v4 `KdTreeNode`).
//!
//! - `node.rs`: the compact node.
//! - `events.rs`: split events, sorted once.
//! - `sah.rs`: the cost model and the sweep that picks a plane.
//! - `build.rs`: the recursive build that splits the sorted events.
//! - `traverse.rs`: closest-hit and any-hit queries.
//! - `check.rs`: `validate` and `stats`.
//!
//! Split planes are `f32`. Boxes are widened outwards to the `f32` grid
//! before the build, so every plane is an exact event position and the
//! primitives are assigned against the plane traversal tests: a box that
//! straddles it goes to both children, one that touches it to the side it
//! lies on, one lying flat in it to the cheaper side. Cells are closed:
//! traversal visits both children wherever the ray may be on the plane.
//! Boxes that cannot be placed (empty, not finite or
//! beyond `f32`) are kept aside and tested for every ray, as brute force
//! would.
//!
//! "Perfect splits" (Wald and Havran 2006, section 4.4): a build may be
//! given a [`Clipper`], the bounds of a primitive inside a cell. A
//! primitive straddling a split then gets, in each child, the box of its
//! own part inside that child's cell instead of its box ∩ the cell, and
//! goes to no child it does not meet: a triangle crossing a cell
//! diagonally is not copied into every cell its box reaches.
//!
//! Limits: at most 2^30 − 1 primitives are placed in the tree (more are
//! kept aside), at most 2^32 references, and splitting stops near 2^29
//! nodes.
//!
//! # Speed
//!
//! A child cell without primitives is not stored: its parent says so, and
//! the walk never steps into it (`node.rs`). [`KdTree::indices`] lists the
//! leaves' primitives in leaf order, and `Geometry` keeps the triangle
//! corners per entry of it, as for the BVH, so a leaf's triangles are read
//! together (80 bytes per reference: the bunny's 384k references take
//! 31 MB of corners instead of 5.6 MB per triangle; the dragon's 1.65M,
//! 132 MB instead of 70 MB).
//!
//! kd-tree time / BVH time, 1 thread, best of 3 interleaved rounds of
//! `python3 bench.py 3 base=OLD after=NEW`, which runs
//! `whitted bench MODEL.obj --rays /tmp/anchor_rays/MODEL --runs 3 --json`
//! with `--accel bvh` and `--accel kdtree` for each binary in turn
//! (Embree-harness rays; the machine is shared, so cells move by about
//! 10% between runs). Main at b30b870 (eight-wide BVH) → this version:
//!
//! | model | primary | shadow | diffuse |
//! |---|---|---|---|
//! | bunny | 1.57 → 1.24 | 1.84 → 1.54 | 2.44 → 2.07 |
//! | kitchen | 1.49 → 1.18 | 2.94 → 1.35 | 1.57 → 1.47 |
//! | dragon | 1.39 → 1.60 | 1.79 → 1.70 | 1.94 → 1.68 |
//!
//! (Bunny diffuse: 1.94 in the two runs before, at 1.77 Mrays/s against
//! the BVH's 3.06 to 3.43; dragon primary: 1.21 to 1.32 in two of four
//! runs, 1.60 to 1.71 in the other two, not explained.) Three changes:
//! - The to-do stack is no longer cleared for every ray (1.5 kB): 93
//!   fewer instructions a ray (callgrind, an eighth of the bunny's rays),
//!   kitchen shadow rays 8.2 → 11.4 Mrays/s. Its size follows the tree's
//!   depth (32 entries up to depth 32, else 64), like the BVH's; that
//!   alone measured the same as an uncleared 64-entry stack.
//! - The plane crossing has no NaN branch: the tests and bounds are
//!   written so a NaN crossing keeps both children over the node's range
//!   (6% fewer instructions on the kitchen's rays).
//! - The depth limit is 4 + 1.3 log2 N instead of pbrt's 8 + 1.3 log2 N
//!   (bunny 29 → 25): the same trace speed with fewer, slightly larger
//!   leaves; nodes 469,697 → 248,868 and references 384k → 275k on the
//!   bunny (5.30 → 3.09 MB, corners 31 → 22 MB), kitchen 2.87 → 2.14 MB,
//!   dragon 25.7 → 22.3 MB (1.65M → 1.52M references, corners 132 →
//!   122 MB); builds 735 → 539 ms, 415 → 342, 4081 → 3798.
//!
//! Earlier, empty children left out (above) took node steps per ray down
//! by 13 to 17% (bunny diffuse 51.3 → 44.0) and the kd/BVH ratios from
//! 1.45/1.66/2.05 to 1.31/1.54/1.81 on the bunny (against the four-wide
//! BVH); the leaf-ordered corners alone took the dragon's diffuse rays
//! from 0.73 to 0.84 Mrays/s and gave nothing measurable on the bunny.
//!
//! Where the time goes (perf, bunny): the walk is about four fifths of the
//! trace time (a step is about 3 ns for the coherent primary rays, about
//! 11 ns for diffuse ones). 92% of the bunny's diffuse rays leave it
//! without a hit, and one of them takes 42 steps: 16.6 at nodes with one
//! stored child (13.8 meeting it, 2.8 dead ends; only 2.6 of them right
//! after another such node, so merging runs of empty-space cuts into one
//! node would save few steps), 23.6 at nodes with two
//! (7.5 meeting only the near one, 12.3 only the far one, 3.8 both), 1.8
//! leaves. Its 6.3 primitive tests are a tenth of its time: the walk
//! alone, every test skipped, runs at 1.9 Mrays/s against 1.74 with them
//! (counted and timed with throwaway instrumentation).
//!
//! The steps do not wait on memory: replaying the nodes a diffuse ray
//! reads (the first 203k anchor rays) through a simulated cache, a ray
//! touches 20.4 lines of nodes, of which 1.7 miss a 32 kB 8-way L1 and
//! 0.08 a 1 MB L2. What a step waits on can be learnt: the first 256
//! diffuse rays traced 792 times over run at 6.0 to 8.0 Mrays/s against
//! 1.6 for the 203k different ones (the BVH: 6.5 to 7.9 against 3.5;
//! one run of each, both ray slots of the bench), and with the nodes
//! in L1 that leaves the branch predictor. Which child a diffuse ray goes
//! to is close to a coin flip (near only 7.5, far only 12.3 a ray), and
//! the walk needs that choice to be a branch (below).
//!
//! At a node with one stored child there is no choice of node, only
//! whether the ray meets the child. There the end of the range that the
//! crossing clips is picked by a select instead of a branch on the ray's
//! direction (`traverse.rs`, `stored_side`), which leaves one branch, on
//! the 2.8 dead ends among 16.6 such steps. The bunny's diffuse rays went
//! from 1.75 to 1.79 Mrays/s and from 1.69 to 1.77 (kd-tree, 1 thread,
//! medians of the best of 15 runs in each of 4 interleaved rounds;
//! medians of single runs moved +2% to +10% between sets, the machine
//! being noisy); the dragon's from 0.82 to 0.88, the kitchen's 1.99 to
//! 2.14 (medians of 4 rounds of `--accel bvh,kdtree`). At nodes with two
//! children the same selects were slower: with the walk branching on
//! which sides the ray meets (and on its direction only when it meets
//! both), 1.58 against 1.79; the near child picked by a select on a
//! per-ray bit mask of directions held in a register (no load on the
//! way), 1.70 against 1.77. Tried and not kept:
//! - One decision per node: whether the ray meets the below and the above
//!   child computed without branches, the ray's direction on the axis
//!   read from a per-ray mask instead of branched on, then one branch on
//!   the pair: bunny diffuse 1.65 against 1.70 Mrays/s (medians of 12
//!   interleaved runs); with the direction still a branch, 1.63 against
//!   1.62.
//! - The near child picked by a conditional move on that per-ray mask
//!   (the met/not-met tests still branches): 1.60 against 1.70 (16 runs).
//! - The met/not-met tests on the crossing itself, against the node's
//!   range widened by 4γ(3), which takes two multiplications and a
//!   min/max off the path from the node load to the branch: 1.64 against
//!   1.65 (28 runs).
//! - Choosing the next node without a branch (the far child written to
//!   the stack every step, the next entry picked by a select): primary
//!   rays 8.2 → 5.6 Mrays/s, kitchen shadow 9.3 → 4.0. The select makes
//!   each node load wait for the previous step's arithmetic, where a
//!   predicted branch lets the load start early. Even for the bunny's
//!   diffuse rays, whose choices the predictor gets wrong most often, the
//!   walk with the next node, its range and the push chosen by selects
//!   (branches left only for leaves and dead ends) ran at 1.21 against
//!   1.60 Mrays/s (medians of 10 interleaved runs, session 6).
//! - Stopping still earlier: 0 + 1.3 log2 N: bunny diffuse 1.25 against
//!   1.43 Mrays/s. No split of cells of 3 or fewer primitives: the same
//!   speed (1.62 / 1.60). Cost constants: intersection 3 the same (1.58),
//!   an empty factor of 0.6 slower (1.31), 1.0 the same.
//! - Any-hit rays without the mailbox, each primitive still tested alone:
//!   3% fewer instructions on the kitchen, but more triangle tests (bunny
//!   5.01 → 5.76, dragon 5.51 → 5.91 a shadow ray); kitchen shadow 11.1 →
//!   12.2 Mrays/s, bunny 3.25 → 3.17, dragon 1.49 → 1.37 (one run of three
//!   rounds): no clear gain. Kept since (session 6): shadow rays hand
//!   `Geometry` whole leaves without the mailbox, so their triangles go
//!   through the BVH's four-at-once AVX test and one call a leaf instead
//!   of one a primitive. kd-tree shadow rays went from 3.31 to 3.99 Mrays/s
//!   on the bunny, 11.7 to 12.3 on the kitchen and 1.57 to 1.77 on the
//!   dragon, the kd/BVH ratios from 1.73 / 1.49 / 1.93 to 1.45 / 1.41 /
//!   1.74 (1 thread, medians of 4, 4 and 3 interleaved rounds of
//!   `--accel bvh,kdtree` on the anchor rays). Closest hits too, since
//!   session 7: one call a leaf, no mailbox to clear per ray nor index to
//!   read per primitive, the triangles still tested one by one. The
//!   bunny's diffuse rays went from 1.68 to 1.78 Mrays/s (medians of the
//!   best of 10 runs in each of 4 interleaved rounds), its primary rays
//!   from 8.0 to 9.1 and the kitchen's from 5.1 to 5.8, its diffuse rays
//!   within noise (1.97 and 1.94; medians of 4 and 3 rounds of
//!   `--accel bvh,kdtree`). In session 6, without the change above to
//!   nodes with one child, the same had measured +1 to +4%.
//! - Prefetching an interior node's above child as the node is read:
//!   bunny diffuse 1.53 → 1.59 Mrays/s (median of five), shadow 2.80 →
//!   2.36. Taken with the prefetch the eight-wide BVH did not gain from
//!   either, the walk waits less on memory than on its own steps.
//! - Against the eight-wide BVH, the cost constants again (intersection
//!   1.0 and 2.5, empty factor 0.9 and 1.0, depth limits 20, 28 and 31):
//!   none faster than the defaults beyond the runs' noise on the bunny's
//!   diffuse rays; a limit of 20 slower (1.18 against 1.64 Mrays/s).
//!   Once more after the two changes of session 7: intersection 1.2 and
//!   2.0 gave 1.78 and 1.75 against 1.77 Mrays/s, empty factors 0.7 and
//!   0.9 were slower (medians of the best of 8 to 10 runs in 4 rounds).
//! - Loading both children of a node with two before the branches, so a
//!   mispredicted step finds the next node already in a register (the
//!   node's value carried in each to-do entry): bunny diffuse 1.70 →
//!   1.85 Mrays/s on the diffuse rays alone (best of 8 runs, medians of
//!   4 rounds), but the same on the anchor rays, all three kinds (1.79
//!   and 1.84, ratios 1.97 and 1.99; medians of 6 rounds), and primary
//!   and shadow rays slower in a first run.
//! - Scaling the inverse direction by 1 ∓ 2γ(3) once per ray instead of
//!   each crossing by it (one multiplication fewer before the branches):
//!   the bounds still hold the exact crossing, but no longer match the box
//!   test's own rounding, and a box lying on a split plane was missed by
//!   3 ulps (`trees_deeper_than_the_short_stack_are_walked_like_brute_force`).
//!   Its speed, once kept to branches: bunny diffuse rays the same (1.55
//!   against 1.59 Mrays/s, medians of 16 interleaved runs), kitchen +7%,
//!   dragon +3%.
//! - A descent to the origin's leaf before every walk (session 8; kept
//!   since session 10 for rays that keep changing direction, below). A ray
//!   starting inside the root meets the child holding its origin first,
//!   so down to the origin's leaf the next node needs only the origin's
//!   side of each plane: an integer comparison (origin and split as
//!   order-preserving integer keys) right after the node's load, the
//!   other child pushed without a branch. The bunny's diffuse rays take
//!   24.5 such steps of their 42, and 25.6 steps before their first leaf.
//!   Bunny diffuse rays 1.86 → 2.19 Mrays/s (medians of the best of 6
//!   runs in 4 interleaved rounds), but bunny shadow rays 3.26 → 2.81
//!   (best of 10, 6 rounds), the kitchen's primary rays (camera inside the root) 6.22 →
//!   5.26 and shadow rays 12.4 → 10.1 (best of 24 runs), its diffuse rays
//!   the same (2.42 and 2.39). A step of the descent is about 54
//!   instructions: the crossing and both children's ranges are computed
//!   every step, where the walk's branches, well predicted for rays that
//!   go the same way, skip most of that. On the shadow rays alone, the
//!   walk reached the first leaf at 8.7 Mrays/s, the descent at 5.0
//!   (with its choice of child a branch; 4.2 and 4.6 on diffuse rays).
//!   Pushing the other child whenever it is stored and dropping empty
//!   ranges when popping was no better (bunny diffuse 1.98, kitchen
//!   shadow 9.3).
//! - Session 9, against the code above (kd-tree, 1 thread, medians of the
//!   best of 6 runs in 4 interleaved rounds on the bunny's anchor rays,
//!   of the best of 3 in 3 rounds on the dragon's):
//!   - The corners kept once per primitive (the bunny's 69k triangles,
//!     5.6 MB, instead of its 275k references, 22 MB) and reached through
//!     [`KdTree::indices`]: bunny diffuse 1.89 → 1.80 Mrays/s, shadow
//!     3.79 → 3.61, dragon shadow 1.65 → 1.27. The second random read
//!     costs more than the smaller footprint saves.
//!   - A prefetch of the far child's node as it is pushed: bunny diffuse
//!     1.96 → 1.91, dragon shadow 1.55 → 1.42.
//!   - The mailbox back on closest hits in leaf order (each reference's
//!     primitive number read from its corners' line): 1.93 and 1.94.
//!   - Closest hits testing runs of leaf triangles four at a time, as
//!     shadow rays do: kd-tree diffuse 1.77 and 1.75, the BVH's 4.0 → 3.2
//!     (the two binaries one after the other, not interleaved).
//!
//! Kept since session 10: the descent to the origin's leaf, for rays the
//! caller says are incoherent ([`crate::accel::with_ray_coherence`];
//! `whitted bench` says so of its diffuse rays). A ray starting inside the
//! tree then first goes down the cells holding its origin, choosing each
//! child by the origin's side of the plane (a branch neighbouring origins
//! take alike) and pushing the other without a branch on the direction
//! (`traverse.rs`, `descend`); it also goes through empty-space cuts whose
//! stored child holds the origin. Other rays walk from the root as before.
//! Kd-tree, 1 thread, Mrays/s before → after, medians of the best of 4
//! runs in 4 interleaved rounds (bunny) and of 3 or 4 runs in 3 rounds
//! (dragon, kitchen), with `python3 best2.py MODEL kdtree
//! primary,shadow,diffuse ROUNDS RUNS /tmp/anchor_rays OLD NEW`, which
//! alternates `whitted bench MODEL.obj --rays DIR --accel kdtree --runs
//! RUNS --json` between two binaries (measured with the choice made as
//! below, which took the descent for exactly the diffuse rays):
//!
//! | model | primary | shadow | diffuse |
//! |---|---|---|---|
//! | bunny | 11.15 → 11.07 | 3.91 → 3.91 | 2.00 → 2.29 |
//! | dragon | 8.39 → 8.56 | 1.73 → 1.75 | 1.03 → 1.22 |
//! | kitchen | 6.05 → 6.22 | 12.39 → 12.22 | 2.43 → 2.51 |
//!
//! Tried on the way and not kept:
//! - The descent for every ray starting inside the tree (an environment
//!   switch in a throwaway build), measured as in session 8: bunny diffuse
//!   2.05 → 2.23, but bunny shadow 3.89 → 3.62, kitchen primary (the
//!   camera inside the tree) 6.24 → 5.50 and kitchen shadow 12.5 → 9.87.
//!   With the children's ranges clipped by bounds chosen off the chain
//!   from one node's range to the next (one `min` and one `max` a step on
//!   it), the bunny's shadow rays still went from 3.86 to 2.99 (bests of
//!   4 rounds of 4 runs).
//! - The choice made without the caller: each thread kept a running share
//!   of its queries whose direction octant differed from the query
//!   before's, and took the descent above a third. It chose right for the
//!   ray files, but a render's rays change octant from one shadow ray to
//!   the next when there are several lights, while the branch predictor
//!   still learns the pattern each pixel repeats: rendering `gears.nff`
//!   (five lights) at 800 × 800 on 1 thread went from 1.96 to 2.19 s
//!   (best of 5 interleaved runs).
//! - The origin's side compared as order-preserving integer keys instead
//!   of floats: bunny diffuse 2.22 → 2.17, primary 10.9 → 10.5.

mod build;
mod check;
mod events;
mod node;
mod sah;
mod traverse;

#[cfg(test)]
mod tests;

use crate::math::Aabb;
use node::KdNode;

/// Options of the kd-tree build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdTreeBuildParams {
    /// Cost of one traversal step.
    pub traversal_cost: f64,
    /// Cost of one primitive test, relative to a traversal step.
    pub intersection_cost: f64,
    /// Multiplies the cost of a split that leaves one side empty (below 1
    /// favours cutting off empty space).
    pub empty_factor: f64,
    /// Deepest leaf allowed; `None` means 4 + 1.3 log2 N. Always capped at
    /// the traversal stack's 64 entries.
    pub max_depth: Option<usize>,
}

impl Default for KdTreeBuildParams {
    fn default() -> Self {
        Self {
            traversal_cost: 1.0,
            intersection_cost: 1.5,
            empty_factor: 0.8,
            max_depth: None,
        }
    }
}

/// A kd-tree over primitive boxes.
///
/// Its queries start the walk of a ray at its origin's leaf when the
/// caller says the rays are incoherent ([`crate::accel::with_ray_coherence`]),
/// at the root otherwise. Only their speed depends on it: both starts
/// return the same closest `t` (on an exact tie, possibly another
/// primitive).
#[derive(Clone, Debug)]
pub struct KdTree {
    /// The nodes, root first, each below child right after its parent.
    nodes: Vec<KdNode>,
    /// The leaves' primitives, each leaf a contiguous run, then those of
    /// `loose` in its order.
    indices: Vec<u32>,
    /// The root cell: the placed boxes' union, widened to `f32`.
    bounds: Aabb,
    /// Primitives whose boxes could not be placed, with their boxes (also
    /// at the end of `indices`).
    loose: Vec<(u32, Aabb)>,
    /// The depth of the deepest leaf (the root's is 0), at most the
    /// traversal stack's capacity: it picks the stack a walk uses.
    max_depth: usize,
}

impl KdTree {
    /// A tree over primitives `0..boxes.len()` with these boxes, built with
    /// the default options.
    pub fn build(boxes: &[Aabb]) -> Self {
        Self::build_with(boxes, &KdTreeBuildParams::default())
    }

    /// A tree over primitives `0..boxes.len()` with these boxes.
    pub fn build_with(boxes: &[Aabb], params: &KdTreeBuildParams) -> Self {
        build::build(boxes, params, None).0
    }

    /// A tree over primitives `0..boxes.len()` with these boxes, whose
    /// straddling primitives are clipped to the cells by `clip` ("perfect
    /// splits"). Validate it with [`KdTree::validate_clipped`].
    pub fn build_clipped(boxes: &[Aabb], params: &KdTreeBuildParams, clip: Clipper) -> Self {
        build::build(boxes, params, Some(clip)).0
    }

    /// The primitive numbers the leaf-order queries' positions refer to
    /// ([`KdTree::intersect_in_leaf_order`]): each leaf's as a contiguous
    /// run (a primitive appears once per leaf that holds it), then those
    /// kept aside.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }
}

/// The bounds of primitive `i` inside the closed box `cell`, or `None`
/// when the primitive does not meet it. It must be conservative: every
/// point of the primitive inside `cell` lies in the returned box (which
/// the build then intersects with the primitive's box and the cell).
pub type Clipper<'a> = &'a dyn Fn(u32, &Aabb) -> Option<Aabb>;

/// The cells below and above `plane` on `axis`.
fn split_cell(cell: &Aabb, axis: usize, plane: f64) -> [Aabb; 2] {
    let mut below = *cell;
    below.max[axis] = plane;
    let mut above = *cell;
    above.min[axis] = plane;
    [below, above]
}
