//! A sphere given by its centre and radius.
//!
//! Scene syntax: `shape = "sphere"`, `center = [x, y, z]`, `radius = r`.
//!
//! Texture coordinates follow pbrt with z as the pole: `u = φ / 2π` with
//! `φ = atan2(y, x)` measured about the centre, `v = 0` at the bottom
//! (`z = -r`) rising to `v = 1` at the top. The tangents are the
//! derivatives of that form: `dpdu = 2π (-y, x, 0)` (zero at the poles) and
//! `dpdv = π (-z cos φ, -z sin φ, √(x² + y²))`, pointing north.
//!
//! The discriminant needs no division and [`beyond`] culls without a
//! square root, so the spheres a ray passes by cost little where many
//! overlap (measured, with the same picture to the bit:
//! docs/performance-log.md, figures moved out of doc comments).

use std::f64::consts::{PI, TAU};

use super::{LocalSurface, ShapeError, ShapeHit, finite, positive, quadratic};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    center: Vec3,
    radius: f64,
}

/// `1 + 2⁻⁴⁰`, the factor from `t_max` to `t′` in [`beyond`].
pub(super) const BEYOND_MARGIN: f64 = 1.0 + 1.0 / (1u64 << 40) as f64;

/// True when no root that [`quadratic::solve`] computes for
/// `a t² + 2 b t + c` (reduced discriminant `disc`) lies in `(t_min, t_max)`
/// with `t_min ≥ 0`, decided without the square root or a division: the
/// spheres a closest-hit search has already passed, and those around a
/// ray's origin that it leaves beyond `t_max` (many, where spheres
/// overlap), then cost little.
///
/// With `q = −(b + sign(b) √disc)`, `solve` returns `q / a` and `c / q`,
/// each within `γ(3)` relative of its exact value for the given `a`, `b`,
/// `c`, `disc`; testing against `t′ = t_max (1 + 2⁻⁴⁰)` covers that. A root
/// at or below zero is never in the interval.
/// - `b < 0`: `q / a > 0` is beyond when `−b ≥ a t′` (as `q ≥ −b`); `c / q`
///   is at most zero when `c ≤ 0`, else beyond when `c + b t′ ≥ t′ √disc`.
/// - `b ≥ 0`: `q ≤ 0`, so `q / a ≤ 0`, and `c / q ≤ 0` when `c > 0`; else
///   `c / q` is beyond when `−c − b t′ ≥ t′ √disc`.
///
/// The left sides are computed less `γ(4)` times the sum of their terms'
/// magnitudes, more than their rounding, and compared squared with a
/// further `γ(4)` for the rounding of both sides. An infinite `t_max` or a
/// NaN never culls.
#[inline]
fn beyond(a: f64, b: f64, c: f64, disc: f64, t_min: f64, t_max: f64) -> bool {
    let t = t_max * BEYOND_MARGIN;
    let root_beyond = |left: f64, error: f64| {
        let left = left - gamma(4) * error;
        left > 0.0 && left * left >= t * t * disc * (1.0 + gamma(4))
    };
    t_min >= 0.0
        && if b < 0.0 {
            -b >= a * t && (c <= 0.0 || root_beyond(c + b * t, c - b * t))
        } else if b >= 0.0 {
            c > 0.0 || root_beyond(-c - b * t, b * t - c)
        } else {
            false
        }
}

impl Sphere {
    /// A sphere around `center`; the radius must be positive.
    pub fn new(center: Vec3, radius: f64) -> Result<Self, ShapeError> {
        Ok(Self {
            center: finite("center", center)?,
            radius: positive("radius", radius)?,
        })
    }

    /// The sphere of `center` and `radius` taken from a sphere that
    /// [`Sphere::new`] accepted (a world keeps them beside its other
    /// entries and rebuilds the sphere to test it).
    #[inline(always)]
    pub(crate) fn from_accepted(center: Vec3, radius: f64) -> Self {
        Self { center, radius }
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
    /// which stays accurate for small spheres far away; that distance times
    /// `a` is `|f × d|²` (Lagrange's identity), which needs no division, so
    /// a ray that misses costs no division or square root.
    pub(super) fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let f = ray.origin - self.center;
        let a = ray.dir.length_squared();
        let b = f.dot(ray.dir);
        let c = f.length_squared() - self.radius * self.radius;
        let disc = a * (self.radius * self.radius) - f.cross(ray.dir).length_squared();
        if beyond(a, b, c, disc, ray.t_min, ray.t_max) {
            return None;
        }
        quadratic::solve(a, b, c, disc)
    }

