//! POV-Ray's superellipsoid: the solid
//! `(|x|^(2/e) + |y|^(2/e))^(e/n) + |z|^(2/n) ≤ 1` scaled by `radius`
//! about `center`.
//!
//! Scene syntax: `shape = "superellipsoid"`, `e = 0.5`, `n = 0.5`,
//! optionally `center = [x, y, z]` (default the origin) and `radius = r`
//! (default 1). `e` shapes the cross-sections parallel to the xy plane,
//! `n` the profile along z: `e = n = 1` is the sphere, `e = n = 2` the
//! octahedron `|x| + |y| + |z| = 1`, small values tend to the cube, values
//! above 2 make stars with ever thinner spikes along the axes.
//!
//! Both exponents must lie in [[`MIN_EXPONENT`], [`MAX_EXPONENT`]]. Below
//! 0.001 the powers `2/e` exceed 2000 and the shape is a cube to within
//! the rounding of its own function; above 10 the spikes along the axes
//! are thinner than 4e-5 of the radius half way out and `|z|^(2/n)` is so
//! steep at `z = 0` that nothing more would be seen.
//!
//! Intersection ([`search`]): the ray is clipped to the bounding cube and
//! cut where the function's pieces change; stretches of it are then
//! dropped, solved or halved using exact bounds of the function and of its
//! slope over them, which follow from the function being nondecreasing in
//! `|x|`, `|y|` and `|z|`. That search cannot step over a thin part (a
//! dropped stretch provably holds none) and needs no tuning of a step, and
//! it spends its halvings only where the ray comes close to the surface.
//!
//! The normal is the gradient of the function. Where a term's gradient is
//! infinite (the creases of `e > 2` at x = 0 or y = 0, of `n > 2` at
//! z = 0), it is the limit approached from the side of the point's sign:
//! the axes of the infinite components. At the poles (x = y = 0) it is ±z.
//!
//! Texture coordinates come from the superquadric's parametric form
//! `x = cos(η)^n cos(ω)^e`, `y = cos(η)^n sin(ω)^e`, `z = sin(η)^n` (signed
//! powers), η from -π/2 to π/2 and ω from -π to π: `u = ω / 2π` in
//! [0, 1) (as the sphere's `u` for `e = n = 1`), `v = (η + π/2) / π`, 0
//! at the bottom, 1 at the top. `dpdu`, `dpdv` are the derivatives of that
//! form, projected on the tangent plane; where they are infinite or zero
//! (at the poles, at the creases of small exponents) a tangent frame about
//! the normal, of the shape's size, takes their place.

mod implicit;
mod search;
#[cfg(test)]
mod tests;

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::{LocalSurface, ShapeError, ShapeHit, finite, positive};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma, unit};
use implicit::Exponents;
use search::Line;

/// The smallest exponent `e` or `n` accepted.
pub const MIN_EXPONENT: f64 = 1e-3;

/// The largest exponent `e` or `n` accepted.
pub const MAX_EXPONENT: f64 = 10.0;

/// A superellipsoid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Superellipsoid {
    center: Vec3,
    radius: f64,
    e: f64,
    n: f64,
    exponents: Exponents,
}

/// Checks that `value` is an exponent `e` or `n` of a superellipsoid: a
/// number in [[`MIN_EXPONENT`], [`MAX_EXPONENT`]].
pub fn exponent(what: &'static str, value: f64) -> Result<f64, ShapeError> {
    if !value.is_finite() {
        Err(ShapeError::NotFinite { what })
    } else if value <= 0.0 {
        Err(ShapeError::NotPositive { what, value })
    } else if !(MIN_EXPONENT..=MAX_EXPONENT).contains(&value) {
        Err(ShapeError::Degenerate {
            shape: "superellipsoid",
            why: "the exponents e and n must lie between 0.001 and 10",
        })
    } else {
        Ok(value)
    }
}

impl Superellipsoid {
    /// The superellipsoid of exponents `e` and `n` (see [`exponent`]),
    /// inside the cube of half-side `radius` about `center`.
    pub fn new(center: Vec3, radius: f64, e: f64, n: f64) -> Result<Self, ShapeError> {
        let (e, n) = (exponent("e", e)?, exponent("n", n)?);
        Ok(Self {
            center: finite("center", center)?,
            radius: positive("radius", radius)?,
            e,
            n,
            exponents: Exponents::new(e, n),
        })
    }

    /// The centre.
    pub fn center(&self) -> Vec3 {
        self.center
    }

    /// The half-side of the bounding cube.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The exponent within planes parallel to xy.
    pub fn e(&self) -> f64 {
        self.e
    }

    /// The exponent along z.
    pub fn n(&self) -> f64 {
        self.n
    }

