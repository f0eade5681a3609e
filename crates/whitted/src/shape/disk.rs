//! A disk, or an annulus when it has an inner radius, in canonical position:
//! centred at the origin in the plane z = 0, facing +z.
//!
//! Scene syntax: `shape = "disk"`, `center = [x, y, z]`, `normal = [x, y, z]`,
//! `radius = r`, and optionally `inner_radius = r` (default 0). The reader
//! places the canonical disk with `Transform::frame(center, normal)`.
//!
//! Texture coordinates are polar: `u = φ / 2π` with `φ = atan2(y, x)` in
//! [0, 2π), and `v = (radius - r) / (radius - inner_radius)`, 0 on the rim
//! rising to 1 at the centre (or at the inner rim); `dpdu = 2π (-y, x, 0)`
//! and `dpdv = -(radius - inner_radius) (cos φ, sin φ, 0)`, pointing inwards.
//!
//! [`cap_hit`] and [`cap_surface`] are the whole geometry of a disk at some
//! height; the cylinder and the cone use them for their caps.

use std::f64::consts::TAU;

use super::{LocalSurface, ShapeError, ShapeHit, non_negative, positive};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};

/// A disk or an annulus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    radius: f64,
    inner_radius: f64,
}

impl Disk {
    /// The disk of the given radius, with a hole of `inner_radius` (0 for
    /// none) in the middle; `inner_radius` must be smaller than `radius`.
    pub fn new(radius: f64, inner_radius: f64) -> Result<Self, ShapeError> {
        let radius = positive("radius", radius)?;
        let inner_radius = non_negative("inner_radius", inner_radius)?;
        if inner_radius >= radius {
            return Err(ShapeError::Degenerate {
                shape: "disk",
                why: "the inner radius is not smaller than the radius",
            });
        }
        Ok(Self {
            radius,
            inner_radius,
        })
    }

    /// The outer radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The radius of the hole (0 for a full disk).
    pub fn inner_radius(&self) -> f64 {
        self.inner_radius
    }

    /// The closest hit in the ray's interval (there is at most one).
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        cap_hit(ray, 0.0, self.radius, self.inner_radius).map(ShapeHit::at)
    }

    /// True when the ray meets the disk in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        cap_surface(ray.at(hit.t), 0.0, 1.0, self.radius, self.inner_radius)
    }

    /// The bounding box (flat in z).
    pub fn bounds(&self) -> Aabb {
        Aabb::new(
            Vec3::new(-self.radius, -self.radius, 0.0),
            Vec3::new(self.radius, self.radius, 0.0),
        )
    }
}

/// The parameter where `ray` crosses the plane z = `height` inside the
/// annulus `inner_radius ≤ r ≤ radius` (both rims included), if it lies in
/// the ray's interval. A ray parallel to the plane (or lying in it) misses.
pub(super) fn cap_hit(ray: &Ray, height: f64, radius: f64, inner_radius: f64) -> Option<f64> {
    if ray.dir.z == 0.0 {
        return None;
    }
    let t = (height - ray.origin.z) / ray.dir.z;
    if !ray.contains(t) {
        return None;
    }
    let x = ray.origin.x + t * ray.dir.x;
    let y = ray.origin.y + t * ray.dir.y;
    let r_squared = x * x + y * y;
    (r_squared <= radius * radius && r_squared >= inner_radius * inner_radius).then_some(t)
}

/// The surface of the disk at z = `height` facing `normal_z` (+1 or -1)
/// at `p`, a point of the ray near it.
///
/// The point is moved onto the plane exactly; its error bound, `γ(5)|p|`
/// per axis, covers the rounding of x and y, and gives caps above z = 0 the
/// slack of a few ulps of `height` along the normal.
pub(super) fn cap_surface(
    p: Vec3,
    height: f64,
    normal_z: f64,
    radius: f64,
    inner_radius: f64,
) -> LocalSurface {
    let r = p.x.hypot(p.y);
    let phi = azimuth(p.x, p.y);
    let (sin_phi, cos_phi) = phi.sin_cos();
    LocalSurface {
        uv: DVec2::new(
            phi / TAU,
            ((radius - r) / (radius - inner_radius)).clamp(0.0, 1.0),
        ),
        dpdu: Vec3::new(-TAU * p.y, TAU * p.x, 0.0),
        dpdv: -(radius - inner_radius) * Vec3::new(cos_phi, sin_phi, 0.0),
        ..cap_geometry(p, height, normal_z)
    }
}

/// [`cap_surface`] without its parametric part: the point, its error
/// bound and the normal, (u, v) and the tangents left zero.
pub(super) fn cap_geometry(p: Vec3, height: f64, normal_z: f64) -> LocalSurface {
    let point = Vec3::new(p.x, p.y, height);
    LocalSurface {
        point,
        point_error: gamma(5) * point.abs(),
        normal: Vec3::new(0.0, 0.0, normal_z),
        uv: DVec2::ZERO,
        dpdu: Vec3::ZERO,
        dpdv: Vec3::ZERO,
    }
}

