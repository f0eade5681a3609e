//! A parallelogram: the points `origin + u edge_u + v edge_v` for `u` and
//! `v` in [0, 1] (a rectangle when the edges are perpendicular).
//!
//! Scene syntax: `shape = "parallelogram"`, `origin = [x, y, z]`,
//! `edge_u = [x, y, z]`, `edge_v = [x, y, z]`.
//!
//! Texture coordinates are the parameters `(u, v)` themselves: (0, 0) at
//! `origin`, (1, 0) at `origin + edge_u`, (0, 1) at `origin + edge_v`. The
//! normal is `normalize(edge_u × edge_v)`, `dpdu = edge_u` and
//! `dpdv = edge_v`.
//!
//! The parallelogram is hit and reprojected as the plane through `origin`
//! with that normal (see [`super::plane`]), then `(u, v)` decide whether the
//! point is inside.

use super::plane::{onto_plane, plane_hit};
use super::{LocalSurface, ShapeError, ShapeHit, finite, not_tiny};
use crate::math::{Aabb, DVec2, Ray, Vec3, magnitude};

/// Edges count as parallel when the sine of the angle between them is below
/// this: the normal would be rounding noise.
const PARALLEL: f64 = 1e-12;

/// A parallelogram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parallelogram {
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
}

impl Parallelogram {
    /// The parallelogram with a corner at `origin` and sides `edge_u` and
    /// `edge_v`; refused when the edges are parallel or of zero length.
    pub fn new(origin: Vec3, edge_u: Vec3, edge_v: Vec3) -> Result<Self, ShapeError> {
        let origin = finite("origin", origin)?;
        let edge_u = finite("edge_u", edge_u)?;
        let edge_v = finite("edge_v", edge_v)?;
        not_tiny("edge_u", [magnitude::norm(edge_u)])?;
        not_tiny("edge_v", [magnitude::norm(edge_v)])?;
        let cross = edge_u.cross(edge_v);
        let flat = cross.length() <= PARALLEL * edge_u.length() * edge_v.length();
        if flat || cross.try_normalize().is_none() {
            return Err(ShapeError::Degenerate {
                shape: "parallelogram",
                why: "its edges are parallel or of zero length",
            });
        }
        Ok(Self {
            origin,
            edge_u,
            edge_v,
        })
    }

    /// The corner at (u, v) = (0, 0).
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The side along which u grows.
    pub fn edge_u(&self) -> Vec3 {
        self.edge_u
    }

    /// The side along which v grows.
    pub fn edge_v(&self) -> Vec3 {
        self.edge_v
    }