    /// The ray in unit space (the same `t`).
    fn unit_ray(&self, ray: &Ray) -> Ray {
        Ray {
            t_min: ray.t_min,
            t_max: ray.t_max,
            ..Ray::new(
                (ray.origin - self.center) / self.radius,
                ray.dir / self.radius,
            )
        }
    }

    /// The closest hit in the ray's interval.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let local = self.unit_ray(ray);
        let cube = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let (t_start, t_end) = cube.intersect_ray(&local)?;
        let line = Line {
            exponents: &self.exponents,
            origin: local.origin,
            dir: local.dir,
        };
        let t = line.first_crossing(t_start, t_end)?;
        ray.contains(t).then(|| ShapeHit::at(t))
    }

    /// True when the ray meets the superellipsoid in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    ///
    /// The point is the ray's, not moved: the search brackets the sign
    /// change of the function to a few ulps, and a reprojection through
    /// the centre (exact for a sphere) moves points a long way along the
    /// spikes of a star, whose sides are nearly radial.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let point = ray.at(hit.t);
        let local = (point - self.center) / self.radius;
        // The function's rounding puts the computed surface within some
        // 1e-15 of the true one; its gradient is at least q/√3 ≥ 0.11 on
        // the surface (Euler's identity for a function homogeneous of
        // degree q), so 1e-13 of the radius covers it with a margin.
        let point_error = gamma(4) * (ray.origin.abs() + (hit.t * ray.dir).abs())
            + Vec3::splat(1e-13 * self.radius * local.abs().max_element());
        let normal = self.normal(local);
        let (uv, dpdu, dpdv) = self.parametric(local, normal);
        LocalSurface {
            point,
            point_error,
            normal,
            uv,
            dpdu,
            dpdv,
        }
    }

    /// The bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(
            self.center - Vec3::splat(self.radius),
            self.center + Vec3::splat(self.radius),
        )
    }

    /// The outward unit normal at `p` on the unit surface.
    fn normal(&self, p: Vec3) -> Vec3 {
        let a = p.abs();
        let g = Vec3::from(self.exponents.magnitude_gradient(a.x, a.y, a.z));
        let g = if g.is_finite() {
            g
        } else {
            Vec3::select(g.cmpeq(Vec3::INFINITY), Vec3::ONE, Vec3::ZERO)
        };
        let signs = Vec3::new(p.x.signum(), p.y.signum(), p.z.signum());
        unit(g * signs).or_else(|| unit(p)).unwrap_or(Vec3::Z)
    }

    /// (u, v), `dpdu` and `dpdv` at `p` on the unit surface, as the module
    /// doc says.
    fn parametric(&self, p: Vec3, normal: Vec3) -> (DVec2, Vec3, Vec3) {
        let (e, n) = (self.e, self.n);
        let a = p.abs();
        let root = |value: f64, power: f64, sign: f64| sign * value.powf(power);
        let omega = root(a.y, 1.0 / e, p.y.signum()).atan2(root(a.x, 1.0 / e, p.x.signum()));
        let planar = self.exponents.planar(a.x, a.y);
        let eta = root(a.z, 1.0 / n, p.z.signum()).atan2(planar.powf(self.exponents.q / 2.0));
        let u = if omega < 0.0 { omega + TAU } else { omega } / TAU;
        let v = (eta + FRAC_PI_2) / PI;
        let (sin_w, cos_w) = omega.sin_cos();
        let (sin_h, cos_h) = eta.sin_cos();
        let signed = |value: f64, power: f64| value.signum() * value.abs().powf(power);
        let slope = |value: f64, power: f64| power * value.abs().powf(power - 1.0);
        let ring = signed(cos_h, n);
        let d_omega = Vec3::new(
            -ring * slope(cos_w, e) * sin_w,
            ring * slope(sin_w, e) * cos_w,
            0.0,
        );
        let d_ring = -slope(cos_h, n) * sin_h;
        let d_eta = Vec3::new(
            d_ring * signed(cos_w, e),
            d_ring * signed(sin_w, e),
            slope(sin_h, n) * cos_h,
        );
        let tangent = |d: Vec3, scale: f64| {
            let d = self.radius * scale * d;
            let d = d - d.dot(normal) * normal;
            (d.is_finite() && d.length() > 1e-12 * self.radius).then_some(d)
        };
        let across = if normal.z.abs() < 0.9 {
            Vec3::Z
        } else {
            Vec3::X
        };
        let east = unit(across.cross(normal)).unwrap_or(Vec3::X);
        let dpdu = tangent(d_omega, TAU).unwrap_or(TAU * self.radius * east);
        let dpdv = tangent(d_eta, PI).unwrap_or(PI * self.radius * normal.cross(east));
        (DVec2::new(u, v), dpdu, dpdv)
    }
}
