//! The surface area heuristic and the sweep that finds a node's cheapest
//! split plane (Wald and Havran 2006, sections 4.2 and 4.3).
//!
//! A primitive whose box straddles the plane counts on both sides; one that
//! only touches it counts on the side it lies on (its box is inside that
//! closed half-space), and one lying flat in the plane on the side that
//! makes the split cheaper. The build assigns them the same way.

use super::events::{Event, EventKind, EventLists};
use crate::math::Aabb;

/// The cost model of the build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Costs {
    /// One traversal step.
    pub(super) traversal: f64,
    /// One primitive test.
    pub(super) intersection: f64,
    /// Multiplies the cost of a split that leaves one side empty.
    pub(super) empty_factor: f64,
}

impl Costs {
    /// The cost of a leaf holding `count` primitives.
    pub(super) fn leaf(&self, count: usize) -> f64 {
        self.intersection * count as f64
    }

    /// The cost of a split whose sides are hit with probabilities `p_below`
    /// and `p_above` and hold `n_below` and `n_above` primitives.
    fn split(&self, p_below: f64, p_above: f64, n_below: usize, n_above: usize) -> f64 {
        let factor = if n_below == 0 || n_above == 0 {
            self.empty_factor
        } else {
            1.0
        };
        let tests = p_below * n_below as f64 + p_above * n_above as f64;
        factor * (self.traversal + self.intersection * tests)
    }
}

/// A chosen split plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Split {
    /// 0, 1 or 2 for x, y, z.
    pub(super) axis: usize,
    /// The plane's position: an event position, so an exact `f32`.
    pub(super) position: f64,
    /// Whether primitives lying flat in the plane go below it.
    pub(super) planar_below: bool,
    /// Its estimated cost.
    pub(super) cost: f64,
}

/// The cheapest split of the cell `cell` holding `count` primitives with
/// these events, if one is cheaper than a leaf. Only planes strictly inside
/// the cell are considered, so every split shrinks both children's cells.
pub(super) fn best_split(
    cell: &Aabb,
    events: &EventLists,
    count: usize,
    costs: &Costs,
) -> Option<Split> {
    let area = cell.surface_area();
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let mut best: Option<Split> = None;
    let mut best_cost = costs.leaf(count);
    for (axis, list) in events.iter().enumerate() {
        let side_area = SideArea::new(cell, axis, area);
        // Primitives starting (or flat) before the current position, and
        // those not ended (nor flat) before it.
        let (mut before, mut after) = (0, count);
        let mut rest = list.as_slice();
        while let Some(first) = rest.first() {
            let position = first.position;
            let ends = run(&mut rest, position, EventKind::End);
            let planars = run(&mut rest, position, EventKind::Planar);
            let starts = run(&mut rest, position, EventKind::Start);
            if position > cell.min[axis] && position < cell.max[axis] {
                let (p_below, p_above) = side_area.probabilities(position);
                let n_below = before;
                let n_above = after - planars - ends;
                let planar_below = costs.split(p_below, p_above, n_below + planars, n_above);
                let planar_above = costs.split(p_below, p_above, n_below, n_above + planars);
                let cost = planar_below.min(planar_above);
                if cost < best_cost {
                    best_cost = cost;
                    best = Some(Split {
                        axis,
                        position,
                        planar_below: planar_below <= planar_above,
                        cost,
                    });
                }
            }
            before += starts + planars;
            after -= ends + planars;
        }
    }
    best
}

/// Counts and skips the events of `kind` at `position` at the head of
/// `rest`.
fn run(rest: &mut &[Event], position: f64, kind: EventKind) -> usize {
    let n = rest
        .iter()
        .take_while(|e| e.position == position && e.kind == kind)
        .count();
    *rest = &rest[n..];
    n
}

/// The surface areas of a cell's two sides as a plane moves along an axis.
struct SideArea {
    min: f64,
    max: f64,
    /// Twice the area of the plane's cross-section of the cell.
    caps: f64,
    /// Twice the perimeter of the cross-section.
    ring: f64,
    inv_area: f64,
}

