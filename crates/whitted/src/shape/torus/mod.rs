//! A torus centred at the origin, lying in the xz-plane around the y axis
//! (POV-Ray's convention): the points at distance `minor` from the circle
//! of radius `major` in the xz-plane.
//!
//! Scene syntax: `shape = "torus"`, `major = R`, `minor = r`; place it with
//! the object's `transform` list.
//!
//! **The surface** is the whole zero set of the quartic
//! `f(p) = (|p|² + R² − r²)² − 4R²(x² + z²)`, as in POV-Ray. For a spindle
//! torus (`R < r`) that is the outer "apple" and the inner "lemon" where the
//! tube overlaps itself; the solid (what glass fills) is `f < 0`, the apple
//! less the lemon, and normals point along `∇f`, out of that solid: into
//! the lemon on its surface. Every crossing of the surface therefore enters
//! or leaves the solid, as the medium stack expects. `R = 0` is the sphere
//! of radius `r` (the quartic is then a square, its roots double, so it is
//! traced as a sphere); a major radius below [`Torus::MIN_RATIO`] times the
//! minor one, or a minor one below it times the major, is refused: the
//! shell or the tube would be thinner than the quartic resolves.
//!
//! **Intersection.** The ray is carried into units of the bounding sphere
//! (radius `R + r`) with a unit direction, and its origin moved to the
//! point of its line nearest the centre before the quartic is formed: the
//! coefficients grow like the fourth power of the origin's distance, and
//! this keeps them of order one for a camera at any distance (POV-Ray moves
//! the origin to the bounding sphere's entry for the same reason). A ray
//! whose line misses the bounding sphere is refused before any quartic.
//! The roots are found only on the chord inside the sphere, by Ferrari's
//! closed form ([`ferrari`]: the resolvent cubic by Cardano, two
//! quadratics) with two Newton steps per root, and checked: every root
//! finite, barely moved by the Newton steps, with a residual near rounding,
//! and as many roots on the chord (odd or even) as the quartic's signs at
//! its ends demand. When the check fails the quartic goes to recursive
//! derivative intervals (Yuksel 2022, [`monotone`]): the critical points
//! (the roots of the cubic derivative, found the same way from the
//! quadratic second derivative) cut the chord into monotone pieces, each
//! holding at most one root, found by Newton's method kept inside its
//! bracket, which cannot miss a simple root or return one outside the
//! chord. The checked closed form is as accurate as the monotone solver
//! alone and faster per ray (measured: docs/performance-log.md, "Torus
//! solvers"); the monotone solver alone was shipped first, and is kept as
//! the fallback and as the tests' second opinion. Sturm sequences (as
//! POV-Ray) were not implemented.
//!
//! **(u, v)** are the natural angles: `u = φ / 2π` around the y axis and
//! `v = θ / 2π` around the tube, with
//! `p = ((R + r cos θ) cos φ, r sin θ, −(R + r cos θ) sin φ)`; `v = 0` on
//! the outer equator, `0.25` on top, `0.5` on the inner equator. A point
//! of a spindle torus's lemon has `R + r cos θ < 0`. `dpdu` and `dpdv` are
//! the derivatives of that form, and `dpdu × dpdv` points along the normal.

mod ferrari;
mod monotone;
#[cfg(test)]
mod tests;

use std::f64::consts::TAU;

use super::{LocalSurface, ShapeError, ShapeHit, non_negative, positive, quadratic};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma, magnitude};

/// A torus around the y axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Torus {
    major: f64,
    minor: f64,
    /// `major + minor`: the bounding sphere's radius, the unit of the
    /// quartic.
    size: f64,
    /// `major / size`.
    unit_major: f64,
    /// `minor / size`.
    unit_minor: f64,
}

impl Torus {
    /// The smallest ratio of the major to the minor radius (when the major
    /// one is not zero) and of the minor to the major radius.
    pub const MIN_RATIO: f64 = 1e-4;

    /// The torus of tube radius `minor` around the circle of radius `major`
    /// in the xz-plane; `minor` must be positive, `major` zero or positive.
    pub fn new(major: f64, minor: f64) -> Result<Self, ShapeError> {
        let major = non_negative("major", major)?;
        let minor = positive("minor", minor)?;
        let size = major + minor;
        magnitude::length(size).map_err(|error| ShapeError::OutOfRange {
            what: "major",
            error,
        })?;
        if major > 0.0 && major < Self::MIN_RATIO * minor {
            return Err(ShapeError::Degenerate {
                shape: "torus",
                why: "`major` is non-zero but below 1e-4 times `minor`: the shell between the \
                      lemon and the apple is too thin to trace (use 0 for a sphere)",
            });
        }
        if minor < Self::MIN_RATIO * major {
            return Err(ShapeError::Degenerate {
                shape: "torus",
                why: "`minor` is below 1e-4 times `major`: the tube is too thin to trace",
            });
        }
        Ok(Self {
            major,
            minor,
            size,
            unit_major: major / size,
            unit_minor: minor / size,
        })
    }

    /// The radius of the circle at the middle of the tube.
    pub fn major(&self) -> f64 {
        self.major
    }

    /// The radius of the tube.
    pub fn minor(&self) -> f64 {
        self.minor
    }

