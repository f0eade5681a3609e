//! Triangles covering a polygon by the even-odd rule, the rule
//! [`crate::shape::Polygon`] tests points with, for any outline, also one
//! that crosses itself.
//!
//! A simple outline (no two edges meet but neighbours at their shared
//! corner) is ear-clipped over its own corners ([`fn@super::triangulate`]).
//! One that crosses itself is cut, in its plane, into vertical slabs at
//! every corner and every crossing: inside a slab no two edges cross, so
//! the edges spanning it, sorted bottom to top, bound the inside in pairs
//! (first and second, third and fourth, ...), each pair a trapezoid of two
//! triangles. Their corners lie on the polygon's edges ([`Corner::OnEdge`]),
//! so a caller interpolates whatever the corners carry (normals, texture
//! coordinates) along the edge a triangle corner lies on.
//!
//! Hostile input stays cheap: an outline of more than [`MAX_CHECKED`]
//! corners is taken as simple, and one that crosses itself so often that
//! the slabs would cost more than [`MAX_SLAB_WORK`] steps is ear-clipped;
//! both then cover their overlaps once.

use super::triangulate::{newell_normal, project, triangulate};
use crate::math::{DVec2, Vec3};

/// A corner of a triangle of the cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Corner {
    /// The polygon's corner `i`.
    Vertex(usize),
    /// The point at `t` in `(0, 1)` along the edge from corner `edge` to the
    /// next one.
    OnEdge {
        /// The edge's first corner.
        edge: usize,
        /// How far along the edge.
        t: f64,
    },
}

impl Corner {
    /// The point it stands for, on the polygon `points`; attributes carried
    /// by the corners are interpolated the same way.
    pub fn lerp<T>(&self, values: &[T]) -> T
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
    {
        match *self {
            Corner::Vertex(i) => values[i],
            Corner::OnEdge { edge, t } => {
                let next = (edge + 1) % values.len();
                values[edge] * (1.0 - t) + values[next] * t
            }
        }
    }
}

/// The triangles covering the polygon `points` by the even-odd rule, each
/// wound like the polygon (counter-clockwise about its Newell normal), as
/// corners. A simple outline gives `n - 2` triangles over its own corners.
pub fn triangulate_even_odd(points: &[Vec3]) -> Vec<[Corner; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    let normal = newell_normal(points);
    let flat = project(points, normal);
    let ear_clipped = || {
        triangulate(points)
            .into_iter()
            .map(|t| t.map(Corner::Vertex))
            .collect()
    };
    if n == 3 || !crosses_itself(&flat) {
        return ear_clipped();
    }
    slabs(&flat).unwrap_or_else(ear_clipped)
}

/// The most slab-edge pairs the slab cover may visit (a second or so): an
/// outline that crosses itself more than that is ear-clipped instead, its
/// overlaps covered once.
pub const MAX_SLAB_WORK: usize = 20_000_000;

/// The most corners an outline may have for the check that it crosses
/// itself (which costs `n²`); a longer one is taken as simple.
pub const MAX_CHECKED: usize = 4096;

/// True when two edges that are not neighbours meet, or two neighbours
/// overlap beyond their shared corner.
fn crosses_itself(flat: &[DVec2]) -> bool {
    let n = flat.len();
    if n > MAX_CHECKED {
        return false;
    }
    let edge = |i: usize| (flat[i], flat[(i + 1) % n]);
    (0..n).any(|i| {
        (i + 1..n).any(|j| {
            let neighbours = j == i + 1 || (i == 0 && j == n - 1);
            let (a, b) = edge(i);
            let (c, d) = edge(j);
            if neighbours {
                // Collinear and folding back over each other.
                let (shared, p, q) = if j == i + 1 { (b, a, d) } else { (a, b, c) };
                (p - shared).perp_dot(q - shared) == 0.0 && (p - shared).dot(q - shared) > 0.0
            } else {
                segments_meet(a, b, c, d)
            }
        })
    })
}