/// The angle `φ = atan2(y, x)` about the z axis, in [0, 2π).
pub(super) fn azimuth(x: f64, y: f64) -> f64 {
    let phi = y.atan2(x);
    if phi < 0.0 { phi + TAU } else { phi }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_surface_is_sane, assert_tangents_follow_uv,
    };
    use crate::shape::{Shape, ShapeError};

    fn unit() -> Disk {
        Disk::new(1.0, 0.0).unwrap()
    }

    fn annulus() -> Disk {
        Disk::new(2.0, 1.0).unwrap()
    }

    fn down_at(x: f64, y: f64) -> Ray {
        Ray::new(Vec3::new(x, y, 2.0), Vec3::new(0.0, 0.0, -4.0))
    }

    #[test]
    fn ray_in_front_hits_with_exact_t_and_normal() {
        let ray = down_at(0.3, 0.4);
        let hit = unit().intersect(&ray).unwrap();
        assert_eq!(hit.t, 0.5);
        let s = unit().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::Z);
        assert_eq!(s.point, Vec3::new(0.3, 0.4, 0.0));
    }

    #[test]
    fn back_side_is_hit_and_the_normal_stays_plus_z() {
        let ray = Ray::new(Vec3::new(0.1, -0.2, -3.0), Vec3::Z);
        let hit = unit().intersect(&ray).unwrap();
        assert_eq!(hit.t, 3.0);
        assert_eq!(unit().surface(&ray, &hit).normal, Vec3::Z);
    }

    #[test]
    fn disk_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::Z);
        assert_eq!(unit().intersect(&ray), None);
        assert!(!unit().occluded(&ray));
    }

    #[test]
    fn rays_beside_the_rim_or_through_the_hole_miss_and_rims_hit() {
        assert_eq!(unit().intersect(&down_at(0.6, 0.8 + 1e-12)), None);
        assert!(unit().intersect(&down_at(0.0, 1.0)).is_some());
        assert_eq!(annulus().intersect(&down_at(0.5, 0.5)), None);
        assert_eq!(annulus().intersect(&down_at(0.0, 0.0)), None);
        assert!(annulus().intersect(&down_at(1.0, 0.0)).is_some());
        assert!(annulus().intersect(&down_at(0.0, -2.0)).is_some());
    }

    #[test]
    fn rays_in_the_plane_or_parallel_to_it_miss_without_nan() {
        for ray in [
            Ray::new(Vec3::new(-2.0, 0.0, 0.0), Vec3::X),
            Ray::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0)),
            Ray::new(Vec3::new(-2.0, 0.0, 1e-12), Vec3::X),
        ] {
            assert_eq!(unit().intersect(&ray), None);
            assert!(!unit().occluded(&ray));
        }
    }

    #[test]
    fn ray_starting_on_the_disk_does_not_hit_it() {
        for dir in [Vec3::Z, -Vec3::Z, Vec3::new(0.3, 0.1, -0.2)] {
            let ray = Ray::new(Vec3::new(0.2, 0.3, 0.0), dir);
            assert_eq!(unit().intersect(&ray), None);
        }
    }

    #[test]
    fn grazing_ray_hits_at_a_finite_point() {
        let ray = Ray::new(Vec3::new(-2.0, 0.0, 1e-12), Vec3::new(1.0, 0.0, -1e-12));
        let hit = unit().intersect(&ray).unwrap();
        let s = unit().surface(&ray, &hit);
        assert!((s.point - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-9);
        assert!(s.uv.is_finite() && s.dpdu.is_finite());
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z, 2.0);
        assert_eq!(unit().intersect(&ray), None);
    }

    #[test]
    fn bad_radii_are_refused() {
        assert!(matches!(
            Disk::new(0.0, 0.0),
            Err(ShapeError::NotPositive { what: "radius", .. })
        ));
        assert_eq!(
            Disk::new(1.0, -0.5),
            Err(ShapeError::Negative {
                what: "inner_radius",
                value: -0.5
            })
        );
        let degenerate = Err(ShapeError::Degenerate {
            shape: "disk",
            why: "the inner radius is not smaller than the radius",
        });
        assert_eq!(Disk::new(1.0, 1.0), degenerate);
        assert_eq!(Disk::new(1.0, 2.0), degenerate);
        assert!(matches!(
            Disk::new(1.0, f64::NAN),
            Err(ShapeError::NotFinite { .. })
        ));
    }

    #[test]
    fn uv_are_polar_from_the_rim_inwards() {
        for (disk, x, y, u, v) in [
            (unit(), 0.0, 0.5, 0.25, 0.5),
            (unit(), -1.0, 0.0, 0.5, 0.0),
            (unit(), 0.0, 0.0, 0.0, 1.0),
            (annulus(), 0.0, -1.5, 0.75, 0.5),
            (annulus(), 1.0, 0.0, 0.0, 1.0),
        ] {
            let ray = down_at(x, y);
            let s = disk.surface(&ray, &disk.intersect(&ray).unwrap());
            assert!((s.uv - DVec2::new(u, v)).length() < 1e-15, "{x} {y}");
        }
    }

    #[test]
    fn secondary_rays_never_hit_the_disk_they_leave() {
        for (radius, inner) in [(1.0, 0.0), (2.0, 0.5), (1e-3, 0.0), (1e4, 3e3)] {
            let shape = Shape::Disk(Disk::new(radius, inner).unwrap());
            assert_no_self_intersection(&shape, 41);
            assert_surface_is_sane(&shape, 43);
            assert_convex_exits_cleanly(&shape, 45);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        let ray = down_at(0.0, 0.5);
        let s = unit().surface(&ray, &unit().intersect(&ray).unwrap());
        assert!((s.dpdu - Vec3::new(-TAU * 0.5, 0.0, 0.0)).length() < 1e-15);
        assert!((s.dpdv - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-15);
        for disk in [unit(), annulus(), Disk::new(1e3, 2e2).unwrap()] {
            assert_tangents_follow_uv(&Shape::Disk(disk), 17);
        }
    }
}
