//! A truncated cone in canonical position: axis +z, radius `radius0` at
//! z = 0 and `radius1` at z = height, open or closed by caps.
//!
//! Scene syntax: `shape = "cone"`, `base = [x, y, z]`, `base_radius = r0`,
//! `top = [x, y, z]`, `top_radius = r1`, and optionally `caps = false`
//! (default true; the NFF `c` primitive is open). The reader builds the
//! canonical cone of height `|top - base|` and places it with
//! `Transform::frame(base, top - base)`.
//!
//! One radius may be zero (a true cone with its apex there, and a cap only
//! at the other end); equal radii make a cylinder.
//!
//! Parts ([`ShapeHit::part`]): 0 the side, 1 the bottom cap (z = 0, facing
//! -z), 2 the top cap (z = height, facing +z). Texture coordinates on the
//! side: `u = φ / 2π` with `φ = atan2(y, x)` in [0, 2π), `v = z / height`;
//! on the caps, as on a disk: the same `u`, `v = 1 - r / radius` (0 on the
//! rim, 1 at the centre). `dpdu = 2π (-y, x, 0)` everywhere (zero at the
//! apex); `dpdv` is `(Δr cos φ, Δr sin φ, height)` with `Δr = r1 - r0` on
//! the side, up the slant, and points inwards on the caps (see
//! [`super::disk`]).

use std::f64::consts::TAU;

use super::disk::{azimuth, cap_geometry, cap_hit, cap_surface};
use super::{LocalSurface, ShapeError, ShapeHit, non_negative, positive, quadratic};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};

/// [`ShapeHit::part`] of the side.
const SIDE: u32 = 0;
/// [`ShapeHit::part`] of the bottom cap.
const BOTTOM: u32 = 1;
/// [`ShapeHit::part`] of the top cap.
const TOP: u32 = 2;

/// A truncated cone, open or capped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    radius0: f64,
    radius1: f64,
    height: f64,
    caps: bool,
}

impl Cone {
    /// The cone around the z axis from radius `radius0` at z = 0 to
    /// `radius1` at z = `height`, closed by disks where the radius is not
    /// zero when `caps` is set. Radii may be zero but not both.
    pub fn new(radius0: f64, radius1: f64, height: f64, caps: bool) -> Result<Self, ShapeError> {
        let radius0 = non_negative("radius0", radius0)?;
        let radius1 = non_negative("radius1", radius1)?;
        let height = positive("height", height)?;
        if radius0 == 0.0 && radius1 == 0.0 {
            return Err(ShapeError::Degenerate {
                shape: "cone",
                why: "both radii are zero",
            });
        }
        Ok(Self {
            radius0,
            radius1,
            height,
            caps,
        })
    }

    /// The radius at z = 0.
    pub fn radius0(&self) -> f64 {
        self.radius0
    }

    /// The radius at z = height.
    pub fn radius1(&self) -> f64 {
        self.radius1
    }

    /// The length along z.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// True when the ends with a non-zero radius are closed.
    pub fn caps(&self) -> bool {
        self.caps
    }

    /// The radius at height `z` in [0, height], as a weighted mean of the
    /// two radii (exact at both ends, no cancellation between them).
    fn radius_at(&self, z: f64) -> f64 {
        let s = z / self.height;
        self.radius0 * (1.0 - s) + self.radius1 * s
    }

    /// Both roots of the side's equation `x² + y² = ρ(z)²`, where
    /// `ρ(z) = r0 + k z` along the ray is `ρ0 + t ρ1`, or `None` when the
    /// ray misses the infinite double cone.
    ///
    /// The quadratic is `a t² + 2 b t + c` with `a = ⟨A, A⟩`, `b = ⟨A, B⟩`,
    /// `c = ⟨B, B⟩` for `A = (dx, dy, ρ1)`, `B = (ox, oy, ρ0)` in the metric
    /// diag(1, 1, -1). Its discriminant `b² - ac` equals `C₁² + C₂² - C₃²`
    /// for `C = A × B` (Lagrange's identity in that metric), which keeps its
    /// precision when the origin is far away. When `a` vanishes (a ray
    /// parallel to the cone's slope, or along the axis of a cylinder) the
    /// equation is linear, with a single root or none.
    fn side_roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let (o, d) = (ray.origin, ray.dir);
        let slope = (self.radius1 - self.radius0) / self.height;
        let rho0 = self.radius0 + slope * o.z;
        let rho1 = slope * d.z;
        let a = d.x * d.x + d.y * d.y - rho1 * rho1;
        let b = o.x * d.x + o.y * d.y - rho0 * rho1;
        let c = o.x * o.x + o.y * o.y - rho0 * rho0;
        if a == 0.0 {
            return (b != 0.0).then(|| {
                let t = -c / (2.0 * b);
                (t, t)
            });
        }
        let c1 = d.y * rho0 - rho1 * o.y;
        let c2 = rho1 * o.x - d.x * rho0;
        let c3 = d.x * o.y - d.y * o.x;
        quadratic::solve(a, b, c, c1 * c1 + c2 * c2 - c3 * c3)
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
            for (part, height, radius) in [
                (BOTTOM, 0.0, self.radius0),
                (TOP, self.height, self.radius1),
            ] {
                if radius > 0.0
                    && let Some(t) = cap_hit(ray, height, radius, 0.0)
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

    /// True when the ray meets the cone in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let p = ray.at(hit.t);
        match hit.part {
            BOTTOM => cap_surface(p, 0.0, -1.0, self.radius0, 0.0),
            TOP => cap_surface(p, self.height, 1.0, self.radius1, 0.0),
            _ => self.side_surface(p),
        }
    }

