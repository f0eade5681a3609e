//! Polygons to triangles by ear clipping in the polygon's own plane, so
//! concave faces come out right (a fan, as most loaders do, covers the
//! notch of an L).

use crate::math::{DVec2, Vec3};

/// The polygon's normal by Newell's method (not unit; zero when the
/// polygon has no area). Robust for concave and slightly non-planar faces.
pub fn newell_normal(points: &[Vec3]) -> Vec3 {
    let mut normal = Vec3::ZERO;
    for (i, p) in points.iter().enumerate() {
        let q = points[(i + 1) % points.len()];
        normal += Vec3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    normal
}

/// Triangles over the corners `0..points.len()` covering the polygon, each
/// wound like the polygon. Degenerate or self-intersecting polygons still
/// give `n - 2` triangles: when no corner is an ear, a convex corner (or
/// else the one where the search stands) is clipped anyway.
///
/// The search for the next ear goes on from the corner before the last one
/// clipped, whose neighbour changed, and only corners that are not convex
/// can lie inside a candidate ear: so a simple face of `n` corners costs
/// about `n` times its count of reflex corners, not `n³`. A face that is
/// not simple can make every search fail; after [`EAR_TESTS`] corner tests
/// the rest of such a face is clipped as a fan.
pub fn triangulate(points: &[Vec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    let normal = newell_normal(points);
    let flat = project(points, normal);
    let mut remaining: Vec<usize> = (0..n).collect();
    let mut blocking: Vec<usize> = (0..n)
        .filter(|&i| !is_convex(&flat, &remaining, i))
        .collect();
    let mut triangles = Vec::with_capacity(n - 2);
    let (mut at, mut misses, mut tests) = (0, 0, 0);
    while remaining.len() > 3 && tests < EAR_TESTS {
        let count = remaining.len();
        at %= count;
        tests += blocking.len();
        let clip = if is_ear(&flat, &remaining, &blocking, at) {
            Some(at)
        } else if misses + 1 >= count {
            Some(
                (0..count)
                    .find(|&i| is_convex(&flat, &remaining, i))
                    .unwrap_or(at),
            )
        } else {
            None
        };
        let Some(ear) = clip else {
            misses += 1;
            at += 1;
            continue;
        };
        triangles.push(corners(&remaining, ear));
        blocking.retain(|&k| k != remaining[ear]);
        remaining.remove(ear);
        // The clipped corner's neighbours may have become convex.
        let count = remaining.len();
        let before = (ear + count - 1) % count;
        for i in [before, ear % count] {
            let corner = remaining[i];
            let convex = is_convex(&flat, &remaining, i);
            let listed = blocking.contains(&corner);
            if convex && listed {
                blocking.retain(|&k| k != corner);
            } else if !convex && !listed {
                blocking.push(corner);
            }
        }
        at = before;
        misses = 0;
    }
    triangles
        .extend((1..remaining.len() - 1).map(|k| [remaining[0], remaining[k], remaining[k + 1]]));
    triangles
}

/// The most corner-in-ear tests spent on one face (a fraction of a second).
pub const EAR_TESTS: usize = 100_000_000;

/// The points in 2D, dropping the normal's largest axis and keeping the
/// winding counter-clockwise.
pub(super) fn project(points: &[Vec3], normal: Vec3) -> Vec<DVec2> {
    let a = normal.abs();
    let (x, y, sign) = if a.x >= a.y && a.x >= a.z {
        (1, 2, normal.x)
    } else if a.y >= a.z {
        (2, 0, normal.y)
    } else {
        (0, 1, normal.z)
    };
    let flip = if sign < 0.0 { -1.0 } else { 1.0 };
    points
        .iter()
        .map(|p| DVec2::new(p[x], flip * p[y]))
        .collect()
}

/// The corners of the ear centred on `remaining[i]`: previous, it, next.
fn corners(remaining: &[usize], i: usize) -> [usize; 3] {
    let count = remaining.len();
    [
        remaining[(i + count - 1) % count],
        remaining[i],
        remaining[(i + 1) % count],
    ]
}

fn cross(o: DVec2, a: DVec2, b: DVec2) -> f64 {
    (a - o).perp_dot(b - o)
}

fn is_convex(flat: &[DVec2], remaining: &[usize], i: usize) -> bool {
    let [a, b, c] = corners(remaining, i).map(|k| flat[k]);
    cross(a, b, c) > 0.0
}

/// A convex corner whose triangle holds none of the `blocking` corners
/// (those remaining that are not convex: a convex corner cannot lie inside
/// an ear of a simple polygon). Points on the triangle's edges count as
/// inside.
fn is_ear(flat: &[DVec2], remaining: &[usize], blocking: &[usize], i: usize) -> bool {
    if !is_convex(flat, remaining, i) {
        return false;
    }
    let ids = corners(remaining, i);
    let [a, b, c] = ids.map(|k| flat[k]);
    blocking.iter().all(|&k| {
        let p = flat[k];
        ids.contains(&k)
            || p == a
            || p == b
            || p == c
            || cross(a, b, p) < 0.0
            || cross(b, c, p) < 0.0
            || cross(c, a, p) < 0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(points: &[Vec3], triangles: &[[usize; 3]]) -> f64 {
        triangles
            .iter()
            .map(|&[a, b, c]| 0.5 * (points[b] - points[a]).cross(points[c] - points[a]).z)
            .sum()
    }

    #[test]
    fn a_concave_l_is_covered_exactly_and_the_notch_stays_empty() {
        // An L in the xy plane: a 2x2 square without its top-right quarter.
        let l = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
            .map(|(x, y)| Vec3::new(f64::from(x), f64::from(y), 0.0));
        // Starting at the reflex corner, a fan would cover the notch.
        for start in 0..l.len() {
            let rotated: Vec<Vec3> = (0..l.len()).map(|i| l[(i + start) % l.len()]).collect();
            let triangles = triangulate(&rotated);
            assert_eq!(triangles.len(), 4);
            assert!((area(&rotated, &triangles) - 3.0).abs() < 1e-12);
            for &[a, b, c] in &triangles {
                assert!((rotated[b] - rotated[a]).cross(rotated[c] - rotated[a]).z > 0.0);
            }
        }
    }

    #[test]
    fn polygons_facing_away_keep_their_winding() {
        let quad = [(0, 0), (0, 1), (1, 1), (1, 0)]
            .map(|(x, z)| Vec3::new(f64::from(x), 0.0, f64::from(z)));
        let triangles = triangulate(&quad);
        let n = newell_normal(&quad);
        for &[a, b, c] in &triangles {
            assert!((quad[b] - quad[a]).cross(quad[c] - quad[a]).dot(n) > 0.0);
        }
    }

    /// A star of `teeth` spikes, concave at every other corner.
    fn star(teeth: usize) -> Vec<Vec3> {
        (0..2 * teeth)
            .map(|k| {
                let angle = std::f64::consts::TAU * k as f64 / (2 * teeth) as f64;
                let radius = if k % 2 == 0 { 1.0 } else { 0.5 };
                radius * Vec3::new(angle.cos(), angle.sin(), 0.0)
            })
            .collect()
    }

    #[test]
    fn a_star_is_covered_exactly_by_counter_clockwise_triangles() {
        for teeth in [3, 5, 72, 1000] {
            let points = star(teeth);
            let triangles = triangulate(&points);
            assert_eq!(triangles.len(), points.len() - 2);
            // The star's area: 2·teeth triangles (centre, tip, notch).
            let step = std::f64::consts::TAU / (2 * teeth) as f64;
            let exact = 2.0 * teeth as f64 * 0.5 * 0.5 * step.sin();
            assert!(
                (area(&points, &triangles) - exact).abs() < 1e-9 * exact,
                "{teeth}"
            );
            for &[a, b, c] in &triangles {
                let z = (points[b] - points[a]).cross(points[c] - points[a]).z;
                assert!(z > 0.0, "{teeth} teeth: a clockwise triangle");
            }
        }
    }

    #[test]
    fn a_huge_self_intersecting_face_still_gives_n_minus_2_triangles() {
        // 20,000 corners at pseudo-random places, as a fuzzed face gives
        // (the search without a bound took many seconds on such a face).
        let mut state = 1u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let points: Vec<Vec3> = (0..20_000)
            .map(|_| Vec3::new(next(), next(), 0.0))
            .collect();
        assert_eq!(triangulate(&points).len(), points.len() - 2);
    }

    #[test]
    fn degenerate_polygons_still_give_n_minus_2_triangles() {
        let line = [0.0, 1.0, 2.0, 3.0, 4.0].map(|x| Vec3::new(x, 0.0, 0.0));
        assert_eq!(triangulate(&line).len(), 3);
        assert!(triangulate(&line[..2]).is_empty());
    }
}
