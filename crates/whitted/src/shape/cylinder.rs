//! A circular cylinder in canonical position: axis +z from z = 0 to
//! z = height, open or closed by two caps.
//!
//! Scene syntax: `shape = "cylinder"`, `base = [x, y, z]`,
//! `top = [x, y, z]`, `radius = r`, and optionally `caps = false` (default
//! true). The reader builds the canonical cylinder of height
//! `|top - base|` and places it with `Transform::frame(base, top - base)`.
//!
//! Parts ([`ShapeHit::part`]): 0 the side, 1 the bottom cap (z = 0, facing
//! -z), 2 the top cap (z = height, facing +z). Texture coordinates on the
//! side: `u = φ / 2π` with `φ = atan2(y, x)` in [0, 2π), `v = z / height`;
//! on the caps, as on a disk: the same `u`, `v = 1 - r / radius` (0 on the
//! rim, 1 at the centre). `dpdu = 2π (-y, x, 0)` everywhere; `dpdv` is
//! `(0, 0, height)` on the side and points inwards on the caps (see
//! [`super::disk`]).

use std::f64::consts::TAU;

use super::disk::{azimuth, cap_geometry, cap_hit, cap_surface};
use super::{LocalSurface, ShapeError, ShapeHit, positive, quadratic};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};

/// [`ShapeHit::part`] of the side.
const SIDE: u32 = 0;
/// [`ShapeHit::part`] of the bottom cap.
const BOTTOM: u32 = 1;
/// [`ShapeHit::part`] of the top cap.
const TOP: u32 = 2;

/// A cylinder, open or capped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    radius: f64,
    height: f64,
    caps: bool,
}

impl Cylinder {
    /// The cylinder of the given radius around the z axis from z = 0 to
    /// z = `height`, closed by two disks when `caps` is set.
    pub fn new(radius: f64, height: f64, caps: bool) -> Result<Self, ShapeError> {
        Ok(Self {
            radius: positive("radius", radius)?,
            height: positive("height", height)?,
            caps,
        })
    }

    /// The radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The length along z.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// True when the ends are closed.
    pub fn caps(&self) -> bool {
        self.caps
    }

