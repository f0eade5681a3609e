//! Polygons to triangles by ear clipping in the polygon's own plane, so
//! concave faces come out right (a fan, as most loaders do, covers the
//! notch of an L).

use crate::math::{DVec2, Vec3};

/// The polygon's normal by Newell's method (not unit; zero when the
/// polygon has no area). Robust for concave and slightly non-planar faces.
pub(super) fn newell_normal(points: &[Vec3]) -> Vec3 {
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
/// give `n - 2` triangles (the leftovers are clipped as a fan).
pub(super) fn triangulate(points: &[Vec3]) -> Vec<[usize; 3]> {
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
    let mut triangles = Vec::with_capacity(n - 2);
    while remaining.len() > 3 {
        let count = remaining.len();
        let ear = (0..count)
            .find(|&i| is_ear(&flat, &remaining, i))
            .or_else(|| (0..count).find(|&i| is_convex(&flat, &remaining, i)))
            .unwrap_or(0);
        let [a, b, c] = corners(&remaining, ear);
        triangles.push([a, b, c]);
        remaining.remove(ear);
    }
    triangles.push([remaining[0], remaining[1], remaining[2]]);
    triangles
}

/// The points in 2D, dropping the normal's largest axis and keeping the
/// winding counter-clockwise.
fn project(points: &[Vec3], normal: Vec3) -> Vec<DVec2> {
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

/// A convex corner whose triangle holds no other remaining corner.
fn is_ear(flat: &[DVec2], remaining: &[usize], i: usize) -> bool {
    if !is_convex(flat, remaining, i) {
        return false;
    }
    let ids = corners(remaining, i);
    let [a, b, c] = ids.map(|k| flat[k]);
    remaining.iter().all(|&k| {
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

    #[test]
    fn degenerate_polygons_still_give_n_minus_2_triangles() {
        let line = [0.0, 1.0, 2.0, 3.0, 4.0].map(|x| Vec3::new(x, 0.0, 0.0));
        assert_eq!(triangulate(&line).len(), 3);
        assert!(triangulate(&line[..2]).is_empty());
    }
}
