//! The bounds of the part of a triangle inside a box, for the kd-tree's
//! "perfect splits" (Havran's thesis, section 4.5; Wald and Havran 2006,
//! section 4.4): the triangle is clipped to the box (Sutherland–Hodgman,
//! one axis-aligned plane at a time) and the clipped polygon's box is
//! returned, often much smaller than the triangle's box ∩ the cell.
//!
//! The result is conservative: the clip is done in `f64` against the box
//! widened by a pad, and the result widened by the same pad, where the pad
//! (2^-40 of the largest coordinate involved, about 4,000 `f64` ulps) far
//! exceeds the rounding of the few interpolations of the clip. It is still
//! far below an `f32` ulp, so the kd-tree, whose planes are `f32`, loses
//! nothing by it.

use crate::math::{Aabb, Vec3};

/// At most 3 + 6 vertices: each of the six planes adds at most one.
const MAX_VERTICES: usize = 9;

/// The pad relative to the largest coordinate: 2^-40.
const RELATIVE_PAD: f64 = 1.0 / (1u64 << 40) as f64;

/// A box around every point of triangle `corners` inside the closed box
/// `cell` (itself within `cell`), or `None` when the triangle does not
/// meet `cell`. Corners or cells that are not finite give the triangle's
/// box ∩ `cell`, which is always conservative.
pub fn clipped_triangle_bounds(corners: [Vec3; 3], cell: &Aabb) -> Option<Aabb> {
    let whole = Aabb::from_points(corners);
    let overlap = whole.intersection(cell)?;
    let scale = corners
        .iter()
        .chain([&cell.min, &cell.max])
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    if !scale.is_finite() {
        return Some(overlap);
    }
    let pad = Vec3::splat(scale * RELATIVE_PAD + f64::MIN_POSITIVE);
    let (low, high) = (cell.min - pad, cell.max + pad);

    let mut polygon = [Vec3::ZERO; MAX_VERTICES];
    polygon[..3].copy_from_slice(&corners);
    let mut len = 3;
    for axis in 0..3 {
        len = clip(&mut polygon, len, axis, low[axis], Keep::Above);
        len = clip(&mut polygon, len, axis, high[axis], Keep::Below);
        if len == 0 {
            return None;
        }
    }
    let clipped = Aabb::from_points(polygon[..len].iter().copied());
    let widened = Aabb {
        min: clipped.min - pad,
        max: clipped.max + pad,
    };
    widened.intersection(&overlap)
}

/// Which side of a plane a clip keeps.
#[derive(Clone, Copy)]
enum Keep {
    Above,
    Below,
}

/// Clips the polygon `polygon[..len]` to the closed half-space on the
/// `keep` side of the plane at `plane` on `axis`; returns its new length.
fn clip(
    polygon: &mut [Vec3; MAX_VERTICES],
    len: usize,
    axis: usize,
    plane: f64,
    keep: Keep,
) -> usize {
    let inside = |p: &Vec3| match keep {
        Keep::Above => p[axis] >= plane,
        Keep::Below => p[axis] <= plane,
    };
    let input = *polygon;
    let mut out = 0;
    for i in 0..len {
        let (a, b) = (input[i], input[(i + 1) % len]);
        if inside(&a) {
            polygon[out] = a;
            out += 1;
        }
        if inside(&a) != inside(&b) && out < MAX_VERTICES {
            // The crossing, with the clipped axis set exactly on the plane.
            let t = ((plane - a[axis]) / (b[axis] - a[axis])).clamp(0.0, 1.0);
            let mut p = a + (b - a) * t;
            p[axis] = plane;
            polygon[out] = p;
            out += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    fn cube(min: f64, max: f64) -> Aabb {
        Aabb::new(Vec3::splat(min), Vec3::splat(max))
    }

    #[test]
    fn a_diagonal_triangle_gets_a_box_much_smaller_than_its_box_in_the_cell() {
        // The triangle x + y + z = 3 in the cell [0, 1]³ meets it only at
        // the corner (1, 1, 1).
        let corners = [
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::new(0.0, 0.0, 3.0),
        ];
        let b = clipped_triangle_bounds(corners, &cube(0.0, 1.0)).unwrap();
        assert!(b.min.cmpgt(Vec3::splat(0.999)).all(), "{b:?}");
        assert!(b.max.cmple(Vec3::ONE).all(), "{b:?}");
        assert_eq!(clipped_triangle_bounds(corners, &cube(0.0, 0.99)), None);
    }

    #[test]
    fn a_triangle_lying_in_a_face_of_the_cell_stays_in_it() {
        let corners = [
            Vec3::new(0.5, 0.5, 1.0),
            Vec3::new(5.0, 0.5, 1.0),
            Vec3::new(0.5, 5.0, 1.0),
        ];
        let b = clipped_triangle_bounds(corners, &cube(0.0, 1.0)).unwrap();
        assert_eq!((b.min.z, b.max.z), (1.0, 1.0));
        assert_eq!(b.max.x, 1.0);
    }

    #[test]
    fn every_point_of_the_triangle_in_the_cell_is_in_the_clipped_box() {
        let mut rng = Rng::new(11);
        for _ in 0..4_000 {
            // Small integer grids make vertices land on cell faces, edges
            // and corners; slivers come from nearly collinear corners.
            let corner =
                |rng: &mut Rng| Vec3::from_array([0; 3].map(|_| f64::from(rng.below(9)) * 0.25));
            let mut corners = [corner(&mut rng), corner(&mut rng), corner(&mut rng)];
            if rng.below(4) == 0 {
                corners[2] = corners[0] + (corners[1] - corners[0]) * 0.5 + Vec3::splat(1e-9);
            }
            let (a, b) = (corner(&mut rng), corner(&mut rng));
            let cell = Aabb::new(a.min(b), a.max(b));
            let clipped = clipped_triangle_bounds(corners, &cell);
            for i in 0..=8 {
                for j in 0..=8 - i {
                    let (u, v) = (f64::from(i) / 8.0, f64::from(j) / 8.0);
                    let p = corners[0] * (1.0 - u - v) + corners[1] * u + corners[2] * v;
                    if p.cmpge(cell.min).all() && p.cmple(cell.max).all() {
                        let c = clipped.unwrap_or_else(|| panic!("{corners:?} in {cell:?}"));
                        assert!(
                            p.cmpge(c.min).all() && p.cmple(c.max).all(),
                            "{p} outside {c:?} for {corners:?} in {cell:?}"
                        );
                    }
                }
            }
            if let Some(c) = clipped {
                assert!(c.min.cmpge(cell.min).all() && c.max.cmple(cell.max).all());
            }
        }
    }
}