    /// Both roots of the side's quadratic in x and y, or `None` when the ray
    /// misses the infinite tube or runs parallel to the axis.
    ///
    /// The discriminant `b² - ac` equals `a r² - (o × d)_z²` (Lagrange's
    /// identity), which keeps its precision when the origin is far away.
    fn side_roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let (o, d) = (ray.origin, ray.dir);
        let a = d.x * d.x + d.y * d.y;
        let b = o.x * d.x + o.y * d.y;
        let c = o.x * o.x + o.y * o.y - self.radius * self.radius;
        let cross = o.x * d.y - o.y * d.x;
        let disc = a * self.radius * self.radius - cross * cross;
        quadratic::solve(a, b, c, disc)
    }

    /// The closest hit in the ray's interval among the side and the caps,
    /// with the part hit in [`ShapeHit::part`].
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let mut best: Option<ShapeHit> = None;
        if let Some((t0, t1)) = self.side_roots(ray) {
            best = [t0, t1]
                .into_iter()
                .filter(|&t| ray.contains(t))
                .find(|&t| (0.0..=self.height).contains(&(ray.origin.z + t * ray.dir.z)))
                .map(|t| ShapeHit {
                    part: SIDE,
                    ..ShapeHit::at(t)
                });
        }
        if self.caps {
            for (part, height) in [(BOTTOM, 0.0), (TOP, self.height)] {
                if let Some(t) = cap_hit(ray, height, self.radius, 0.0)
                    && best.is_none_or(|b| t < b.t)
                {
                    best = Some(ShapeHit {
                        part,
                        ..ShapeHit::at(t)
                    });
                }
            }
        }
        best
    }

    /// True when the ray meets the cylinder in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let p = ray.at(hit.t);
        match hit.part {
            BOTTOM => cap_surface(p, 0.0, -1.0, self.radius, 0.0),
            TOP => cap_surface(p, self.height, 1.0, self.radius, 0.0),
            _ => self.side_surface(p),
        }
    }

    /// The surface at a hit without its parametric part: (u, v) and the
    /// tangents are left zero (see [`crate::shape::Shape::surface_geometry`]).
    pub fn surface_geometry(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let p = ray.at(hit.t);
        match hit.part {
            BOTTOM => cap_geometry(p, 0.0, -1.0),
            TOP => cap_geometry(p, self.height, 1.0),
            _ => self.side_geometry(p),
        }
    }

    /// The side's surface at `p` (see [`Self::side_geometry`]).
    fn side_surface(&self, p: Vec3) -> LocalSurface {
        let s = self.side_geometry(p);
        let point = s.point;
        LocalSurface {
            uv: DVec2::new(azimuth(point.x, point.y) / TAU, point.z / self.height),
            dpdu: Vec3::new(-TAU * point.y, TAU * point.x, 0.0),
            dpdv: Vec3::new(0.0, 0.0, self.height),
            ..s
        }
    }

    /// The side's point, error bound and normal at `p`, moved radially onto
    /// the radius; (u, v) and the tangents zero. The error bound `γ(5)|p|`
    /// per axis covers the rounding of that move.
    fn side_geometry(&self, p: Vec3) -> LocalSurface {
        let r = p.x.hypot(p.y);
        let normal = if r > 0.0 {
            Vec3::new(p.x / r, p.y / r, 0.0)
        } else {
            Vec3::X
        };
        let point = Vec3::new(
            self.radius * normal.x,
            self.radius * normal.y,
            p.z.clamp(0.0, self.height),
        );
        LocalSurface {
            point,
            point_error: gamma(5) * point.abs(),
            normal,
            uv: DVec2::ZERO,
            dpdu: Vec3::ZERO,
            dpdv: Vec3::ZERO,
        }
    }

    /// The bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(
            Vec3::new(-self.radius, -self.radius, 0.0),
            Vec3::new(self.radius, self.radius, self.height),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_outward_rays_escape, assert_surface_is_sane, assert_tangents_follow_uv, rays_toward,
    };
    use crate::shape::{Shape, ShapeError};

    /// Radius 1, from z = 0 to z = 2.
    fn capped() -> Cylinder {
        Cylinder::new(1.0, 2.0, true).unwrap()
    }

    fn open() -> Cylinder {
        Cylinder::new(1.0, 2.0, false).unwrap()
    }

    #[test]
    fn ray_from_outside_hits_the_side_with_exact_t_and_outward_normal() {
        for shape in [capped(), open()] {
            let ray = Ray::new(Vec3::new(-5.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 0.0));
            let hit = shape.intersect(&ray).unwrap();
            assert_eq!((hit.t, hit.part), (2.0, SIDE));
            let s = shape.surface(&ray, &hit);
            assert_eq!(s.normal, -Vec3::X);
            assert_eq!(s.point, Vec3::new(-1.0, 0.0, 1.0));
        }
    }

    #[test]
    fn ray_starting_inside_hits_the_far_side_or_the_far_cap() {
        let sideways = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::X);
        let hit = capped().intersect(&sideways).unwrap();
        assert_eq!((hit.t, hit.part), (1.0, SIDE));
        assert_eq!(capped().surface(&sideways, &hit).normal, Vec3::X);

        let up = Ray::new(Vec3::new(0.5, 0.0, 1.0), Vec3::new(0.1, 0.0, 1.0));
        let hit = capped().intersect(&up).unwrap();
        assert_eq!(hit.part, TOP);
        assert!((hit.t - 1.0).abs() < 1e-15);
        assert_eq!(capped().surface(&up, &hit).normal, Vec3::Z);

        let down = Ray::new(Vec3::new(0.0, 0.5, 1.5), Vec3::new(0.0, 0.2, -1.0));
        let hit = capped().intersect(&down).unwrap();
        assert_eq!(hit.part, BOTTOM);
        assert_eq!(capped().surface(&down, &hit).normal, -Vec3::Z);
    }

    #[test]
    fn ray_along_the_axis_hits_the_cap_or_passes_through_the_open_tube() {
        let ray = Ray::new(Vec3::new(0.3, 0.2, -3.0), Vec3::new(0.0, 0.0, 0.5));
        let hit = capped().intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (6.0, BOTTOM));
        assert_eq!(capped().surface(&ray, &hit).point, Vec3::new(0.3, 0.2, 0.0));
        assert_eq!(open().intersect(&ray), None);
        assert!(!open().occluded(&ray));
        let inside_open = Ray::new(Vec3::new(0.3, 0.2, 1.0), Vec3::Z);
        assert_eq!(open().intersect(&inside_open), None);
    }

    #[test]
    fn ray_into_the_open_end_hits_the_inside_of_the_wall() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::new(1.0, 0.0, -2.0));
        let hit = open().intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (1.0, SIDE));
        let s = open().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::X);
        assert_eq!(s.point, Vec3::new(1.0, 0.0, 1.0));
    }

    #[test]
    fn cap_in_front_of_the_side_is_the_closest_hit() {
        let ray = Ray::new(Vec3::new(-0.5, 0.0, 3.0), Vec3::new(1.0, 0.0, -1.0));
        let hit = capped().intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (1.0, TOP));
        let hit = open().intersect(&ray).unwrap();
        assert_eq!((hit.part, hit.t), (SIDE, 1.5));
    }

    #[test]
    fn cylinder_behind_the_ray_is_missed() {
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 1.0), -Vec3::X);
        assert_eq!(capped().intersect(&ray), None);
        assert!(!capped().occluded(&ray));
    }

    #[test]
    fn rays_beside_above_or_below_are_missed() {
        for ray in [
            Ray::new(Vec3::new(-5.0, 1.0 + 1e-9, 1.0), Vec3::X),
            Ray::new(Vec3::new(-5.0, 0.0, 2.0 + 1e-9), Vec3::X),
            Ray::new(Vec3::new(-5.0, 0.0, -1e-9), Vec3::X),
            Ray::new(Vec3::new(1.0 + 1e-9, 0.0, -1.0), Vec3::Z),
        ] {
            assert_eq!(capped().intersect(&ray), None, "{ray:?}");
        }
    }

    #[test]
    fn tangent_ray_touches_once_without_nan() {
        let ray = Ray::new(Vec3::new(1.0, -5.0, 1.0), Vec3::Y);
        let hit = open().intersect(&ray).unwrap();
        assert_eq!(hit.t, 5.0);
        let s = open().surface(&ray, &hit);
        assert_eq!(s.normal, Vec3::X);
        let along_the_wall = Ray::new(Vec3::new(1.0, 0.0, -1.0), Vec3::Z);
        for shape in [capped(), open()] {
            if let Some(hit) = shape.intersect(&along_the_wall) {
                let s = shape.surface(&along_the_wall, &hit);
                assert!(s.normal.is_finite() && s.uv.is_finite());
            }
        }
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(-5.0, 0.0, 1.0), Vec3::X, 4.0);
        assert_eq!(capped().intersect(&ray), None);
        let cap = Ray::segment(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z, 3.0);
        assert_eq!(capped().intersect(&cap), None);
    }

    #[test]
    fn bad_dimensions_are_refused() {
        assert!(matches!(
            Cylinder::new(0.0, 1.0, true),
            Err(ShapeError::NotPositive { what: "radius", .. })
        ));
        assert!(matches!(
            Cylinder::new(1.0, -1.0, false),
            Err(ShapeError::NotPositive { what: "height", .. })
        ));
        assert!(matches!(
            Cylinder::new(f64::INFINITY, 1.0, false),
            Err(ShapeError::NotFinite { what: "radius" })
        ));
    }

    #[test]
    fn uv_follow_the_side_and_cap_parametrisations() {
        let cases = [
            (Vec3::new(0.0, -5.0, 0.5), Vec3::Y, SIDE, 0.75, 0.25),
            (Vec3::new(-5.0, 0.0, 2.0), Vec3::X, SIDE, 0.5, 1.0),
            (Vec3::new(0.0, 0.5, 5.0), -Vec3::Z, TOP, 0.25, 0.5),
            (Vec3::new(-0.25, 0.0, -5.0), Vec3::Z, BOTTOM, 0.5, 0.75),
        ];
        for (origin, dir, part, u, v) in cases {
            let ray = Ray::new(origin, dir);
            let hit = capped().intersect(&ray).unwrap();
            assert_eq!(hit.part, part);
            let s = capped().surface(&ray, &hit);
            assert!(
                (s.uv - DVec2::new(u, v)).length() < 1e-15,
                "{origin}: {}",
                s.uv
            );
        }
    }

    #[test]
    fn rays_entering_through_a_rim_never_slip_between_side_and_cap() {
        let mut rng = Rng::new(67);
        for (radius, height) in [(1.0, 2.0), (0.37, 1.3), (1e-3, 4e-3), (1e4, 3e3)] {
            let shape = Cylinder::new(radius, height, true).unwrap();
            let mut entering = 0;
            for _ in 0..20_000 {
                let phi = rng.range(0.0, TAU);
                let (z, cap_normal) = if rng.uniform() < 0.5 {
                    (0.0, -Vec3::Z)
                } else {
                    (height, Vec3::Z)
                };
                let side_normal = Vec3::new(phi.cos(), phi.sin(), 0.0);
                let dir = rng.unit_vector();
                if dir.dot(side_normal) > -0.01 || dir.dot(cap_normal) > -0.01 {
                    continue;
                }
                entering += 1;
                let rim = Vec3::new(radius * phi.cos(), radius * phi.sin(), z);
                let ray = Ray::new(rim - 3.0 * radius * dir, dir);
                assert!(shape.intersect(&ray).is_some(), "{ray:?}");
            }
            assert!(entering > 2000, "{entering}");
        }
    }

    #[test]
    fn rays_leaving_points_near_the_rims_escape() {
        for (radius, height) in [(1.0, 2.0), (1e-3, 5e-3), (1e4, 3e3)] {
            for caps in [true, false] {
                let rims: Vec<Vec3> = (0..1000)
                    .map(|k| {
                        let phi = TAU * k as f64 / 1000.0;
                        let z = if k % 2 == 0 { 0.0 } else { height };
                        Vec3::new(radius * phi.cos(), radius * phi.sin(), z)
                    })
                    .collect();
                let shape = Shape::Cylinder(Cylinder::new(radius, height, caps).unwrap());
                let hits =
                    assert_outward_rays_escape(&shape, rays_toward(&rims, 3.0 * radius, 59), 61);
                assert!(hits > 300, "{hits}");
            }
        }
    }

    #[test]
    fn secondary_rays_never_hit_the_cylinder_they_leave() {
        for (radius, height) in [(1.0, 2.0), (0.5, 3.0), (1e-3, 2e-3), (1e4, 5e3)] {
            for caps in [true, false] {
                let shape = Shape::Cylinder(Cylinder::new(radius, height, caps).unwrap());
                assert_no_self_intersection(&shape, 47);
                assert_surface_is_sane(&shape, 53);
                assert_convex_exits_cleanly(&shape, 55);
                assert_no_nan_for_awkward_rays(&shape);
            }
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 1.0), Vec3::X);
        let s = capped().surface(&ray, &capped().intersect(&ray).unwrap());
        assert!((s.dpdu - Vec3::new(0.0, -TAU, 0.0)).length() < 1e-15);
        assert_eq!(s.dpdv, Vec3::new(0.0, 0.0, 2.0));
        for shape in [capped(), open(), Cylinder::new(3.0, 0.5, true).unwrap()] {
            assert_tangents_follow_uv(&Shape::Cylinder(shape), 19);
        }
    }
}
