//! A sphere given by its centre and radius.
//!
//! Scene syntax: `shape = "sphere"`, `center = [x, y, z]`, `radius = r`.
//!
//! Texture coordinates follow pbrt with z as the pole: `u = φ / 2π` with
//! `φ = atan2(y, x)` measured about the centre, `v = 0` at the bottom
//! (`z = -r`) rising to `v = 1` at the top. The tangents are the
//! derivatives of that form: `dpdu = 2π (-y, x, 0)` (zero at the poles) and
//! `dpdv = π (-z cos φ, -z sin φ, √(x² + y²))`, pointing north.

use std::f64::consts::{PI, TAU};

use super::{LocalSurface, ShapeError, ShapeHit, finite, positive, quadratic};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    center: Vec3,
    radius: f64,
}

impl Sphere {
    /// A sphere around `center`; the radius must be positive.
    pub fn new(center: Vec3, radius: f64) -> Result<Self, ShapeError> {
        Ok(Self {
            center: finite("center", center)?,
            radius: positive("radius", radius)?,
        })
    }

    /// The centre.
    pub fn center(&self) -> Vec3 {
        self.center
    }

    /// The radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Both roots of the ray's quadratic, or `None` when it misses.
    ///
    /// The discriminant is computed from the squared distance between the
    /// centre and the ray's line (Haines et al., *Ray Tracing Gems* ch. 7),
    /// which stays accurate for small spheres far away.
    fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let f = ray.origin - self.center;
        let a = ray.dir.length_squared();
        let b = f.dot(ray.dir);
        let c = f.length_squared() - self.radius * self.radius;
        let perpendicular = f - (b / a) * ray.dir;
        let disc = a * (self.radius * self.radius - perpendicular.length_squared());
        quadratic::solve(a, b, c, disc)
    }

    /// The closest hit in the ray's interval.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let roots = self.roots(ray)?;
        quadratic::nearest_in(roots, ray.t_min, ray.t_max).map(ShapeHit::at)
    }

    /// True when the ray meets the sphere in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let mut local = ray.at(hit.t) - self.center;
        let length = local.length();
        if length > 0.0 {
            local *= self.radius / length;
        } else {
            local = Vec3::new(0.0, 0.0, self.radius);
        }
        let point = self.center + local;
        let point_error = gamma(8) * (self.center.abs() + local.abs());
        let normal = local / self.radius;
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let theta = (local.z / self.radius).clamp(-1.0, 1.0).acos();
        let (sin_phi, cos_phi) = phi.sin_cos();
        LocalSurface {
            point,
            point_error,
            normal,
            uv: DVec2::new(phi / TAU, 1.0 - theta / PI),
            dpdu: Vec3::new(-TAU * local.y, TAU * local.x, 0.0),
            dpdv: PI
                * Vec3::new(
                    -local.z * cos_phi,
                    -local.z * sin_phi,
                    local.x.hypot(local.y),
                ),
        }
    }

    /// The bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(
            self.center - Vec3::splat(self.radius),
            self.center + Vec3::splat(self.radius),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_surface_is_sane, assert_tangents_follow_uv,
    };
    use crate::shape::{Shape, ShapeError};

    fn unit() -> Sphere {
        Sphere::new(Vec3::ZERO, 1.0).unwrap()
    }

    #[test]
    fn ray_in_front_hits_near_side() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let hit = unit().intersect(&ray).unwrap();
        assert_eq!(hit.t, 4.0);
        let s = unit().surface(&ray, &hit);
        assert_eq!(s.normal, -Vec3::Z);
    }

    #[test]
    fn ray_starting_inside_sphere_hits_far_side() {
        let ray = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::Y);
        let hit = unit().intersect(&ray).unwrap();
        assert!((hit.t - 0.5).abs() < 1e-15);
        assert_eq!(unit().surface(&ray, &hit).normal, Vec3::Y);
    }

    #[test]
    fn sphere_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
        assert_eq!(unit().intersect(&ray), None);
        assert!(!unit().occluded(&ray));
    }

    #[test]
    fn ray_passing_beside_is_missed() {
        let ray = Ray::new(Vec3::new(1.0 + 1e-9, 0.0, -5.0), Vec3::Z);
        assert_eq!(unit().intersect(&ray), None);
    }

    #[test]
    fn tangent_ray_touches_once_without_nan() {
        let ray = Ray::new(Vec3::new(1.0, 0.0, -5.0), Vec3::Z);
        let hit = unit().intersect(&ray).unwrap();
        assert!((hit.t - 5.0).abs() < 1e-7);
        let s = unit().surface(&ray, &hit);
        assert!(s.normal.is_finite() && (s.normal - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn hits_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 4.0);
        assert_eq!(unit().intersect(&ray), None);
    }

    #[test]
    fn small_sphere_far_away_is_hit_precisely() {
        let s = Sphere::new(Vec3::new(0.0, 0.0, 1e6), 1e-3).unwrap();
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let hit = s.intersect(&ray).unwrap();
        assert!((hit.t - (1e6 - 1e-3)).abs() < 1e-9);
    }

    #[test]
    fn uv_follows_the_parametric_form() {
        let ray = Ray::new(Vec3::new(0.0, -5.0, 0.0), Vec3::Y);
        let hit = unit().intersect(&ray).unwrap();
        let s = unit().surface(&ray, &hit);
        assert!((s.uv.x - 0.75).abs() < 1e-12);
        assert!((s.uv.y - 0.5).abs() < 1e-12);
        let top = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let s = unit().surface(&top, &unit().intersect(&top).unwrap());
        assert!((s.uv.y - 1.0).abs() < 1e-12);
    }

    #[test]
    fn zero_or_negative_radius_is_refused() {
        assert!(matches!(
            Sphere::new(Vec3::ZERO, 0.0),
            Err(ShapeError::NotPositive { .. })
        ));
        assert!(Sphere::new(Vec3::ZERO, -1.0).is_err());
        assert!(Sphere::new(Vec3::ZERO, f64::NAN).is_err());
        assert!(Sphere::new(Vec3::new(f64::INFINITY, 0.0, 0.0), 1.0).is_err());
    }

    #[test]
    fn secondary_rays_never_hit_the_surface_they_leave() {
        for (center, radius) in [(Vec3::ZERO, 1.0), (Vec3::new(1e4, -3e3, 7.0), 2.5)] {
            let shape = Shape::Sphere(Sphere::new(center, radius).unwrap());
            assert_no_self_intersection(&shape, 7);
            assert_surface_is_sane(&shape, 11);
            assert_convex_exits_cleanly(&shape, 13);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        for (center, radius) in [(Vec3::ZERO, 1.0), (Vec3::new(1e3, -20.0, 7.0), 2.5)] {
            let shape = Shape::Sphere(Sphere::new(center, radius).unwrap());
            assert_tangents_follow_uv(&shape, 3);
        }
        // On the equator facing -y, u runs along +x and v points north:
        // dpdu × dpdv is the outward normal.
        let ray = Ray::new(Vec3::new(0.0, -5.0, 0.0), Vec3::Y);
        let s = unit().surface(&ray, &unit().intersect(&ray).unwrap());
        assert!((s.dpdu - TAU * Vec3::X).length() < 1e-12, "{}", s.dpdu);
        assert!((s.dpdv - PI * Vec3::Z).length() < 1e-12, "{}", s.dpdv);
    }
}