    /// The closest hit in the ray's interval.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let roots = self.roots(ray)?;
        quadratic::nearest_in(roots, ray.t_min, ray.t_max).map(ShapeHit::at)
    }

    /// Where the ray crosses the sphere in its interval, nearest first: the
    /// hits that closest-hit tests find one after the other, each with
    /// the interval starting at the hit before, from one quadratic. A ray
    /// that touches the sphere (two equal roots) crosses it once.
    pub(crate) fn crossings(&self, ray: &Ray) -> impl Iterator<Item = f64> {
        let (t_min, t_max) = (ray.t_min, ray.t_max);
        let roots = self
            .roots(ray)
            .map_or([None, None], |(t0, t1)| [Some(t0), (t1 > t0).then_some(t1)]);
        roots
            .into_iter()
            .flatten()
            .filter(move |&t| t > t_min && t < t_max)
    }

    /// True when the ray meets the sphere in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let (mut surface, local) = self.placed(ray, hit);
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let theta = (local.z / self.radius).clamp(-1.0, 1.0).acos();
        // cos φ and sin φ from the point itself (φ = 0 at the poles, as
        // atan2(0, 0) gives).
        let rho = local.x.hypot(local.y);
        let (sin_phi, cos_phi) = if rho > 0.0 {
            (local.y / rho, local.x / rho)
        } else {
            (0.0, 1.0)
        };
        surface.uv = DVec2::new(phi / TAU, 1.0 - theta / PI);
        surface.dpdu = Vec3::new(-TAU * local.y, TAU * local.x, 0.0);
        surface.dpdv = PI * Vec3::new(-local.z * cos_phi, -local.z * sin_phi, rho);
        surface
    }

    /// The surface at a hit without its parametric part: (u, v) and the
    /// tangents are left zero (see [`crate::shape::Shape::surface_geometry`]).
    pub fn surface_geometry(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        self.placed(ray, hit).0
    }

    /// The point, its error bound and the normal at a hit, with (u, v) and
    /// the tangents zero; and the point relative to the centre.
    #[inline]
    fn placed(&self, ray: &Ray, hit: &ShapeHit) -> (LocalSurface, Vec3) {
        let mut local = ray.at(hit.t) - self.center;
        let length = local.length();
        if length > 0.0 {
            local *= self.radius / length;
        } else {
            local = Vec3::new(0.0, 0.0, self.radius);
        }
        let surface = LocalSurface {
            point: self.center + local,
            point_error: gamma(8) * (self.center.abs() + local.abs()),
            normal: local / self.radius,
            uv: DVec2::ZERO,
            dpdu: Vec3::ZERO,
            dpdv: Vec3::ZERO,
        };
        (surface, local)
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

    /// The roots as computed without [`beyond`]'s cull.
    fn unculled(sphere: &Sphere, ray: &Ray) -> Option<f64> {
        let far_away = Ray {
            t_max: f64::INFINITY,
            ..*ray
        };
        let roots = sphere.roots(&far_away)?;
        quadratic::nearest_in(roots, ray.t_min, ray.t_max)
    }

    #[test]
    fn radii_whose_squares_overflow_or_underflow_are_refused() {
        for radius in [2e154, 1e-200] {
            assert!(matches!(
                Sphere::new(Vec3::ZERO, radius),
                Err(ShapeError::OutOfRange { what: "radius", .. })
            ));
        }
        assert!(matches!(
            Sphere::new(Vec3::new(0.0, 1e40, 0.0), 1.0),
            Err(ShapeError::OutOfRange { what: "center", .. })
        ));
    }

    #[test]
    fn culling_passed_spheres_never_changes_the_hit() {
        let mut rng = crate::math::random::Rng::new(11);
        let mut culled = 0;
        for _ in 0..100_000 {
            let point = |rng: &mut crate::math::random::Rng, scale: f64| {
                scale * Vec3::new(rng.uniform(), rng.uniform(), rng.uniform())
                    - Vec3::splat(scale / 2.0)
            };
            let scale = [1e-3, 1.0, 1e4][rng.below(3) as usize];
            let sphere =
                Sphere::new(point(&mut rng, scale), scale * (0.05 + rng.uniform())).unwrap();
            let origin = point(&mut rng, 4.0 * scale);
            let dir = point(&mut rng, 2.0) * [1.0, 1e-3, 1e3][rng.below(3) as usize];
            let mut ray = Ray::new(origin, dir);
            // t_max at, just below or just above the hit, or anywhere short
            // of it.
            let t = unculled(&sphere, &ray).unwrap_or(scale * rng.uniform());
            ray.t_max = match rng.below(2) {
                0 => t + [-2.0, -1.0, 0.0, 1.0, 2.0][rng.below(5) as usize] * t * f64::EPSILON,
                _ => t * rng.uniform(),
            };
            ray.t_min = [0.0, 1e-9 * scale, 0.5 * t.abs()][rng.below(3) as usize];
            let hit = sphere.intersect(&ray).map(|h| h.t);
            assert_eq!(hit, unculled(&sphere, &ray), "{sphere:?} {ray:?}");
            let far_away = Ray {
                t_max: f64::INFINITY,
                ..ray
            };
            culled +=
                usize::from(sphere.roots(&ray).is_none() && sphere.roots(&far_away).is_some());
        }
        assert!(culled > 1000, "the cull was exercised only {culled} times");
    }

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
    fn crossings_are_the_hits_of_successive_tests() {
        let mut rng = crate::math::random::Rng::new(5);
        let sphere = Sphere::new(Vec3::new(0.5, -0.25, 1.0), 1.5).unwrap();
        let mut counts = [0; 3];
        for _ in 0..2000 {
            // From inside and outside, towards points in and around it.
            let origin = sphere.center() + 4.0 * rng.unit_vector() * rng.uniform();
            let aim = sphere.center() + 2.0 * rng.unit_vector() * rng.uniform();
            let dir = (aim - origin).normalize();
            let mut ray = Ray::segment(origin, dir, 8.0 * rng.uniform());
            let crossings = sphere.crossings(&ray).collect::<Vec<_>>();
            let mut hits = Vec::new();
            while let Some(hit) = sphere.intersect(&ray) {
                hits.push(hit.t);
                ray.t_min = hit.t;
            }
            assert_eq!(crossings, hits, "{ray:?}");
            counts[hits.len()] += 1;
        }
        assert!(counts.iter().all(|&n| n > 100), "{counts:?}");
        let touching = Ray::new(Vec3::new(-5.0, 1.0, 0.0), Vec3::X);
        assert_eq!(unit().crossings(&touching).collect::<Vec<_>>(), [5.0]);
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
