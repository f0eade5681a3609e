//! Property checks shared by the tests of every shape: seeded random rays
//! aimed at the shape, and the invariants each hit must keep.

use super::Shape;
use crate::math::random::Rng;
use crate::math::{Aabb, DVec2, Ray, Vec3, offset_ray_origin};

/// A random line through the box `bounds`: from a point twice the box's
/// diagonal away from its centre towards a point inside it, with a random
/// length of direction and the origin moved anywhere along the line, so
/// tests of crossings along whole lines see every parametrisation. Also
/// gives the line's parameter at that far point: the box lies between it
/// and about 3 further on.
pub(crate) fn random_line_through(rng: &mut Rng, bounds: &Aabb) -> (Ray, f64) {
    let size = bounds.extent().length();
    let origin = bounds.centroid() + 2.0 * size * rng.unit_vector();
    let target = rng.point_in(bounds.min, bounds.max);
    let dir = (target - origin) * rng.range(0.2, 3.0);
    let start = rng.range(-1.0, 1.0);
    (Ray::new(origin - start * dir, dir), start)
}

/// The region random rays aim at: the shape's bounds, or a box around the
/// origin for unbounded shapes.
fn region(shape: &Shape) -> Aabb {
    let b = shape.bounds();
    if b.is_finite() {
        b
    } else {
        Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
    }
}

/// Random rays from outside the region aimed at a point inside it.
fn random_rays(shape: &Shape, seed: u64, count: usize) -> impl Iterator<Item = Ray> {
    let region = region(shape);
    let size = region.extent().length().max(f64::MIN_POSITIVE);
    let center = region.centroid();
    let mut rng = Rng::new(seed);
    (0..count).map(move |_| {
        let origin = center + 2.0 * size * rng.unit_vector();
        let target = rng.point_in(region.min, region.max);
        Ray::new(origin, target - origin)
    })
}

/// Rays leaving every hit point in random directions, from the offset origin,
/// never meet the surface again within a distance no legitimate second hit
/// could have (1e-7 of the shape's size).
pub(crate) fn assert_no_self_intersection(shape: &Shape, seed: u64) {
    let size = region(shape).extent().length();
    let mut rng = Rng::new(seed ^ 0xabcdef);
    let mut hits = 0;
    for ray in random_rays(shape, seed, 2000) {
        let Some(hit) = shape.intersect(&ray) else {
            continue;
        };
        hits += 1;
        let s = shape.surface(&ray, &hit);
        for _ in 0..4 {
            let w = rng.unit_vector();
            let origin = offset_ray_origin(s.point, s.point_error, s.normal, w);
            let next = Ray::new(origin, w);
            if let Some(again) = shape.intersect(&next) {
                assert!(
                    again.t > 1e-7 * size,
                    "{}: ray from {origin:?} along {w:?} hit its own surface again at t = {}",
                    shape.kind(),
                    again.t
                );
            }
        }
    }
    assert!(
        hits > 100,
        "{}: too few random rays hit ({hits})",
        shape.kind()
    );
}

/// Rays from random directions at `distance` aimed at each of `targets`,
/// each target first nudged by a random amount in {0, 1e-15, 1e-12, 1e-9}
/// times `distance`: for aiming at rims, edges and corners.
pub(crate) fn rays_toward(targets: &[Vec3], distance: f64, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed);
    targets
        .iter()
        .map(|&target| {
            let nudge = [0.0, 1e-15, 1e-12, 1e-9][rng.below(4) as usize];
            let target = target + nudge * distance * rng.unit_vector();
            let origin = target + distance * rng.unit_vector();
            Ray::new(origin, target - origin)
        })
        .collect()
}