    /// The side's surface at `p`, moved radially onto the cone at its
    /// height.
    ///
    /// Error bound: `γ(8)|p|` per axis. Its x and y parts cover the radial
    /// move; its z part, which the slope turns into a radial distance of
    /// `γ(8)|r1 - r0| z / h` along the normal, covers the rounding of the
    /// radius at that height, here and when a new ray is tested from there.
    fn side_surface(&self, p: Vec3) -> LocalSurface {
        let (s, (cos, sin)) = self.side_geometry(p);
        let point = s.point;
        LocalSurface {
            uv: DVec2::new(azimuth(cos, sin) / TAU, point.z / self.height),
            dpdu: Vec3::new(-TAU * point.y, TAU * point.x, 0.0),
            dpdv: Vec3::new(
                (self.radius1 - self.radius0) * cos,
                (self.radius1 - self.radius0) * sin,
                self.height,
            ),
            ..s
        }
    }

    /// The side's point, error bound and normal at `p` (see
    /// [`Self::side_surface`]), (u, v) and the tangents zero; and the
    /// cosine and sine of the point's angle about the axis.
    fn side_geometry(&self, p: Vec3) -> (LocalSurface, (f64, f64)) {
        let z = p.z.clamp(0.0, self.height);
        let rho = self.radius_at(z);
        let r = p.x.hypot(p.y);
        let (cos, sin) = if r > 0.0 {
            (p.x / r, p.y / r)
        } else {
            (1.0, 0.0)
        };
        let point = Vec3::new(rho * cos, rho * sin, z);
        let slant = self.height.hypot(self.radius0 - self.radius1);
        let surface = LocalSurface {
            point,
            point_error: gamma(8) * point.abs(),
            normal: Vec3::new(
                cos * (self.height / slant),
                sin * (self.height / slant),
                (self.radius0 - self.radius1) / slant,
            ),
            uv: DVec2::ZERO,
            dpdu: Vec3::ZERO,
            dpdv: Vec3::ZERO,
        };
        (surface, (cos, sin))
    }

    /// The surface at a hit without its parametric part: (u, v) and the
    /// tangents are left zero (see [`crate::shape::Shape::surface_geometry`]).
    pub fn surface_geometry(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let p = ray.at(hit.t);
        match hit.part {
            BOTTOM => cap_geometry(p, 0.0, -1.0),
            TOP => cap_geometry(p, self.height, 1.0),
            _ => self.side_geometry(p).0,
        }
    }