    /// The closest hit in the ray's interval, with the parameters of the hit
    /// point in `u, v`.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let cross = self.edge_u.cross(self.edge_v);
        let area_squared = cross.length_squared();
        // Cannot fail: the constructor refused edges whose cross product
        // does not normalise.
        let normal = cross.normalize();
        let t = plane_hit(self.origin, normal, ray)?;
        let w = ray.at(t) - self.origin;
        let u = cross.dot(w.cross(self.edge_v)) / area_squared;
        let v = cross.dot(self.edge_u.cross(w)) / area_squared;
        ((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)).then_some(ShapeHit {
            t,
            u,
            v,
            part: 0,
        })
    }

    /// True when the ray meets the parallelogram in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let normal = self.edge_u.cross(self.edge_v).normalize();
        let (point, point_error) = onto_plane(self.origin, normal, ray.at(hit.t));
        LocalSurface {
            point,
            point_error,
            normal,
            uv: DVec2::new(hit.u, hit.v),
            dpdu: self.edge_u,
            dpdv: self.edge_v,
        }
    }

    /// The bounding box of the four corners.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points([
            self.origin,
            self.origin + self.edge_u,
            self.origin + self.edge_v,
            self.origin + self.edge_u + self.edge_v,
        ])
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

    /// The rectangle [0, 2] × [0, 3] in the plane z = 0, facing +z.
    fn rectangle() -> Parallelogram {
        Parallelogram::new(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        )
        .unwrap()
    }

    #[test]
    fn ray_in_front_hits_with_exact_t_uv_and_normal() {
        let ray = Ray::new(Vec3::new(1.0, 1.5, 4.0), Vec3::new(0.0, 0.0, -2.0));
        let hit = rectangle().intersect(&ray).unwrap();
        assert_eq!(hit.t, 2.0);
        let s = rectangle().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::Z);
        assert_eq!(s.point, Vec3::new(1.0, 1.5, 0.0));
        assert_eq!(s.uv, DVec2::new(0.5, 0.5));
        assert_eq!(s.dpdu, Vec3::new(2.0, 0.0, 0.0));
    }

    #[test]
    fn back_side_is_hit_and_keeps_the_edge_u_cross_edge_v_normal() {
        let ray = Ray::new(Vec3::new(1.0, 1.0, -1.0), Vec3::Z);
        let hit = rectangle().intersect(&ray).unwrap();
        assert_eq!(hit.t, 1.0);
        assert_eq!(rectangle().surface(&ray, &hit).normal, Vec3::Z);
    }

    #[test]
    fn parallelogram_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(1.0, 1.0, 1.0), Vec3::Z);
        assert_eq!(rectangle().intersect(&ray), None);
        assert!(!rectangle().occluded(&ray));
    }

    #[test]
    fn rays_just_outside_each_side_miss_and_corners_hit() {
        for (x, y) in [
            (-1e-9, 1.0),
            (2.0 + 1e-9, 1.0),
            (1.0, -1e-9),
            (1.0, 3.0 + 1e-9),
        ] {
            let ray = Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
            assert_eq!(rectangle().intersect(&ray), None, "{x} {y}");
        }
        for (x, y) in [(0.0, 0.0), (2.0, 0.0), (0.0, 3.0), (2.0, 3.0)] {
            let ray = Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
            let s = rectangle().surface(&ray, &rectangle().intersect(&ray).unwrap());
            assert_eq!(s.uv, DVec2::new(x / 2.0, y / 3.0));
        }
    }

    #[test]
    fn grazing_ray_hits_at_a_finite_point() {
        let ray = Ray::new(Vec3::new(-1.0, 1.0, 1e-9), Vec3::new(1.0, 0.0, -1e-9));
        let hit = rectangle().intersect(&ray).unwrap();
        assert!((hit.t - 1.0).abs() < 1e-6);
        let s = rectangle().surface(&ray, &hit);
        assert!(s.point.is_finite() && s.uv.is_finite());
    }

    #[test]
    fn rays_parallel_to_it_or_in_its_plane_miss_without_nan() {
        for ray in [
            Ray::new(Vec3::new(-1.0, 1.0, 0.5), Vec3::X),
            Ray::new(Vec3::new(-1.0, 1.0, 0.0), Vec3::X),
            Ray::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)),
        ] {
            assert_eq!(rectangle().intersect(&ray), None);
            assert!(!rectangle().occluded(&ray));
        }
    }

    #[test]
    fn ray_starting_on_the_parallelogram_does_not_hit_it() {
        for dir in [Vec3::Z, -Vec3::Z, Vec3::new(1.0, -1.0, 0.3)] {
            let ray = Ray::new(Vec3::new(0.7, 1.1, 0.0), dir);
            assert_eq!(rectangle().intersect(&ray), None);
        }
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(1.0, 1.0, 2.0), -Vec3::Z, 2.0);
        assert_eq!(rectangle().intersect(&ray), None);
    }

    #[test]
    fn parallel_or_zero_edges_are_refused() {
        let degenerate = Err(ShapeError::Degenerate {
            shape: "parallelogram",
            why: "its edges are parallel or of zero length",
        });
        let edge = Vec3::new(0.3, -1.7, 2.2);
        assert_eq!(Parallelogram::new(Vec3::ONE, edge, -3.0 * edge), degenerate);
        assert_eq!(Parallelogram::new(Vec3::ONE, edge, Vec3::ZERO), degenerate);
        assert_eq!(
            Parallelogram::new(Vec3::ONE, edge, Vec3::new(0.0, f64::NAN, 0.0)),
            Err(ShapeError::NotFinite { what: "edge_v" })
        );
    }

    #[test]
    fn uv_are_the_parameters_on_a_sheared_parallelogram() {
        let (origin, edge_u, edge_v) = (
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(2.0, 0.0, 0.5),
            Vec3::new(1.0, 1.0, 1.0),
        );
        let shape = Parallelogram::new(origin, edge_u, edge_v).unwrap();
        let normal = edge_u.cross(edge_v).normalize();
        let target = origin + 0.25 * edge_u + 0.75 * edge_v;
        let ray = Ray::new(
            target + 3.0 * normal + 0.1 * edge_u,
            -3.0 * normal - 0.1 * edge_u,
        );
        let s = shape.surface(&ray, &shape.intersect(&ray).unwrap());
        assert!((s.uv - DVec2::new(0.25, 0.75)).length() < 1e-14);
        assert!((s.point - target).length() < 1e-14);
        assert!((s.normal - normal).length() < 1e-15);
    }

    #[test]
    fn secondary_rays_never_hit_the_parallelogram_they_leave() {
        for (origin, edge_u, edge_v) in [
            (Vec3::ZERO, Vec3::X, Vec3::Y),
            (
                Vec3::new(0.3, -0.2, 0.5),
                Vec3::new(1.0, 0.4, -0.3),
                Vec3::new(-0.2, 0.7, 1.1),
            ),
            (
                Vec3::new(1e4, -1e4, 5e3),
                Vec3::new(2.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 3.0),
            ),
            (
                Vec3::new(1e-3, 0.0, 0.0),
                Vec3::new(1e-3, 1e-3, 0.0),
                Vec3::new(0.0, 0.0, 2e-3),
            ),
            (
                Vec3::ZERO,
                Vec3::new(1e4, 0.0, 1e3),
                Vec3::new(0.0, 2e4, 0.0),
            ),
        ] {
            let shape = Shape::Parallelogram(Parallelogram::new(origin, edge_u, edge_v).unwrap());
            assert_no_self_intersection(&shape, 23);
            assert_surface_is_sane(&shape, 29);
            assert_convex_exits_cleanly(&shape, 31);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        let (edge_u, edge_v) = (Vec3::new(2.0, 0.0, 0.5), Vec3::new(1.0, 1.0, 1.0));
        let shape = Parallelogram::new(Vec3::ONE, edge_u, edge_v).unwrap();
        let ray = Ray::new(Vec3::new(2.0, 1.5, 5.0), -Vec3::Z);
        let s = shape.surface(&ray, &shape.intersect(&ray).unwrap());
        assert_eq!((s.dpdu, s.dpdv), (edge_u, edge_v));
        assert_tangents_follow_uv(&Shape::Parallelogram(shape), 11);
    }
}