    /// The closest hit in the ray's interval.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        self.intersect_by::<ferrari::Ferrari>(ray)
    }

    /// The closest hit found by recursive derivative intervals alone
    /// instead of [`Torus::intersect`]'s checked closed form, on the same
    /// moved-origin quartic: for measurement and as the tests' second
    /// opinion (the solver comparison in docs/performance-log.md), not used
    /// when rendering.
    #[doc(hidden)]
    pub fn intersect_by_monotone(&self, ray: &Ray) -> Option<ShapeHit> {
        self.intersect_by::<monotone::Monotone>(ray)
    }

    /// The closest hit, with the quartic's roots found by `S`.
    fn intersect_by<S: QuarticSolver>(&self, ray: &Ray) -> Option<ShapeHit> {
        let length = magnitude::norm(ray.dir);
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let dir = ray.dir / length;
        // Along the unit direction, in units of `size`, from the point of
        // the line nearest the centre: `t = (nearest + s) · size / length`.
        let origin = ray.origin / self.size;
        let nearest = -origin.dot(dir);
        let middle = origin + nearest * dir;
        let off_axis = middle.length_squared();
        // A NaN (from an infinite origin) is refused as well.
        if off_axis.is_nan() || off_axis > 1.0 + 1e-12 {
            return None;
        }
        let to_t = |s: f64| (nearest + s) * (self.size / length);
        let to_s = |t: f64| t * (length / self.size) - nearest;
        let half_chord = (1.0 + 1e-12 - off_axis).sqrt();
        let lo = to_s(ray.t_min).max(-half_chord);
        let hi = to_s(ray.t_max).min(half_chord);
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return None;
        }
        let accept = |s: f64| ray.contains(to_t(s));
        let s = if self.major == 0.0 {
            sphere_root(middle, dir, lo, hi, accept)
        } else {
            let c = self.quartic(middle, dir);
            S::first_root(&c, lo, hi, accept)
        }?;
        Some(ShapeHit::at(to_t(s)))
    }

    /// The coefficients of `f(o + s d)` (lowest degree first), for a unit
    /// `d` and a point `o` in units of the bounding sphere.
    fn quartic(&self, o: Vec3, d: Vec3) -> [f64; 5] {
        let (big, small) = (self.unit_major, self.unit_minor);
        let four_big2 = 4.0 * big * big;
        let b = o.dot(d);
        let k = o.length_squared() + (big - small) * (big + small);
        [
            k * k - four_big2 * (o.x * o.x + o.z * o.z),
            4.0 * b * k - 2.0 * four_big2 * (o.x * d.x + o.z * d.z),
            4.0 * b * b + 2.0 * k - four_big2 * (d.x * d.x + d.z * d.z),
            4.0 * b,
            1.0,
        ]
    }

    /// True when the ray meets the torus in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let p = ray.at(hit.t);
        let rho = p.x.hypot(p.z);
        // The azimuth of the point; on the axis, any.
        let (cos_az, sin_az) = if rho > 0.0 {
            (p.x / rho, -p.z / rho)
        } else {
            (1.0, 0.0)
        };
        // The point on the near side of the tube's circle (the apple) or on
        // the far side (a spindle torus's lemon), whichever is closer.
        let near = (rho - self.major).hypot(p.y);
        let far = (rho + self.major).hypot(p.y);
        let lemon = (far - self.minor).abs() < (near - self.minor).abs();
        let (phi_cos, phi_sin, across) = if lemon {
            (-cos_az, -sin_az, -rho - self.major)
        } else {
            (cos_az, sin_az, rho - self.major)
        };
        let tube = across.hypot(p.y);
        let (cos_theta, sin_theta) = if tube > 0.0 {
            (across / tube, p.y / tube)
        } else {
            (1.0, 0.0)
        };
        let ring = self.major + self.minor * cos_theta;
        let tube_normal = Vec3::new(cos_theta * phi_cos, sin_theta, -cos_theta * phi_sin);
        let point = Vec3::new(ring * phi_cos, self.minor * sin_theta, -ring * phi_sin);
        let normal = if ring < 0.0 {
            -tube_normal
        } else {
            tube_normal
        };
        let point_error = Vec3::splat(gamma(16) * self.size * (self.size / self.minor));
        LocalSurface {
            point,
            point_error,
            normal,
            uv: DVec2::new(
                angle(phi_sin, phi_cos) / TAU,
                angle(sin_theta, cos_theta) / TAU,
            ),
            dpdu: TAU * ring * Vec3::new(-phi_sin, 0.0, -phi_cos),
            dpdv: TAU
                * self.minor
                * Vec3::new(-sin_theta * phi_cos, cos_theta, sin_theta * phi_sin),
        }
    }

    /// The bounding box.
    pub fn bounds(&self) -> Aabb {
        let extent = Vec3::new(self.size, self.minor, self.size);
        Aabb::new(-extent, extent)
    }
}

/// A way to find the roots of the torus's quartic.
trait QuarticSolver {
    /// The first root of the quartic `c` (lowest degree first) in
    /// `(lo, hi)` that `accept` takes, trying the roots in increasing order.
    fn first_root(c: &[f64; 5], lo: f64, hi: f64, accept: impl FnMut(f64) -> bool) -> Option<f64>;
}

/// The angle of `(cos, sin)` in `[0, 2π)`.
fn angle(sin: f64, cos: f64) -> f64 {
    let a = sin.atan2(cos);
    if a < 0.0 { a + TAU } else { a }
}

/// The first root that `accept` takes, in `(lo, hi)`, of the unit sphere
/// (the torus with `major = 0`) along `o + s d`, `d` unit.
fn sphere_root(
    o: Vec3,
    d: Vec3,
    lo: f64,
    hi: f64,
    mut accept: impl FnMut(f64) -> bool,
) -> Option<f64> {
    let b = o.dot(d);
    let disc = 1.0 - o.cross(d).length_squared();
    let (s0, s1) = quadratic::solve(1.0, b, o.length_squared() - 1.0, disc)?;
    [s0, s1]
        .into_iter()
        .find(|&s| s > lo && s < hi && accept(s))
}