    /// The bounding box.
    pub fn bounds(&self) -> Aabb {
        let r = self.radius0.max(self.radius1);
        Aabb::new(Vec3::new(-r, -r, 0.0), Vec3::new(r, r, self.height))
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::SQRT_2;

    use super::*;
    use crate::math::random::Rng;
    use crate::shape::testing::{
        assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
        assert_outward_rays_escape, assert_surface_is_sane, assert_tangents_follow_uv, rays_toward,
    };
    use crate::shape::{Cylinder, Shape, ShapeError};

    /// Radius 1 at z = 0, apex at z = 1.
    fn pointed(caps: bool) -> Cone {
        Cone::new(1.0, 0.0, 1.0, caps).unwrap()
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-15
    }

    #[test]
    fn ray_from_outside_hits_the_side_with_exact_t_and_outward_normal() {
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.5), Vec3::new(2.0, 0.0, 0.0));
        let hit = pointed(true).intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (2.25, SIDE));
        let s = pointed(true).surface(&ray, &hit);
        assert_eq!(s.point, Vec3::new(-0.5, 0.0, 0.5));
        assert!(close(s.normal, Vec3::new(-1.0, 0.0, 1.0) / SQRT_2));
    }

    #[test]
    fn frustum_side_is_hit_at_the_interpolated_radius() {
        let frustum = Cone::new(1.0, 0.5, 2.0, false).unwrap();
        let ray = Ray::new(Vec3::new(0.0, -5.0, 1.0), Vec3::Y);
        let hit = frustum.intersect(&ray).unwrap();
        assert_eq!(hit.t, 4.25);
        let s = frustum.surface(&ray, &hit);
        let slant = 4.25f64.sqrt();
        assert!(close(s.normal, Vec3::new(0.0, -2.0 / slant, 0.5 / slant)));
    }

    #[test]
    fn ray_starting_inside_hits_the_far_side_or_the_cap() {
        let sideways = Ray::new(Vec3::new(0.0, 0.0, 0.25), Vec3::X);
        let hit = pointed(true).intersect(&sideways).unwrap();
        assert_eq!((hit.t, hit.part), (0.75, SIDE));
        let s = pointed(true).surface(&sideways, &hit);
        assert!(close(s.normal, Vec3::new(1.0, 0.0, 1.0) / SQRT_2));

        let down = Ray::new(Vec3::new(0.2, 0.1, 0.5), -Vec3::Z);
        let hit = pointed(true).intersect(&down).unwrap();
        assert_eq!((hit.t, hit.part), (0.5, BOTTOM));
        assert_eq!(pointed(true).surface(&down, &hit).normal, -Vec3::Z);
        assert_eq!(pointed(false).intersect(&down), None);
    }

    #[test]
    fn ray_down_the_axis_touches_the_apex_without_nan() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -2.0));
        let hit = pointed(false).intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (2.0, SIDE));
        let s = pointed(false).surface(&ray, &hit);
        assert_eq!(s.point, Vec3::new(0.0, 0.0, 1.0));
        assert!((s.normal.length() - 1.0).abs() < 1e-15);
        assert_eq!(s.dpdu, Vec3::ZERO);
        assert!(s.uv.is_finite());
    }

    #[test]
    fn ray_up_the_axis_hits_the_bottom_cap_only_when_capped() {
        let ray = Ray::new(Vec3::new(0.25, 0.0, -3.0), Vec3::Z);
        let hit = pointed(true).intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (3.0, BOTTOM));
        let hit = pointed(false).intersect(&ray).unwrap();
        assert_eq!(hit.part, SIDE);
        assert!((hit.t - 3.75).abs() < 1e-15);
    }

    #[test]
    fn cone_with_its_apex_at_the_bottom_has_only_a_top_cap() {
        let cup = Cone::new(0.0, 1.0, 1.0, true).unwrap();
        let from_below = Ray::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z);
        let hit = cup.intersect(&from_below).unwrap();
        assert_eq!((hit.t, hit.part), (1.0, SIDE));
        let from_above = Ray::new(Vec3::new(0.5, 0.0, 2.0), -Vec3::Z);
        let hit = cup.intersect(&from_above).unwrap();
        assert_eq!((hit.t, hit.part), (1.0, TOP));
        assert_eq!(cup.surface(&from_above, &hit).normal, Vec3::Z);
    }

    #[test]
    fn ray_parallel_to_the_slope_hits_the_far_side_once() {
        let ray = Ray::new(Vec3::new(0.5, 0.0, 0.0), Vec3::new(-1.0, 0.0, 1.0));
        let hit = pointed(true).intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.part), (0.75, SIDE));
        let outside = Ray::new(Vec3::new(1.5, 0.0, 0.0), Vec3::new(-1.0, 0.0, 1.0));
        assert_eq!(pointed(true).intersect(&outside), None);
    }

    #[test]
    fn rays_tangent_to_the_side_or_lying_in_it_give_no_nan() {
        let tangent = Ray::new(Vec3::new(-5.0, 0.5, 0.5), Vec3::X);
        let hit = pointed(false).intersect(&tangent).unwrap();
        assert_eq!(hit.t, 5.0);
        let s = pointed(false).surface(&tangent, &hit);
        assert!(close(s.normal, Vec3::new(0.0, 1.0, 1.0) / SQRT_2));
        let along = Ray::new(Vec3::new(2.0, 0.0, -1.0), Vec3::new(-1.0, 0.0, 1.0));
        for shape in [pointed(true), pointed(false)] {
            if let Some(hit) = shape.intersect(&along) {
                let s = shape.surface(&along, &hit);
                assert!(s.normal.is_finite() && s.uv.is_finite() && s.point.is_finite());
            }
        }
    }

    #[test]
    fn cone_behind_the_ray_or_beside_it_is_missed() {
        for ray in [
            Ray::new(Vec3::new(-5.0, 0.0, 0.5), -Vec3::X),
            Ray::new(Vec3::new(-5.0, 0.5 + 1e-9, 0.5), Vec3::X),
            Ray::new(Vec3::new(-5.0, 0.0, 1.0 + 1e-9), Vec3::X),
            Ray::new(Vec3::new(-5.0, 0.0, -1e-9), Vec3::X),
        ] {
            assert_eq!(pointed(true).intersect(&ray), None, "{ray:?}");
            assert!(!pointed(true).occluded(&ray));
        }
    }

    #[test]
    fn hits_at_or_beyond_t_max_are_ignored() {
        let ray = Ray::segment(Vec3::new(-5.0, 0.0, 0.5), Vec3::X, 4.5);
        assert_eq!(pointed(true).intersect(&ray), None);
    }

    #[test]
    fn equal_radii_behave_like_a_cylinder() {
        let cone = Cone::new(1.0, 1.0, 2.0, true).unwrap();
        let cylinder = Cylinder::new(1.0, 2.0, true).unwrap();
        let mut rng = Rng::new(71);
        let mut hits = 0;
        for _ in 0..2000 {
            let origin = Vec3::new(0.0, 0.0, 1.0) + 4.0 * rng.unit_vector();
            let target = rng.point_in(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 2.0));
            let ray = Ray::new(origin, target - origin);
            let (a, b) = (cone.intersect(&ray), cylinder.intersect(&ray));
            assert_eq!(a.is_some(), b.is_some(), "{ray:?}");
            if let (Some(a), Some(b)) = (a, b) {
                hits += 1;
                assert_eq!(a.part, b.part);
                assert!((a.t - b.t).abs() < 1e-12 * b.t, "{} {}", a.t, b.t);
                let (sa, sb) = (cone.surface(&ray, &a), cylinder.surface(&ray, &b));
                assert!((sa.normal - sb.normal).length() < 1e-12);
            }
        }
        assert!(hits > 1000);
        let along_the_axis = Ray::new(Vec3::new(0.5, 0.0, -1.0), Vec3::Z);
        assert_eq!(cone.intersect(&along_the_axis).unwrap().part, BOTTOM);
    }

    #[test]
    fn bad_radii_or_height_are_refused() {
        assert_eq!(
            Cone::new(0.0, 0.0, 1.0, true),
            Err(ShapeError::Degenerate {
                shape: "cone",
                why: "both radii are zero"
            })
        );
        assert_eq!(
            Cone::new(-1.0, 1.0, 1.0, false),
            Err(ShapeError::Negative {
                what: "radius0",
                value: -1.0
            })
        );
        assert!(matches!(
            Cone::new(1.0, -0.5, 1.0, false),
            Err(ShapeError::Negative {
                what: "radius1",
                ..
            })
        ));
        assert!(matches!(
            Cone::new(1.0, 0.5, 0.0, false),
            Err(ShapeError::NotPositive { what: "height", .. })
        ));
        assert!(matches!(
            Cone::new(f64::NAN, 0.5, 1.0, false),
            Err(ShapeError::NotFinite { what: "radius0" })
        ));
    }

    #[test]
    fn uv_follow_the_side_and_cap_parametrisations() {
        let cases = [
            (Vec3::new(-5.0, 0.0, 0.5), Vec3::X, SIDE, 0.5, 0.5),
            (Vec3::new(0.0, -5.0, 0.25), Vec3::Y, SIDE, 0.75, 0.25),
            (Vec3::new(0.0, -0.5, -5.0), Vec3::Z, BOTTOM, 0.75, 0.5),
        ];
        for (origin, dir, part, u, v) in cases {
            let ray = Ray::new(origin, dir);
            let hit = pointed(true).intersect(&ray).unwrap();
            assert_eq!(hit.part, part);
            let s = pointed(true).surface(&ray, &hit);
            assert!(
                (s.uv - DVec2::new(u, v)).length() < 1e-15,
                "{origin}: {}",
                s.uv
            );
        }
    }

    #[test]
    fn rays_entering_through_a_rim_never_slip_between_side_and_cap() {
        let mut rng = Rng::new(137);
        for (radius0, radius1, height) in [(1.0, 0.3, 2.0), (0.4, 1.1, 0.5), (1e4, 3e3, 3e3)] {
            let shape = Cone::new(radius0, radius1, height, true).unwrap();
            let slant = height.hypot(radius0 - radius1);
            let mut entering = 0;
            for _ in 0..20_000 {
                let phi = rng.range(0.0, TAU);
                let (z, radius, cap_normal) = if rng.uniform() < 0.5 {
                    (0.0, radius0, -Vec3::Z)
                } else {
                    (height, radius1, Vec3::Z)
                };
                let side_normal = Vec3::new(
                    phi.cos() * height / slant,
                    phi.sin() * height / slant,
                    (radius0 - radius1) / slant,
                );
                let dir = rng.unit_vector();
                if dir.dot(side_normal) > -0.01 || dir.dot(cap_normal) > -0.01 {
                    continue;
                }
                entering += 1;
                let rim = Vec3::new(radius * phi.cos(), radius * phi.sin(), z);
                let ray = Ray::new(rim - 3.0 * slant * dir, dir);
                assert!(shape.intersect(&ray).is_some(), "{ray:?}");
            }
            assert!(entering > 1000, "{entering}");
        }
    }

    #[test]
    fn rays_leaving_points_near_the_rims_and_the_apex_escape() {
        for (radius0, radius1, height) in [
            (1.0, 0.0, 1.0),
            (0.3, 1.2, 0.5),
            (1.0, 0.0, 1e-3),
            (1e4, 2e3, 5e3),
        ] {
            for caps in [true, false] {
                let cone = Cone::new(radius0, radius1, height, caps).unwrap();
                let rims: Vec<Vec3> = (0..1000)
                    .map(|k| {
                        let phi = TAU * k as f64 / 1000.0;
                        let (z, r) = if k % 2 == 0 {
                            (0.0, radius0)
                        } else {
                            (height, radius1)
                        };
                        Vec3::new(r * phi.cos(), r * phi.sin(), z)
                    })
                    .collect();
                let size = radius0.max(radius1).max(height);
                let rays = rays_toward(&rims, 3.0 * size, 73);
                let hits = assert_outward_rays_escape(&Shape::Cone(cone), rays, 79);
                assert!(hits > 300, "{hits}");
            }
        }
    }

    #[test]
    fn rays_leaving_nearly_flat_cones_outward_escape() {
        // Inward rays may legitimately meet the other part of such a thin
        // wedge within 1e-7 of its size, so only outward rays are checked.
        for (radius0, radius1, height) in [(1.0, 0.0, 1e-3), (0.5, 1.0, 1e-4), (1e4, 0.0, 1.0)] {
            for caps in [true, false] {
                let shape = Shape::Cone(Cone::new(radius0, radius1, height, caps).unwrap());
                assert_surface_is_sane(&shape, 127);
                assert_convex_exits_cleanly(&shape, 131);
                assert_no_nan_for_awkward_rays(&shape);
            }
        }
    }

    #[test]
    fn secondary_rays_never_hit_the_cone_they_leave() {
        for (radius0, radius1, height) in [
            (1.0, 0.0, 1.0),
            (0.0, 1.0, 2.0),
            (1.0, 0.4, 0.7),
            (0.5, 0.5, 1.0),
            (2.0, 0.1, 0.05),
            (1e-3, 0.0, 2e-3),
            (1e4, 3e3, 2e4),
        ] {
            for caps in [true, false] {
                let cone = Cone::new(radius0, radius1, height, caps).unwrap();
                let shape = Shape::Cone(cone);
                assert_no_self_intersection(&shape, 83);
                assert_surface_is_sane(&shape, 89);
                assert_convex_exits_cleanly(&shape, 97);
                assert_no_nan_for_awkward_rays(&shape);
            }
        }
    }

    #[test]
    fn tangents_are_the_derivatives_of_the_parametric_form() {
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.5), Vec3::X);
        let s = pointed(true).surface(&ray, &pointed(true).intersect(&ray).unwrap());
        assert!(close(s.dpdv, Vec3::new(1.0, 0.0, 1.0)), "{}", s.dpdv);
        for (radius0, radius1, height) in [(1.0, 0.0, 1.0), (0.5, 1.5, 2.0), (2.0, 1.0, 0.3)] {
            let cone = Cone::new(radius0, radius1, height, true).unwrap();
            assert_tangents_follow_uv(&Shape::Cone(cone), 23);
        }
    }
}
