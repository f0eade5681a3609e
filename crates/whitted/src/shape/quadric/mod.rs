//! A quadric surface `A x² + B y² + C z² + D xy + E xz + F yz + G x + H y +
//! I z + J = 0` (POV-Ray's convention), optionally clipped to a box.
//!
//! Scene syntax: `shape = "quadric"`, the coefficients `a` … `j` (each
//! defaulting to 0), and `bounds = [[x0, y0, z0], [x1, y1, z1]]`.
//!
//! **Inside and normals.** The inside is where the polynomial is negative;
//! the normal is its gradient `(2Ax + Dy + Ez + G, 2By + Dx + Fz + H,
//! 2Cz + Ex + Fy + I)`, normalised, so it points outward. Where the
//! gradient vanishes on the surface (a cone's apex) the normal faces back
//! along the ray.
//!
//! **Bounds.** The surface is bounded exactly when the quadratic part is
//! definite: with `M` the symmetric matrix of the quadratic part (`A`, `B`,
//! `C` on the diagonal, `D/2`, `E/2`, `F/2` off it), when the leading
//! principal minors of `M` or of `-M` are all positive (Sylvester's
//! criterion). The surface is then the ellipsoid `(p - c)ᵀ M (p - c) = -k`
//! around `c = -M⁻¹ (G, H, I) / 2`, with `k = J + (G, H, I)·c / 2`, whose
//! half-width along axis i is `√(-k (M⁻¹)ᵢᵢ)`; when `-k` does not have the
//! sign of `M` it is empty or a single point, and refused. (With `M`
//! negative definite the inside is everything outside the ellipsoid: a
//! bubble.) Every other quadric (cylinders, cones, paraboloids,
//! hyperboloids, planes, pairs of planes) reaches infinity and needs
//! `bounds`.
//!
//! **Clipping.** With `bounds`, the shape is the part of the quadric inside
//! the box (faces included); the box itself is not a surface, so a clipped
//! quadric is open where the box cuts it (like POV-Ray's `clipped_by`). A
//! root whose point lies outside the box is skipped, so a ray may hit the
//! second root. A bounded quadric may have bounds too.
//!
//! **Texture coordinates** are the sphere's spherical angles about the
//! centre `c` of the shape's box ([`Quadric::bounds`]; an ellipsoid's own
//! centre when it has no `bounds`): `u = φ / 2π` with `φ = atan2(y, x)` of
//! `p - c` in [0, 2π), `v = 1 - θ / π` from 0 at the bottom to 1 at the top.
//! They are continuous away from the seam `φ = 0` and the poles. The
//! tangents are the derivatives of the point along u and v, moving on the
//! surface along the line from `c`: the sphere's tangents `T` for the
//! radius `|p - c|`, slid along `p - c` into the tangent plane,
//! `T - (p - c) (n·T) / (n·(p - c))`. Both are perpendicular to the normal;
//! where the line from `c` grazes the surface (`n·(p - c)` within 1e-9 of
//! `|p - c|`), where the derivative is infinite, `T` is projected
//! perpendicularly onto the tangent plane instead. For `A = B = C = 1`,
//! `J = -r²` this is exactly [`super::Sphere`]'s parametrisation.
//!
//! **Solving.** The ray is taken to unit direction and its origin moved to
//! the point nearest the centre `c` before the polynomial along it is
//! formed, so distant rays lose no precision; the quadratic is solved by
//! [`super::quadratic::solve`], and as a linear equation when its leading
//! coefficient is exactly zero (a ray along a paraboloid's axis, or any ray
//! for a plane).

mod form;

use std::f64::consts::{PI, TAU};

use self::form::{Extent, Form};
use super::{LocalSurface, ShapeError, ShapeHit, quadratic};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma, magnitude};

/// A quadric surface, optionally clipped to a box. Its data is boxed to keep
/// [`super::Shape`] small.
#[derive(Clone, Debug, PartialEq)]
pub struct Quadric {
    data: Box<Data>,
}

/// What a [`Quadric`] keeps.
#[derive(Clone, Debug, PartialEq)]
struct Data {
    form: Form,
    /// The clipping box given, if any.
    clip: Option<Aabb>,
    /// The object-space bounds: the clipping box, narrowed to the
    /// ellipsoid's box when the quadric is bounded.
    bounds: Aabb,
    /// The centre of `bounds`: where rays are re-based for solving, and the
    /// centre of the texture coordinates.
    center: Vec3,
}