impl SideArea {
    fn new(cell: &Aabb, axis: usize, area: f64) -> Self {
        let e = cell.extent();
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        Self {
            min: cell.min[axis],
            max: cell.max[axis],
            caps: 2.0 * e[u] * e[v],
            ring: 2.0 * (e[u] + e[v]),
            inv_area: 1.0 / area,
        }
    }

    /// The probabilities that a ray through the cell meets each side of a
    /// plane at `position`.
    fn probabilities(&self, position: f64) -> (f64, f64) {
        let below = self.caps + self.ring * (position - self.min);
        let above = self.caps + self.ring * (self.max - position);
        (below * self.inv_area, above * self.inv_area)
    }
}

#[cfg(test)]
mod tests {
    use super::super::events::{push_events, sort_events};
    use super::*;
    use crate::math::Vec3;

    const COSTS: Costs = Costs {
        traversal: 1.0,
        intersection: 1.5,
        empty_factor: 0.8,
    };

    fn lists(boxes: &[Aabb]) -> (Aabb, EventLists) {
        let mut lists = EventLists::default();
        for (i, b) in boxes.iter().enumerate() {
            push_events(b, i as u32, &mut lists);
        }
        lists.iter_mut().for_each(|l| sort_events(l));
        let cell = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
        (cell, lists)
    }

    fn cube(min: Vec3, size: f64) -> Aabb {
        Aabb::new(min, min + Vec3::splat(size))
    }

    #[test]
    fn two_far_apart_clusters_are_split_in_the_gap() {
        let boxes: Vec<Aabb> = (0..8)
            .map(|i| cube(Vec3::new(f64::from(i % 2) * 100.0, 0.0, 0.0), 1.0))
            .collect();
        let (cell, events) = lists(&boxes);
        let split = best_split(&cell, &events, boxes.len(), &COSTS).unwrap();
        assert_eq!(split.axis, 0);
        assert!(split.position == 1.0 || split.position == 100.0);
    }

    #[test]
    fn identical_boxes_and_a_single_box_stay_leaves() {
        let same = vec![cube(Vec3::ONE, 2.0); 50];
        let (cell, events) = lists(&same);
        assert_eq!(best_split(&cell, &events, 50, &COSTS), None);
        let (cell, events) = lists(&same[..1]);
        assert_eq!(best_split(&cell, &events, 1, &COSTS), None);
    }

    #[test]
    fn the_side_a_flat_box_goes_to_is_the_cheaper_one() {
        // Forty flat squares at x = 4 on the face of a cube in [0, 4], and a
        // far cube: the cut at x = 4 is cheap only with the squares kept in
        // the small cell below it.
        let mut boxes = vec![cube(Vec3::ZERO, 4.0)];
        boxes
            .extend((0..40).map(|_| Aabb::new(Vec3::new(4.0, 0.0, 0.0), Vec3::new(4.0, 4.0, 4.0))));
        boxes.push(cube(Vec3::new(40.0, 0.0, 0.0), 4.0));
        let (cell, events) = lists(&boxes);
        let split = best_split(&cell, &events, boxes.len(), &COSTS).unwrap();
        assert_eq!((split.axis, split.position), (0, 4.0));
        assert!(split.planar_below);
    }

    #[test]
    fn boxes_touching_the_plane_count_on_their_own_side_only() {
        // Two cubes meeting at x = 1: the plane there separates them.
        let boxes = [cube(Vec3::ZERO, 1.0), cube(Vec3::X, 1.0)];
        let (cell, events) = lists(&boxes);
        let split = best_split(&cell, &events, 2, &COSTS).unwrap();
        assert_eq!((split.axis, split.position), (0, 1.0));
        // 1 + 1.5 (0.6 · 1 + 0.6 · 1): one cube on each side.
        assert!((split.cost - 2.8).abs() < 1e-12, "{split:?}");
    }
}
