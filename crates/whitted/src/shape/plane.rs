//! An infinite plane through a point, facing along a normal.
//!
//! Scene syntax: `shape = "plane"`, `point = [x, y, z]`,
//! `normal = [x, y, z]` (any non-zero length; it is normalised).
//!
//! Texture coordinates are unbounded and in world units: `(u, v)` are the
//! coordinates of `p - point` along the fixed tangent frame
//! `normal.any_orthonormal_pair()`, so `dpdu` and `dpdv` are that frame's
//! two unit vectors (`dpdu × dpdv = normal`).
//!
//! The two helpers [`plane_hit`] and [`onto_plane`] are the whole geometry of
//! a plane; the bounded flat shapes (parallelogram, polygon) use them too, so
//! every flat shape is hit and reprojected the same way.

use super::{LocalSurface, ShapeError, ShapeHit, finite};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma, unit};

/// An infinite plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    point: Vec3,
    normal: Vec3,
}

impl Plane {
    /// The plane through `point` with the given normal (any non-zero length).
    pub fn new(point: Vec3, normal: Vec3) -> Result<Self, ShapeError> {
        let point = finite("point", point)?;
        if !normal.is_finite() {
            return Err(ShapeError::NotFinite { what: "normal" });
        }
        let normal = unit(normal).ok_or(ShapeError::Degenerate {
            shape: "plane",
            why: "the normal has zero length",
        })?;
        Ok(Self { point, normal })
    }

    /// The point the plane was given through.
    pub fn point(&self) -> Vec3 {
        self.point
    }

    /// The unit normal.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// The closest hit in the ray's interval (there is at most one).
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        plane_hit(self.point, self.normal, ray).map(ShapeHit::at)
    }

    /// True when the ray meets the plane in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        plane_hit(self.point, self.normal, ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let (point, point_error) = onto_plane(self.point, self.normal, ray.at(hit.t));
        let (tangent, bitangent) = self.normal.any_orthonormal_pair();
        let offset = point - self.point;
        LocalSurface {
            point,
            point_error,
            normal: self.normal,
            uv: DVec2::new(offset.dot(tangent), offset.dot(bitangent)),
            dpdu: tangent,
            dpdv: bitangent,
        }
    }

    /// The bounds: all of space.
    pub fn bounds(&self) -> Aabb {
        Aabb::INFINITE
    }
}

/// The parameter where `ray` crosses the plane through `point` with unit
/// `normal`, if it lies in the ray's interval. A ray parallel to the plane
/// (or lying in it) misses.
///
/// The distance is measured from `point`, not from the world origin, so it
/// stays precise for planes far from the origin.
pub(crate) fn plane_hit(point: Vec3, normal: Vec3, ray: &Ray) -> Option<f64> {
    let denominator = normal.dot(ray.dir);
    if denominator == 0.0 {
        return None;
    }
    let t = normal.dot(point - ray.origin) / denominator;
    ray.contains(t).then_some(t)
}

