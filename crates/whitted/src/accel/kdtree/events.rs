//! Split events: where a primitive's box starts, ends or lies flat on one
//! axis (Wald and Havran 2006, section 4). Each node keeps one list per axis
//! sorted by position, ends before flat ("planar") events before starts at
//! the same position, so one sweep counts the primitives on each side of
//! every candidate plane.
//!
//! Boxes are first widened outwards to the `f32` grid: every event, and so
//! every split plane, is then exactly the `f32` a node stores, and a
//! primitive is assigned to children against the very plane traversal
//! tests.

use crate::math::{Aabb, Vec3};

/// What happens to a primitive at an event's position.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum EventKind {
    /// Its box ends here.
    End,
    /// Its box is flat here (zero extent on this axis).
    Planar,
    /// Its box starts here.
    Start,
}

/// One event on one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Event {
    /// Where on the axis (an `f32` value, never `-0.0`).
    pub(super) position: f64,
    /// Which primitive.
    pub(super) primitive: u32,
    /// Start, end or planar.
    pub(super) kind: EventKind,
}

/// One sorted event list per axis.
pub(super) type EventLists = [Vec<Event>; 3];

/// The smallest box with `f32` corners around `b`, or `None` when `b` is
/// empty or does not fit in `f32` (infinite or NaN corners, or beyond
/// `f32::MAX`).
pub(super) fn snap_outward(b: &Aabb) -> Option<Aabb> {
    let min = Vec3::from_array(b.min.to_array().map(round_down));
    let max = Vec3::from_array(b.max.to_array().map(round_up));
    let snapped = Aabb { min, max };
    (snapped.is_finite() && !snapped.is_empty()).then_some(snapped)
}

/// The largest `f32` at or below `x`, as `f64` (`+0.0` for zero).
fn round_down(x: f64) -> f64 {
    let f = x as f32;
    let f = if f64::from(f) > x { f.next_down() } else { f };
    f64::from(f) + 0.0
}

/// The smallest `f32` at or above `x`, as `f64` (`+0.0` for zero).
fn round_up(x: f64) -> f64 {
    let f = x as f32;
    let f = if f64::from(f) < x { f.next_up() } else { f };
    f64::from(f) + 0.0
}

/// Appends the events of `primitive`, whose (snapped) box is `b`, to the
/// lists of every axis, unsorted.
pub(super) fn push_events(b: &Aabb, primitive: u32, lists: &mut EventLists) {
    for (axis, list) in lists.iter_mut().enumerate() {
        let (min, max) = (b.min[axis], b.max[axis]);
        if min == max {
            list.push(Event {
                position: min,
                primitive,
                kind: EventKind::Planar,
            });
        } else {
            list.push(Event {
                position: min,
                primitive,
                kind: EventKind::Start,
            });
            list.push(Event {
                position: max,
                primitive,
                kind: EventKind::End,
            });
        }
    }
}

/// Sorts a list by position, then kind.
pub(super) fn sort_events(list: &mut [Event]) {
    list.sort_unstable_by(|a, b| a.position.total_cmp(&b.position).then(a.kind.cmp(&b.kind)));
}

/// Merges two sorted lists into one, in linear time.
pub(super) fn merge(a: Vec<Event>, b: Vec<Event>) -> Vec<Event> {
    if b.is_empty() {
        return a;
    }
    let mut out = Vec::with_capacity(a.len() + b.len());
    let mut b = b.into_iter().peekable();
    for e in a {
        while let Some(f) = b.next_if(|f| (f.position, f.kind) < (e.position, e.kind)) {
            out.push(f);
        }
        out.push(e);
    }
    out.extend(b);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    #[test]
    fn snapping_widens_to_f32_and_keeps_exact_values() {
        let b = Aabb::new(Vec3::new(0.1, -0.0, -1e-300), Vec3::new(0.3, 2.0, 1e-300));
        let s = snap_outward(&b).unwrap();
        assert!(s.min.cmple(b.min).all() && s.max.cmpge(b.max).all());
        for v in s.min.to_array().into_iter().chain(s.max.to_array()) {
            assert_eq!(f64::from(v as f32), v);
            assert!(v != 0.0 || v.is_sign_positive(), "-0.0 must become +0.0");
        }
        assert_eq!((s.min.y, s.max.y), (0.0, 2.0));
        assert!(s.max.x > 0.3 && s.max.x - 0.3 < 1e-7);
        assert!(s.min.z < 0.0 && s.min.z > -1e-44 && s.max.z == -s.min.z);
    }

    #[test]
    fn boxes_beyond_f32_or_not_finite_or_empty_are_refused() {
        let huge = Aabb::new(Vec3::ZERO, Vec3::splat(1e39));
        let nan = Aabb::new(Vec3::ZERO, Vec3::new(f64::NAN, 1.0, 1.0));
        for b in [huge, nan, Aabb::INFINITE, Aabb::EMPTY] {
            assert_eq!(snap_outward(&b), None, "{b:?}");
        }
        let f32_max = Aabb::new(Vec3::ZERO, Vec3::splat(f64::from(f32::MAX)));
        assert_eq!(snap_outward(&f32_max), Some(f32_max));
    }

    #[test]
    fn flat_boxes_give_planar_events_and_others_a_start_and_an_end() {
        let mut lists = EventLists::default();
        push_events(
            &Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 2.0)),
            4,
            &mut lists,
        );
        assert_eq!(lists[0].len(), 2);
        assert_eq!(lists[1][0].kind, EventKind::Planar);
        assert_eq!(lists[2][1].position, 2.0);
    }

    #[test]
    fn merging_sorted_lists_equals_sorting_their_union() {
        let mut rng = Rng::new(3);
        let mut random_list = |n: usize| {
            let mut lists = EventLists::default();
            for i in 0..n {
                let a = f64::from(rng.below(20));
                let b = a + f64::from(rng.below(3));
                push_events(
                    &Aabb::new(Vec3::splat(a), Vec3::splat(b)),
                    i as u32,
                    &mut lists,
                );
            }
            let [mut list, _, _] = lists;
            sort_events(&mut list);
            list
        };
        let (a, b) = (random_list(50), random_list(30));
        let merged = merge(a.clone(), b.clone());
        let mut sorted = [a, b].concat();
        sort_events(&mut sorted);
        let key = |l: &[Event]| l.iter().map(|e| (e.position, e.kind)).collect::<Vec<_>>();
        assert_eq!(key(&merged), key(&sorted));
    }
}