/// True when the closed segments `ab` and `cd` share a point.
fn segments_meet(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let side = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let (d1, d2) = (side(c, d, a), side(c, d, b));
    let (d3, d4) = (side(a, b, c), side(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        side(p, q, r) == 0.0
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on(c, d, a) || on(c, d, b) || on(a, b, c) || on(a, b, d)
}

/// The even-odd cover of a self-crossing outline by vertical slabs; `None`
/// past [`MAX_SLAB_WORK`].
fn slabs(flat: &[DVec2]) -> Option<Vec<[Corner; 3]>> {
    let n = flat.len();
    let edge = |i: usize| (flat[i], flat[(i + 1) % n]);
    // Slab boundaries: every corner's x and every crossing's.
    let mut xs: Vec<f64> = flat.iter().map(|p| p.x).collect();
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = edge(i);
            let (c, d) = edge(j);
            let denominator = (b - a).perp_dot(d - c);
            if denominator == 0.0 {
                continue;
            }
            let s = (c - a).perp_dot(d - c) / denominator;
            let u = (c - a).perp_dot(b - a) / denominator;
            if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&u) {
                xs.push(a.x + s * (b.x - a.x));
                if xs.len().saturating_mul(n) > MAX_SLAB_WORK {
                    return None;
                }
            }
        }
    }
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    if xs.len().saturating_mul(n) > MAX_SLAB_WORK {
        return None;
    }
    let mut triangles = Vec::new();
    for pair in xs.windows(2) {
        let (x0, x1) = (pair[0], pair[1]);
        let middle = 0.5 * (x0 + x1);
        // The edges spanning the slab: at each side, where they are.
        let mut spanning: Vec<(f64, Corner, Corner, DVec2, DVec2)> = (0..n)
            .filter_map(|i| {
                let (a, b) = edge(i);
                if a.x.min(b.x) >= middle || a.x.max(b.x) <= middle {
                    return None;
                }
                let at = |x: f64| {
                    let t = (x - a.x) / (b.x - a.x);
                    let point = DVec2::new(x, a.y + t * (b.y - a.y));
                    let corner = if t <= 0.0 {
                        Corner::Vertex(i)
                    } else if t >= 1.0 {
                        Corner::Vertex((i + 1) % n)
                    } else {
                        Corner::OnEdge { edge: i, t }
                    };
                    (corner, point)
                };
                let (left, left_point) = at(x0);
                let (right, right_point) = at(x1);
                let y_middle = a.y + (middle - a.x) / (b.x - a.x) * (b.y - a.y);
                Some((y_middle, left, right, left_point, right_point))
            })
            .collect();
        spanning.sort_by(|p, q| p.0.total_cmp(&q.0));
        for pair in spanning.chunks_exact(2) {
            let (_, bottom_left, bottom_right, bl, br) = pair[0];
            let (_, top_left, top_right, tl, tr) = pair[1];
            // Counter-clockwise in the plane, as the projection keeps the
            // polygon's own winding counter-clockwise.
            for (corners, points) in [
                ([bottom_left, bottom_right, top_right], [bl, br, tr]),
                ([bottom_left, top_right, top_left], [bl, tr, tl]),
            ] {
                if (points[1] - points[0]).perp_dot(points[2] - points[0]) > 0.0 {
                    triangles.push(corners);
                }
            }
        }
    }
    Some(triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Twice the area covered, from the triangles' corners in the plane.
    fn area(points: &[Vec3], triangles: &[[Corner; 3]]) -> f64 {
        triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| k.lerp(points));
                (b - a).cross(c - a).length()
            })
            .sum::<f64>()
            / 2.0
    }

    #[test]
    fn a_bow_tie_is_covered_by_its_two_wings() {
        // Two triangles meeting at (1.2, 1.2), of areas 1.2 and 2.7 (a
        // symmetric bow tie has no Newell normal, so no plane).
        let bow = [(0, 0), (3, 3), (3, 0), (0, 2)]
            .map(|(x, y)| Vec3::new(f64::from(x), f64::from(y), 0.0));
        let triangles = triangulate_even_odd(&bow);
        assert!(
            (area(&bow, &triangles) - 3.9).abs() < 1e-12,
            "{}",
            area(&bow, &triangles)
        );
        assert!(
            triangles
                .iter()
                .flatten()
                .any(|c| matches!(c, Corner::OnEdge { .. }))
        );
    }

    #[test]
    fn a_pentagram_has_a_hole_where_it_overlaps_itself() {
        // Each corner to the second next: the inner pentagon is covered
        // twice, so by the even-odd rule it is outside.
        let corners: Vec<Vec3> = (0..5)
            .map(|k| {
                let angle = std::f64::consts::TAU * f64::from(2 * k) / 5.0;
                Vec3::new(angle.cos(), angle.sin(), 0.0)
            })
            .collect();
        let triangles = triangulate_even_odd(&corners);
        // Every sample of a fine grid is covered exactly when an even-odd
        // count puts it inside.
        let flat: Vec<DVec2> = corners.iter().map(|p| DVec2::new(p.x, p.y)).collect();
        let inside = |p: DVec2| {
            let mut odd = false;
            for i in 0..flat.len() {
                let (a, b) = (flat[i], flat[(i + 1) % flat.len()]);
                if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x)
                {
                    odd = !odd;
                }
            }
            odd
        };
        let covered = |p: DVec2| {
            triangles.iter().any(|t| {
                let [a, b, c] = t.map(|k| {
                    let q = k.lerp(&corners);
                    DVec2::new(q.x, q.y)
                });
                let s = |p0: DVec2, p1: DVec2| (p1 - p0).perp_dot(p - p0);
                s(a, b) >= 0.0 && s(b, c) >= 0.0 && s(c, a) >= 0.0
            })
        };
        let mut checked = 0;
        for i in 0..200 {
            for j in 0..200 {
                let p = DVec2::new(
                    -1.0 + 0.01 * f64::from(i) + 0.003,
                    -1.0 + 0.01 * f64::from(j) + 0.007,
                );
                assert_eq!(covered(p), inside(p), "{p}");
                checked += usize::from(inside(p));
            }
        }
        assert!(checked > 3000, "{checked}");
    }

    #[test]
    fn a_simple_outline_keeps_its_own_corners() {
        let l = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
            .map(|(x, y)| Vec3::new(f64::from(x), f64::from(y), 0.0));
        let triangles = triangulate_even_odd(&l);
        assert_eq!(triangles.len(), 4);
        assert!(
            triangles
                .iter()
                .flatten()
                .all(|c| matches!(c, Corner::Vertex(_)))
        );
        assert!((area(&l, &triangles) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn an_outline_crossing_itself_millions_of_times_is_ear_clipped_in_bounded_time() {
        let mut rng = crate::math::random::Rng::new(3);
        let n = 3000;
        let tangle: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0))
            .collect();
        let triangles = triangulate_even_odd(&tangle);
        assert_eq!(triangles.len(), n - 2);
        assert!(
            triangles
                .iter()
                .flatten()
                .all(|c| matches!(c, Corner::Vertex(_)))
        );
    }
}