/// Rays leaving a hit point on the outer side of the surface (the side the
/// normal points to) never meet the shape again, at any distance: every
/// shape is a piece of the boundary of a convex solid (or of a plane), so
/// nothing of it lies outside a tangent plane. Hit points come from `rays`
/// (so a test can aim at rims and edges); returns how many were checked.
pub(crate) fn assert_outward_rays_escape(
    shape: &Shape,
    rays: impl IntoIterator<Item = Ray>,
    seed: u64,
) -> usize {
    let mut rng = Rng::new(seed ^ 0x5eed);
    let mut hits = 0;
    for ray in rays {
        let Some(hit) = shape.intersect(&ray) else {
            continue;
        };
        hits += 1;
        let s = shape.surface(&ray, &hit);
        for _ in 0..4 {
            let mut w = rng.unit_vector();
            if w.dot(s.normal) < 0.0 {
                w = -w;
            }
            let origin = offset_ray_origin(s.point, s.point_error, s.normal, w);
            let next = Ray::new(origin, w);
            if let Some(again) = shape.intersect(&next) {
                panic!(
                    "{}: outward ray from {origin:?} along {w:?} (normal {:?}, part {}) \
                     hit the shape again at t = {} (part {})",
                    shape.kind(),
                    s.normal,
                    hit.part,
                    again.t,
                    again.part
                );
            }
        }
    }
    hits
}

/// [`assert_outward_rays_escape`] for random rays aimed at the shape.
pub(crate) fn assert_convex_exits_cleanly(shape: &Shape, seed: u64) {
    let hits = assert_outward_rays_escape(shape, random_rays(shape, seed, 2000), seed);
    assert!(
        hits > 100,
        "{}: too few random rays hit ({hits})",
        shape.kind()
    );
}

/// Every hit of a random ray has a finite unit normal, finite texture
/// coordinates, a point on the ray (within a tight tolerance of the shape's
/// size) and an `occluded` answer that agrees with `intersect`.
pub(crate) fn assert_surface_is_sane(shape: &Shape, seed: u64) {
    let size = region(shape).extent().length();
    for ray in random_rays(shape, seed, 2000) {
        let hit = shape.intersect(&ray);
        assert_eq!(hit.is_some(), shape.occluded(&ray), "{}", shape.kind());
        let Some(hit) = hit else { continue };
        assert!(ray.contains(hit.t));
        let s = shape.surface(&ray, &hit);
        let lean = shape.surface_geometry(&ray, &hit);
        assert_eq!(
            (lean.point, lean.point_error, lean.normal),
            (s.point, s.point_error, s.normal),
            "{}: the surface without (u, v) differs",
            shape.kind()
        );
        assert!(
            (s.normal.length() - 1.0).abs() < 1e-9,
            "{}: normal {:?}",
            shape.kind(),
            s.normal
        );
        assert!(s.uv.is_finite() && s.dpdu.is_finite() && s.point_error.is_finite());
        assert!(s.dpdv.is_finite(), "{}: dpdv {:?}", shape.kind(), s.dpdv);
        for tangent in [s.dpdu, s.dpdv] {
            assert!(
                tangent.dot(s.normal).abs() <= 1e-9 * tangent.length(),
                "{}: tangent {tangent:?} not perpendicular to the normal {:?}",
                shape.kind(),
                s.normal
            );
        }
        let distance = (s.point - ray.at(hit.t)).length();
        assert!(
            distance <= 1e-9 * size.max(ray.origin.length()),
            "{}: reprojected point moved by {distance}",
            shape.kind()
        );
        let b = shape.bounds();
        let slack = 1e-12 * (size + b.min.abs().max(b.max.abs()).max_element());
        let in_bounds =
            ray.at(hit.t).cmpge(b.min - slack).all() && ray.at(hit.t).cmple(b.max + slack).all();
        assert!(
            !b.is_finite() || in_bounds,
            "{}: hit at {:?} outside the bounds {b:?}",
            shape.kind(),
            ray.at(hit.t)
        );
    }
}

