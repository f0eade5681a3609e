//! A single triangle given by its three vertices.
//!
//! Scene syntax: `shape = "triangle"`,
//! `vertices = [[x0, y0, z0], [x1, y1, z1], [x2, y2, z2]]`.
//!
//! The front faces the viewer who sees the vertices counter-clockwise: the
//! normal is `normalize((p1 - p0) × (p2 - p0))`. Texture coordinates are the
//! barycentric coordinates `(u, v) = (b1, b2)` of the point
//! `b0 p0 + b1 p1 + b2 p2`, so `p0` is at (0, 0), `p1` at (1, 0) and `p2` at
//! (0, 1); `dpdu = p1 - p0` and `dpdv = p2 - p0`.
//!
//! Intersection is the watertight test of Woop, Benthin and Wald ("Watertight
//! Ray/Triangle Intersection", JCGT 2013) with the conservative bound on `t`
//! of pbrt-v4 (`IntersectTriangle` in `src/pbrt/shapes.h`): a ray through an
//! edge shared by two triangles hits at least one of them, and a ray leaving
//! the surface is never taken to hit it again.

use super::{LocalSurface, ShapeError, ShapeHit, finite, not_tiny};
use crate::math::apart::coordinates_apart;
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma, magnitude};

/// Vertices count as collinear when the sine of the angle at `p0` is below
/// this: such a needle's normal would be rounding noise.
const COLLINEAR: f64 = 1e-12;

/// A triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
}

impl Triangle {
    /// The triangle `p0, p1, p2`; refused when the vertices are collinear or
    /// two of them coincide.
    pub fn new(p0: Vec3, p1: Vec3, p2: Vec3) -> Result<Self, ShapeError> {
        let (p0, p1, p2) = (
            finite("vertex", p0)?,
            finite("vertex", p1)?,
            finite("vertex", p2)?,
        );
        let (edge1, edge2) = (p1 - p0, p2 - p0);
        not_tiny(
            "the longest edge",
            [edge1, edge2, p2 - p1].map(magnitude::norm),
        )?;
        let cross = edge1.cross(edge2);
        let flat = cross.length() <= COLLINEAR * edge1.length() * edge2.length();
        if flat || cross.try_normalize().is_none() {
            return Err(ShapeError::Degenerate {
                shape: "triangle",
                why: "its vertices are collinear or coincide",
            });
        }
        Ok(Self { p0, p1, p2 })
    }

    /// The three vertices, in the order given.
    pub fn vertices(&self) -> [Vec3; 3] {
        [self.p0, self.p1, self.p2]
    }

    /// The closest hit in the ray's interval, with the barycentric
    /// coordinates `b1, b2` in `u, v`.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        watertight(self.p0, self.p1, self.p2, ray, &RayShear::new(ray))
    }

    /// True when the ray meets the triangle in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit: the point rebuilt from its barycentric
    /// coordinates, which lies on the triangle up to the bound
    /// `γ(7) (|b0 p0| + |b1 p1| + |b2 p2|)` (pbrt-v4 eq. 6.31).
    pub fn surface(&self, _ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        // Cannot fail to normalise: the constructor refused triangles whose
        // cross product does not.
        barycentric_surface([self.p0, self.p1, self.p2], hit.u, hit.v)
    }

    /// The bounding box of the vertices.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points([self.p0, self.p1, self.p2])
    }
}

/// The surface of the triangle with `corners` at barycentric coordinates
/// (`b1`, `b2`): the point rebuilt from them with its error bound, the
/// geometric normal, (u, v) = (`b1`, `b2`) and the edges as tangents. The
/// triangle must have a non-zero area (the normal is normalised).
pub(crate) fn barycentric_surface(corners: [Vec3; 3], b1: f64, b2: f64) -> LocalSurface {
    let [p0, p1, p2] = corners;
    let (w0, w1, w2) = ((1.0 - b1 - b2) * p0, b1 * p1, b2 * p2);
    let (edge1, edge2) = (p1 - p0, p2 - p0);
    LocalSurface {
        point: w0 + w1 + w2,
        point_error: gamma(7) * (w0.abs() + w1.abs() + w2.abs()),
        normal: edge1.cross(edge2).normalize(),
        uv: DVec2::new(b1, b2),
        dpdu: edge1,
        dpdv: edge2,
    }
}