impl Quadric {
    /// The names of the coefficients in scene files and messages, in order.
    pub const COEFFICIENTS: [&str; 10] = ["a", "b", "c", "d", "e", "f", "g", "h", "i", "j"];

    /// The quadric with `coefficients` `[A, B, C, D, E, F, G, H, I, J]`,
    /// clipped to `clip` when given.
    ///
    /// Refused: a coefficient that is not finite or out of
    /// [`magnitude::length`]'s range (zero, or 1e-30 to 1e30 in magnitude);
    /// all of `A` … `I` zero (the polynomial is a constant); a clipping box
    /// out of range or not wider than zero on every axis; an unbounded
    /// quadric without a clipping box; an empty (or one-point) ellipsoid;
    /// a clipping box that misses the ellipsoid.
    pub fn new(coefficients: [f64; 10], clip: Option<Aabb>) -> Result<Self, ShapeError> {
        for (what, value) in Self::COEFFICIENTS.into_iter().zip(coefficients) {
            if !value.is_finite() {
                return Err(ShapeError::NotFinite { what });
            }
            magnitude::length(value).map_err(|error| ShapeError::OutOfRange { what, error })?;
        }
        if coefficients[..9].iter().all(|&c| c == 0.0) {
            return Err(ShapeError::Degenerate {
                shape: "quadric",
                why: "all of a to i are zero: the polynomial is a constant",
            });
        }
        if let Some(clip) = clip {
            super::finite("bounds", clip.min)?;
            super::finite("bounds", clip.max)?;
            if !clip.min.cmplt(clip.max).all() {
                return Err(ShapeError::Degenerate {
                    shape: "quadric",
                    why: "the bounds' first corner must be below the second on every axis",
                });
            }
        }
        let form = Form { coefficients };
        let bounds = match (form.extent(), clip) {
            (Extent::Empty, _) => {
                return Err(ShapeError::Degenerate {
                    shape: "quadric",
                    why: "it is an ellipsoid with no real points (or a single one)",
                });
            }
            (Extent::Unbounded, None) => {
                return Err(ShapeError::Degenerate {
                    shape: "quadric",
                    why: "it is unbounded (not an ellipsoid): give `bounds` to clip it",
                });
            }
            (Extent::Unbounded, Some(clip)) => clip,
            (Extent::Ellipsoid(own), None) => own,
            (Extent::Ellipsoid(own), Some(clip)) => {
                own.intersection(&clip).ok_or(ShapeError::Degenerate {
                    shape: "quadric",
                    why: "the bounds do not meet the ellipsoid",
                })?
            }
        };
        Ok(Self {
            data: Box::new(Data {
                form,
                clip,
                bounds,
                center: bounds.centroid(),
            }),
        })
    }

    /// The coefficients `[A, B, C, D, E, F, G, H, I, J]`.
    pub fn coefficients(&self) -> [f64; 10] {
        self.data.form.coefficients
    }

    /// The clipping box, if one was given.
    pub fn clip(&self) -> Option<Aabb> {
        self.data.clip
    }

    /// True when `p` lies in the clipping box (always without one).
    fn kept(&self, p: Vec3) -> bool {
        self.data
            .clip
            .is_none_or(|b| p.cmpge(b.min).all() && p.cmple(b.max).all())
    }