/// Awkward rays give no NaN: origins at every combination of the bounds'
/// minimum, centre and maximum per axis (corners, edge and face centres,
/// points on the surface), directions along every combination of -1, 0 and
/// 1 per axis (parallel to faces and axes, along diagonals), at lengths
/// 1e-150, 1 and 1e150. Any hit has a finite `t` in the ray's interval and
/// a finite surface with a unit normal, and `occluded` agrees.
pub(crate) fn assert_no_nan_for_awkward_rays(shape: &Shape) {
    let region = region(shape);
    let levels = [region.min, region.centroid(), region.max];
    let steps = [-1.0, 0.0, 1.0];
    for i in 0..27 {
        let origin = Vec3::new(levels[i % 3].x, levels[i / 3 % 3].y, levels[i / 9].z);
        for j in 0..27 {
            let dir = Vec3::new(steps[j % 3], steps[j / 3 % 3], steps[j / 9]);
            if dir == Vec3::ZERO {
                continue;
            }
            for length in [1e-150, 1.0, 1e150] {
                let ray = Ray::new(origin, length * dir);
                let hit = shape.intersect(&ray);
                assert_eq!(hit.is_some(), shape.occluded(&ray), "{}", shape.kind());
                let Some(hit) = hit else { continue };
                assert!(
                    hit.t.is_finite()
                        && ray.contains(hit.t)
                        && hit.u.is_finite()
                        && hit.v.is_finite(),
                    "{}: {hit:?} for {ray:?}",
                    shape.kind()
                );
                let s = shape.surface(&ray, &hit);
                assert!(
                    s.point.is_finite()
                        && s.point_error.is_finite()
                        && s.uv.is_finite()
                        && s.dpdu.is_finite()
                        && s.dpdv.is_finite()
                        && (s.normal.length() - 1.0).abs() < 1e-9,
                    "{}: {s:?} for {ray:?}",
                    shape.kind()
                );
            }
        }
    }
}

/// `dpdu` and `dpdv` are the derivatives of the parametric form: moving a
/// hit point by `h dpdu` (or `h dpdv`) for a small `h` and casting a ray
/// back at the surface there changes (u, v) by `(h, 0)` (or `(0, h)`), to
/// within 1e-3 of `h`. Steps that leave the part hit, cross the seam of u
/// or start where a tangent (nearly) vanishes are skipped; returns how many
/// steps were checked.
pub(crate) fn assert_tangents_follow_uv(shape: &Shape, seed: u64) -> usize {
    let size = region(shape).extent().length();
    let mut checked = 0;
    for ray in random_rays(shape, seed, 500) {
        let Some(hit) = shape.intersect(&ray) else {
            continue;
        };
        let s = shape.surface(&ray, &hit);
        for (tangent, along) in [(s.dpdu, DVec2::X), (s.dpdv, DVec2::Y)] {
            if tangent.length() < 1e-4 * size {
                continue;
            }
            let h = 1e-6 * s.uv.abs().max_element().max(1.0);
            let target = s.point + h * tangent;
            let back = Ray::new(target + 0.01 * size * s.normal, -s.normal);
            let Some(moved) = shape.intersect(&back) else {
                continue;
            };
            if moved.part != hit.part {
                continue;
            }
            let change = shape.surface(&back, &moved).uv - s.uv;
            if change.abs().max_element() > 0.5 {
                continue;
            }
            let step = change / h;
            assert!(
                (step - along).abs().max_element() < 1e-3,
                "{}: moving along {tangent:?} from {:?} (uv {:?}) changed uv by {step:?} per unit",
                shape.kind(),
                s.point,
                s.uv
            );
            checked += 1;
        }
    }
    assert!(
        checked > 200,
        "{}: too few tangent steps checked ({checked})",
        shape.kind()
    );
    checked
}

/// Follows `ray` through `shape` from crossing to crossing (each next ray
/// from the offset origin of the last hit) and checks they alternate
/// entering and leaving by the sign of the normal against the ray: the
/// first enters (normal against the ray), the last leaves. Returns how
/// many crossings there were.
pub(crate) fn assert_crossings_alternate(shape: &Shape, ray: Ray) -> usize {
    let mut ray = ray;
    let mut crossings = 0;
    while let Some(hit) = shape.intersect(&ray) {
        let s = shape.surface(&ray, &hit);
        let entering = crossings % 2 == 0;
        let cos = s.normal.dot(ray.dir.normalize());
        assert!(
            if entering { cos < 0.0 } else { cos > 0.0 },
            "{}: crossing {crossings} at {:?} should {} the solid, but normal {:?} · direction = {cos}",
            shape.kind(),
            s.point,
            if entering { "enter" } else { "leave" },
            s.normal
        );
        crossings += 1;
        assert!(crossings <= 16, "{}: endless crossings", shape.kind());
        ray = Ray::new(
            offset_ray_origin(s.point, s.point_error, s.normal, ray.dir),
            ray.dir,
        );
    }
    assert!(
        crossings % 2 == 0,
        "{}: {crossings} crossings, the last one entering",
        shape.kind()
    );
    crossings
}