/// What the watertight test needs of a ray, computed once per ray: the axis
/// permutation that makes the largest direction component z, and the shear
/// that turns the ray into the +z axis from the origin.
#[derive(Clone, Copy, Debug)]
pub struct RayShear {
    /// The axis that becomes z (the next two, cyclically, become x and y).
    kz: usize,
    shear: Vec3,
}

impl RayShear {
    /// The shear for `ray`.
    pub fn new(ray: &Ray) -> Self {
        // Read apart: the ray is mostly written just before.
        let [x, y, z] = coordinates_apart(&ray.dir);
        let kz = Vec3::new(x.abs(), y.abs(), z.abs()).max_position();
        let kx = (kz + 1) % 3;
        let ky = (kx + 1) % 3;
        let d = Vec3::new(ray.dir[kx], ray.dir[ky], ray.dir[kz]);
        Self {
            kz,
            shear: Vec3::new(-d.x / d.z, -d.y / d.z, 1.0 / d.z),
        }
    }

    /// The axis that becomes z.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn kz(&self) -> usize {
        self.kz
    }

    /// The shear factors: x and y gain `x` and `y` times z, and z is
    /// scaled by `z`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn factors(&self) -> Vec3 {
        self.shear
    }

    /// A point in the ray's sheared space (z not yet scaled), the axes
    /// permuted by `KX`, `KY`, `KZ`.
    #[inline(always)]
    fn apply<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        p: Vec3,
        origin: Vec3,
    ) -> Vec3 {
        let q = p - origin;
        let z = q[KZ];
        Vec3::new(q[KX] + self.shear.x * z, q[KY] + self.shear.y * z, z)
    }
}

/// The watertight ray/triangle test of Woop, Benthin and Wald with pbrt-v4's
/// conservative bound on `t`, for the triangle `p0, p1, p2` and a ray with
/// its precomputed shear: the closest hit in the ray's interval with the
/// barycentric coordinates `b1, b2` in `u, v`. A zero-area triangle is
/// never hit.
#[inline]
pub fn watertight(p0: Vec3, p1: Vec3, p2: Vec3, ray: &Ray, shear: &RayShear) -> Option<ShapeHit> {
    // One copy per permutation, so the axes are constants: indexing the
    // vertices by a run-time axis took more instructions (figures in
    // docs/performance-log.md, one-triangle test).
    match shear.kz {
        0 => watertight_permuted::<1, 2, 0>(p0, p1, p2, ray, shear),
        1 => watertight_permuted::<2, 0, 1>(p0, p1, p2, ray, shear),
        _ => watertight_permuted::<0, 1, 2>(p0, p1, p2, ray, shear),
    }
}