/// `p` projected onto the plane through `point` with unit `normal`, with a
/// bound on the distance of the result from the plane, per axis.
///
/// Rounding: `d = n · (p - point)` is off by at most `γ(4) Σ|nⱼ||pⱼ - pointⱼ|`;
/// `p - d n` adds `γ(1)|d||nᵢ|` and `γ(1)|pᵢ'|`. The bound below is a little
/// larger, and its component along the normal always exceeds the rounding of
/// [`plane_hit`] for a ray leaving the point, so offset rays never hit the
/// plane they leave.
pub(super) fn onto_plane(point: Vec3, normal: Vec3, p: Vec3) -> (Vec3, Vec3) {
    let offset = p - point;
    let distance = normal.dot(offset);
    let projected = p - distance * normal;
    let spread = normal.abs().dot(offset.abs()) + distance.abs();
    let error = gamma(6) * (projected.abs() + spread * normal.abs());
    (projected, error)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_surface_is_sane, assert_tangents_follow_uv,
    };
    use crate::shape::{Shape, ShapeError};

    fn floor() -> Plane {
        Plane::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0)).unwrap()
    }

    #[test]
    fn ray_in_front_hits_with_exact_t_and_the_given_normal() {
        let ray = Ray::new(Vec3::new(0.5, -0.5, 5.0), Vec3::new(0.0, 0.0, -2.0));
        let hit = floor().intersect(&ray).unwrap();
        assert_eq!(hit.t, 2.5);
        let s = floor().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::Z);
        assert_eq!(s.point, Vec3::new(0.5, -0.5, 0.0));
    }

    #[test]
    fn ray_from_behind_hits_too_and_the_normal_keeps_its_side() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::Z);
        let hit = floor().intersect(&ray).unwrap();
        assert_eq!(hit.t, 3.0);
        assert_eq!(floor().surface(&ray, &hit).normal, Vec3::Z);
    }

    #[test]
    fn plane_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::Z);
        assert_eq!(floor().intersect(&ray), None);
        assert!(!floor().occluded(&ray));
    }

    #[test]
    fn ray_starting_on_the_plane_does_not_hit_it() {
        for dir in [Vec3::Z, -Vec3::Z, Vec3::new(1.0, 2.0, -0.5)] {
            let ray = Ray::new(Vec3::new(0.3, -7.0, 0.0), dir);
            assert_eq!(floor().intersect(&ray), None);
        }
    }

    #[test]
    fn rays_parallel_to_the_plane_or_in_it_miss_without_nan() {
        let above = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::X);
        let inside = Ray::new(Vec3::new(3.0, 1.0, 0.0), Vec3::new(1.0, 2.0, 0.0));
        for ray in [above, inside] {
            assert_eq!(floor().intersect(&ray), None);
            assert!(!floor().occluded(&ray));
        }
    }

    #[test]
    fn grazing_ray_hits_far_away_with_a_finite_surface() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, -1e-12));
        let hit = floor().intersect(&ray).unwrap();
        assert!((hit.t - 1e12).abs() < 1e-3);
        let s = floor().surface(&ray, &hit);
        assert_eq!(s.point.z, 0.0);
        assert!(s.point.is_finite() && s.uv.is_finite() && s.point_error.is_finite());
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(0.0, 0.0, 4.0), -Vec3::Z, 4.0);
        assert_eq!(floor().intersect(&ray), None);
        let shorter = Ray::segment(Vec3::new(0.0, 0.0, 4.0), -Vec3::Z, 4.0 + 1e-9);
        assert!(floor().intersect(&shorter).is_some());
    }

    #[test]
    fn zero_or_non_finite_input_is_refused() {
        assert!(matches!(
            Plane::new(Vec3::ONE, Vec3::ZERO),
            Err(ShapeError::Degenerate { shape: "plane", .. })
        ));
        assert!(matches!(
            Plane::new(Vec3::new(f64::NAN, 0.0, 0.0), Vec3::Z),
            Err(ShapeError::NotFinite { what: "point" })
        ));
        assert!(matches!(
            Plane::new(Vec3::ZERO, Vec3::new(0.0, f64::INFINITY, 0.0)),
            Err(ShapeError::NotFinite { what: "normal" })
        ));
    }

    #[test]
    fn tiny_and_huge_normals_are_normalised() {
        for scale in [1e-200, 1e200] {
            let plane = Plane::new(Vec3::ZERO, Vec3::new(scale, 0.0, scale)).unwrap();
            let expected = Vec3::new(1.0, 0.0, 1.0) / 2f64.sqrt();
            assert!((plane.normal() - expected).length() < 1e-15);
        }
    }

    #[test]
    fn uv_are_world_coordinates_along_the_tangent_frame() {
        let point = Vec3::new(1.0, 2.0, 3.0);
        let normal = Vec3::new(1.0, -2.0, 0.5);
        let plane = Plane::new(point, normal).unwrap();
        let (tangent, bitangent) = plane.normal().any_orthonormal_pair();
        let target = point + 2.0 * tangent - 3.0 * bitangent;
        let origin = target + 5.0 * plane.normal() + tangent;
        let ray = Ray::new(origin, target - origin);
        let s = plane.surface(&ray, &plane.intersect(&ray).unwrap());
        assert!((s.uv - DVec2::new(2.0, -3.0)).length() < 1e-12);
        assert_eq!(s.dpdu, tangent);
    }

    #[test]
    fn reprojected_point_lies_within_its_error_bound_of_a_far_tilted_plane() {
        let plane = Plane::new(Vec3::new(1e4, -3e4, 2e4), Vec3::new(0.3, 0.9, -0.2)).unwrap();
        let ray = Ray::new(Vec3::new(-7e3, 1e3, 5.0), Vec3::new(0.7, -1.3, 0.45));
        let hit = plane.intersect(&ray).unwrap();
        let s = plane.surface(&ray, &hit);
        let distance = plane.normal().dot(s.point - plane.point()).abs();
        assert!(distance <= plane.normal().abs().dot(s.point_error));
    }

    #[test]
    fn secondary_rays_never_hit_the_plane_they_leave() {
        for (point, normal) in [
            (Vec3::ZERO, Vec3::Z),
            (Vec3::new(0.2, -0.1, 0.3), Vec3::new(1.0, 2.0, -3.0)),
            (Vec3::new(1e4, -2e4, 3e3), Vec3::new(-0.5, 0.1, 0.7)),
            (Vec3::new(1e-3, 0.0, 0.0), Vec3::new(1.0, 1e-3, 0.0)),
        ] {
            let shape = Shape::Plane(Plane::new(point, normal).unwrap());
            assert_no_self_intersection(&shape, 3);
            assert_surface_is_sane(&shape, 5);
            assert_convex_exits_cleanly(&shape, 7);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        for normal in [Vec3::Z, -Vec3::Y, Vec3::new(1.0, -2.0, 0.5)] {
            let plane = Plane::new(Vec3::new(0.5, 1.0, -2.0), normal).unwrap();
            let origin = plane.point() + 3.0 * plane.normal() + Vec3::new(0.3, 0.2, 0.1);
            let ray = Ray::new(origin, -plane.normal());
            let s = plane.surface(&ray, &plane.intersect(&ray).unwrap());
            assert!((s.dpdu.cross(s.dpdv) - plane.normal()).length() < 1e-15);
            assert_tangents_follow_uv(&Shape::Plane(plane), 5);
        }
    }
}