    /// Both roots along the ray (equal for a linear equation), in the
    /// ray's parameter, smallest first; `None` when the line misses.
    fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let length = ray.dir.length();
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let dir = ray.dir / length;
        let shift = (self.data.center - ray.origin).dot(dir);
        let origin = ray.origin + shift * dir;
        let line = self.data.form.along(origin, dir);
        let (s0, s1) = if line.a == 0.0 {
            if line.b == 0.0 {
                return None;
            }
            let s = -line.c / (2.0 * line.b);
            (s, s)
        } else {
            let disc = line.b * line.b - line.a * line.c;
            quadratic::solve(line.a, line.b, line.c, disc)?
        };
        let to_t = |s: f64| (s + shift) / length;
        Some((to_t(s0), to_t(s1)))
    }

    /// The closest hit in the ray's interval whose point lies in the
    /// clipping box.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (t0, t1) = self.roots(ray)?;
        [t0, t1]
            .into_iter()
            .filter(|&t| t.is_finite() && ray.contains(t))
            .find(|&t| self.kept(ray.at(t)))
            .map(ShapeHit::at)
    }

    /// True when the ray meets the quadric in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.intersect(ray).is_some()
    }

    /// The surface at a hit: the point moved onto the surface by one Newton
    /// step along the gradient (and kept in the clipping box), the unit
    /// gradient as the normal, and the spherical (u, v) about the centre.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let mut surface = self.surface_geometry(ray, hit);
        let local = surface.point - self.data.center;
        (surface.uv, surface.dpdu, surface.dpdv) = spherical(local, surface.normal);
        surface
    }

    /// The surface at a hit without its parametric part: (u, v) and the
    /// tangents are left zero (see [`crate::shape::Shape::surface_geometry`]).
    pub fn surface_geometry(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let form = &self.data.form;
        let hit_point = ray.at(hit.t);
        let gradient = form.gradient(hit_point);
        let squared = gradient.length_squared();
        let mut point = hit_point;
        if squared > 0.0 && squared.is_finite() {
            let step = form.value(hit_point) / squared * gradient;
            if step.is_finite() {
                point -= step;
            }
        }
        if let Some(clip) = self.data.clip {
            point = point.clamp(clip.min, clip.max);
        }
        let normal = crate::math::unit(form.gradient(point))
            .or_else(|| crate::math::unit(-ray.dir))
            .unwrap_or(Vec3::Z);
        let point_error = gamma(8) * point.abs() + Vec3::splat(self.surface_error(point));
        LocalSurface {
            point,
            point_error,
            normal,
            uv: DVec2::ZERO,
            dpdu: Vec3::ZERO,
            dpdv: Vec3::ZERO,
        }
    }

    /// How far the computed surface may lie from `point` along the normal:
    /// four times the polynomial's rounding error there over its gradient
    /// (once for placing the point, once for the next ray's root, with a
    /// margin for re-basing that ray on the centre); the box's diagonal
    /// where the gradient vanishes.
    fn surface_error(&self, point: Vec3) -> f64 {
        let form = &self.data.form;
        let slope = form.gradient(point).length();
        let error = 4.0 * form.value_error(point) / slope;
        let size = self.data.bounds.extent().length();
        if error.is_finite() {
            error.min(size)
        } else {
            size
        }
    }

    /// The bounding box: the clipping box, or the ellipsoid's (the two
    /// intersected when both exist).
    pub fn bounds(&self) -> Aabb {
        self.data.bounds
    }
}

/// `|n·(p - c)|` below this fraction of `|p - c|`: the line from the
/// centre grazes the surface, and the tangents are projected instead.
const GRAZING: f64 = 1e-3;

/// The spherical (u, v) of `local` (the point less the centre) and the
/// tangents along them on the surface with unit `normal`, as the module
/// documentation says.
fn spherical(local: Vec3, normal: Vec3) -> (DVec2, Vec3, Vec3) {
    let radius = local.length();
    let rho = local.x.hypot(local.y);
    let mut phi = local.y.atan2(local.x);
    if phi < 0.0 {
        phi += TAU;
    }
    let theta = if radius > 0.0 {
        (local.z / radius).clamp(-1.0, 1.0).acos()
    } else {
        PI / 2.0
    };
    let (sin_phi, cos_phi) = if rho > 0.0 {
        (local.y / rho, local.x / rho)
    } else {
        (0.0, 1.0)
    };
    let along_u = Vec3::new(-TAU * local.y, TAU * local.x, 0.0);
    let along_v = PI * Vec3::new(-local.z * cos_phi, -local.z * sin_phi, rho);
    let facing = normal.dot(local);
    let onto_surface = |t: Vec3| {
        if facing.abs() > GRAZING * radius {
            t - local * (normal.dot(t) / facing)
        } else {
            t - normal * normal.dot(t)
        }
    };
    (
        DVec2::new(phi / TAU, 1.0 - theta / PI),
        onto_surface(along_u),
        onto_surface(along_v),
    )
}

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