/// [`watertight`] with the shear's axis permutation given as `KX`, `KY`,
/// `KZ`.
#[inline(always)]
fn watertight_permuted<const KX: usize, const KY: usize, const KZ: usize>(
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
    ray: &Ray,
    shear: &RayShear,
) -> Option<ShapeHit> {
    let (mut a, mut b, mut c) = (
        shear.apply::<KX, KY, KZ>(p0, ray.origin),
        shear.apply::<KX, KY, KZ>(p1, ray.origin),
        shear.apply::<KX, KY, KZ>(p2, ray.origin),
    );
    let shear = shear.shear;

    // Edge functions: twice the signed areas opposite each vertex. An
    // edge shared with a neighbour gives the same value, negated, there.
    // Their signs are combined with `|` and `&`, not `||` and `&&`: one
    // branch per triangle, mostly a predictable miss, instead of one per
    // sign (faster with both structures: docs/performance-log.md, one-triangle
    // test).
    let e0 = b.x * c.y - b.y * c.x;
    let e1 = c.x * a.y - c.y * a.x;
    let e2 = a.x * b.y - a.y * b.x;
    let negative = (e0 < 0.0) | (e1 < 0.0) | (e2 < 0.0);
    let positive = (e0 > 0.0) | (e1 > 0.0) | (e2 > 0.0);
    if negative & positive {
        return None;
    }
    let det = e0 + e1 + e2;
    if det == 0.0 {
        return None;
    }
    a.z *= shear.z;
    b.z *= shear.z;
    c.z *= shear.z;
    let t = (e0 * a.z + e1 * b.z + e2 * c.z) / det;
    if !ray.contains(t) {
        return None;
    }

    // Error bounds of pbrt-v4 (section 6.8.4): reject a `t` that is not
    // conservatively positive, and edge functions that are all rounding
    // noise (a ray lying in the triangle's plane).
    let max_x = Vec3::new(a.x, b.x, c.x).abs().max_element();
    let max_y = Vec3::new(a.y, b.y, c.y).abs().max_element();
    let max_z = Vec3::new(a.z, b.z, c.z).abs().max_element();
    let delta_x = gamma(5) * (max_x + max_z);
    let delta_y = gamma(5) * (max_y + max_z);
    let delta_z = gamma(3) * max_z;
    let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    if det.abs() <= 3.0 * delta_e {
        return None;
    }
    let max_e = Vec3::new(e0, e1, e2).abs().max_element();
    let delta_t = 3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) / det.abs();
    if t <= delta_t {
        return None;
    }
    Some(ShapeHit {
        t,
        u: e1 / det,
        v: e2 / det,
        part: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_surface_is_sane, assert_tangents_follow_uv,
    };
    use crate::shape::{Shape, ShapeError};

    fn unit() -> Triangle {
        Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y).unwrap()
    }

    #[test]
    fn ray_in_front_hits_with_exact_t_barycentrics_and_normal() {
        let ray = Ray::new(Vec3::new(0.25, 0.5, 2.0), Vec3::new(0.0, 0.0, -4.0));
        let hit = unit().intersect(&ray).unwrap();
        assert_eq!(hit.t, 0.5);
        assert_eq!((hit.u, hit.v), (0.25, 0.5));
        let s = unit().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::Z);
        assert_eq!(s.point, Vec3::new(0.25, 0.5, 0.0));
    }

    #[test]
    fn rays_along_each_axis_hit_with_the_same_t_and_barycentrics() {
        // The unit triangle with its coordinates rotated so each axis in
        // turn is the normal (and the ray's largest component).
        let turn = |v: Vec3, k: usize| match k {
            0 => Vec3::new(v.z, v.x, v.y),
            1 => Vec3::new(v.y, v.z, v.x),
            _ => v,
        };
        for k in 0..3 {
            let triangle =
                Triangle::new(turn(Vec3::ZERO, k), turn(Vec3::X, k), turn(Vec3::Y, k)).unwrap();
            let dir = turn(Vec3::new(0.01, -0.02, -4.0), k);
            let ray = Ray::new(turn(Vec3::new(0.25, 0.5, 2.0), k), dir);
            let hit = triangle.intersect(&ray).unwrap();
            assert_eq!(hit.t, 0.5, "axis {k}");
            assert!((hit.u - 0.255).abs() < 1e-15 && (hit.v - 0.49).abs() < 1e-15);
            let miss = Ray::new(turn(Vec3::new(0.6, 0.5, 2.0), k), dir);
            assert_eq!(triangle.intersect(&miss), None, "axis {k}");
        }
    }

    #[test]
    fn back_side_is_hit_and_keeps_the_counter_clockwise_normal() {
        let ray = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z);
        let hit = unit().intersect(&ray).unwrap();
        assert_eq!(hit.t, 1.0);
        assert_eq!(unit().surface(&ray, &hit).normal, Vec3::Z);
    }

    #[test]
    fn clockwise_vertices_face_the_other_way() {
        let flipped = Triangle::new(Vec3::ZERO, Vec3::Y, Vec3::X).unwrap();
        let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        let hit = flipped.intersect(&ray).unwrap();
        assert_eq!(flipped.surface(&ray, &hit).normal, -Vec3::Z);
    }

    #[test]
    fn triangle_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::Z);
        assert_eq!(unit().intersect(&ray), None);
        assert!(!unit().occluded(&ray));
    }

    #[test]
    fn ray_passing_beside_the_hypotenuse_is_missed() {
        let ray = Ray::new(Vec3::new(0.5 + 1e-9, 0.5, 1.0), -Vec3::Z);
        assert_eq!(unit().intersect(&ray), None);
        let inside = Ray::new(Vec3::new(0.5 - 1e-9, 0.5, 1.0), -Vec3::Z);
        assert!(unit().intersect(&inside).is_some());
    }

    #[test]
    fn rays_exactly_through_a_vertex_or_an_edge_hit_without_nan() {
        let edges = [Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0)];
        for target in [Vec3::X, Vec3::Y, Vec3::ZERO, Vec3::new(0.5, 0.5, 0.0)]
            .iter()
            .chain(&edges)
        {
            let ray = Ray::new(*target + Vec3::new(0.0, 0.0, 3.0), -Vec3::Z);
            let hit = unit().intersect(&ray).unwrap();
            let s = unit().surface(&ray, &hit);
            assert_eq!(s.point, *target);
            assert!(s.uv.is_finite() && s.normal == Vec3::Z);
        }
    }

    #[test]
    fn rays_in_the_plane_of_the_triangle_miss_without_nan() {
        let tilted = Triangle::new(
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(1.7, -0.4, 0.9),
            Vec3::new(-0.3, 1.1, 2.0),
        )
        .unwrap();
        let [p0, p1, p2] = tilted.vertices();
        let centroid = (p0 + p1 + p2) / 3.0;
        for (triangle, origin, dir) in [
            (unit(), Vec3::new(-1.0, 0.25, 0.0), Vec3::X),
            (unit(), Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)),
            (tilted, centroid - (p1 - p0), p1 - p0),
            (tilted, centroid + (p2 - p1), p1 - p2),
        ] {
            let ray = Ray::new(origin, dir);
            assert_eq!(triangle.intersect(&ray), None, "{origin} {dir}");
            assert!(!triangle.occluded(&ray));
        }
    }

    #[test]
    fn ray_starting_on_the_triangle_does_not_hit_it() {
        for dir in [Vec3::Z, -Vec3::Z, Vec3::new(1.0, 2.0, -0.5)] {
            let ray = Ray::new(Vec3::new(0.25, 0.25, 0.0), dir);
            assert_eq!(unit().intersect(&ray), None);
        }
    }

    #[test]
    fn ray_parallel_to_the_plane_above_it_is_missed() {
        let ray = Ray::new(Vec3::new(-1.0, 0.2, 1e-9), Vec3::X);
        assert_eq!(unit().intersect(&ray), None);
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(0.2, 0.2, 2.0), -Vec3::Z, 2.0);
        assert_eq!(unit().intersect(&ray), None);
    }

    #[test]
    fn direction_length_does_not_change_the_hit_point() {
        for scale in [1e-3, 1.0, 1e4] {
            let ray = Ray::new(Vec3::new(0.3, 0.3, 1.0), Vec3::new(0.0, 0.0, -scale));
            let hit = unit().intersect(&ray).unwrap();
            assert!((hit.t * scale - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn collinear_or_coincident_vertices_are_refused() {
        let degenerate = ShapeError::Degenerate {
            shape: "triangle",
            why: "its vertices are collinear or coincide",
        };
        let a = Vec3::new(0.1, 0.2, 0.3);
        let b = Vec3::new(1.3, -0.7, 2.9);
        assert_eq!(
            Triangle::new(a, b, 0.25 * a + 0.75 * b),
            Err(degenerate.clone())
        );
        assert_eq!(Triangle::new(a, a, b), Err(degenerate.clone()));
        assert_eq!(Triangle::new(a, a, a), Err(degenerate));
        assert_eq!(
            Triangle::new(a, b, Vec3::new(0.0, f64::NAN, 0.0)),
            Err(ShapeError::NotFinite { what: "vertex" })
        );
    }

    #[test]
    fn uv_are_the_barycentrics_and_dpdu_follows_the_first_edge() {
        let (p0, p1, p2) = (
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(4.0, 2.0, 1.0),
            Vec3::new(0.0, 5.0, 2.0),
        );
        let triangle = Triangle::new(p0, p1, p2).unwrap();
        let target = p0 + 0.2 * (p1 - p0) + 0.3 * (p2 - p0);
        let normal = (p1 - p0).cross(p2 - p0).normalize();
        let ray = Ray::new(target + 2.0 * normal, -normal);
        let s = triangle.surface(&ray, &triangle.intersect(&ray).unwrap());
        assert!((s.uv - DVec2::new(0.2, 0.3)).length() < 1e-12);
        assert_eq!(s.dpdu, p1 - p0);
        assert!((s.normal - normal).length() < 1e-15);
    }

    #[test]
    fn rays_through_a_shared_edge_never_slip_between_two_triangles() {
        let (a, b) = (Vec3::new(0.1, -0.3, 0.2), Vec3::new(0.9, 1.1, -0.4));
        let left = Triangle::new(a, b, Vec3::new(-1.0, 0.8, 0.1)).unwrap();
        let right = Triangle::new(b, a, Vec3::new(1.3, -0.9, 0.3)).unwrap();
        let mut rng = Rng::new(17);
        for _ in 0..10_000 {
            let target = a + rng.uniform() * (b - a);
            let origin = Vec3::new(0.3, 0.2, 3.0) + rng.unit_vector();
            let ray = Ray::new(origin, target - origin);
            assert!(
                left.intersect(&ray).is_some() || right.intersect(&ray).is_some(),
                "{origin} -> {target}"
            );
        }
    }

    #[test]
    fn secondary_rays_never_hit_the_triangle_they_leave() {
        let shapes = [
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [
                Vec3::new(0.3, -1.2, 0.4),
                Vec3::new(2.1, 0.7, -0.8),
                Vec3::new(-0.6, 0.9, 1.5),
            ],
            [
                Vec3::new(1e4, 1e4, -1e4),
                Vec3::new(1e4 + 3.0, 1e4 - 1.0, -1e4 + 2.0),
                Vec3::new(1e4 - 1.0, 1e4 + 2.5, -1e4 + 0.5),
            ],
            [
                Vec3::ZERO,
                Vec3::new(1e-3, 2e-4, 0.0),
                Vec3::new(0.0, 1e-3, 1e-3),
            ],
            [
                Vec3::ZERO,
                Vec3::new(1e4, 0.0, 0.0),
                Vec3::new(0.0, 5e3, 1e4),
            ],
        ];
        for [p0, p1, p2] in shapes {
            let shape = Shape::Triangle(Triangle::new(p0, p1, p2).unwrap());
            assert_no_self_intersection(&shape, 13);
            assert_surface_is_sane(&shape, 19);
            assert_convex_exits_cleanly(&shape, 17);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        let (p0, p1, p2) = (
            Vec3::new(0.3, -1.2, 0.4),
            Vec3::new(2.1, 0.7, -0.8),
            Vec3::new(-0.6, 0.9, 1.5),
        );
        let triangle = Triangle::new(p0, p1, p2).unwrap();
        let ray = Ray::new(Vec3::new(0.5, 0.2, 3.0), Vec3::new(0.0, 0.0, -1.0));
        let s = triangle.surface(&ray, &triangle.intersect(&ray).unwrap());
        assert_eq!((s.dpdu, s.dpdv), (p1 - p0, p2 - p0));
        assert_tangents_follow_uv(&Shape::Triangle(triangle), 7);
    }
}
