//! Area lights: a rectangle, disk or sphere that glows with a uniform
//! radiance, giving soft shadows.
//!
//! Radiance `L` is per unit area and solid angle, so the irradiance an area
//! light gives a point is `E = ∫ L cos θ cos θₗ / d² dA` over the part of
//! the light the point sees: physical inverse-square fall-off, no
//! attenuation coefficients. A rectangle or disk emits from its front side
//! only (the side its normal points to), a sphere all round (outwards).
//! Its flux is `π L A`, `A` the emitting area.
//!
//! Direct light is estimated by `samples` stratified points of the light
//! ([`AreaLight::sample`]): a rectangle or disk is sampled uniformly over its
//! area, a sphere uniformly over the cone of directions in which the point
//! sees it (points on its visible cap, no sample wasted on the far side).
//! Each sample carries `1 / samples` of the estimate, as the
//! [`LightSample::intensity`] that multiplies `N·L` in the Phong model, so a
//! sample is used exactly as a point light's is.
//!
//! The light is seen by the camera through a glowing shape the scene places
//! in the world ([`AreaLight::glowing_shape`]), which also stops the light
//! of other lights. A shadow ray towards a sampled point therefore ends
//! just short of it ([`SHADOW_GAP`]), so that it is not stopped by the
//! light's own surface.

use std::f64::consts::{PI, TAU};

use crate::math::sampling::{about_axis, cosine_hemisphere, uniform_disk, uniform_sphere};
use crate::math::{Transform, Vec3};
use crate::shading::{Color, EmittedRay, LightSample};
use crate::shape::{Disk, Parallelogram, Shape, ShapeError, Sphere};

/// How far short of a sampled point of an area light its shadow ray ends,
/// relative to the distance (and to the point's coordinates, for rounding
/// far from the origin): far above the rounding of the sampled point, far
/// below any gap between surfaces a scene means.
pub const SHADOW_GAP: f64 = 1e-9;

/// The shape of an area light, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Emitter {
    /// A parallelogram (a rectangle when its edges are perpendicular),
    /// emitting towards `edge_u × edge_v`.
    Rect {
        /// One corner.
        corner: Vec3,
        /// The first edge from the corner.
        edge_u: Vec3,
        /// The second edge from the corner.
        edge_v: Vec3,
    },
    /// A disk emitting towards its unit `normal`.
    Disk {
        /// Its centre.
        center: Vec3,
        /// The unit normal of its emitting side.
        normal: Vec3,
        /// Its radius.
        radius: f64,
    },
    /// A sphere emitting outwards all round.
    Sphere {
        /// Its centre.
        center: Vec3,
        /// Its radius.
        radius: f64,
    },
}

impl Emitter {
    /// The area that emits.
    pub fn area(&self) -> f64 {
        match self {
            Emitter::Rect { edge_u, edge_v, .. } => edge_u.cross(*edge_v).length(),
            Emitter::Disk { radius, .. } => PI * radius * radius,
            Emitter::Sphere { radius, .. } => 4.0 * PI * radius * radius,
        }
    }

    /// A point of the surface and its unit outward (emitting) normal, both
    /// uniform over the area for `u` uniform in `[0, 1)²`.
    pub fn point(&self, u: [f64; 2]) -> (Vec3, Vec3) {
        match self {
            Emitter::Rect {
                corner,
                edge_u,
                edge_v,
            } => (
                *corner + u[0] * *edge_u + u[1] * *edge_v,
                edge_u.cross(*edge_v).normalize(),
            ),
            Emitter::Disk {
                center,
                normal,
                radius,
            } => {
                let (x, y) = normal.any_orthonormal_pair();
                let d = uniform_disk(u) * *radius;
                (*center + d.x * x + d.y * y, *normal)
            }
            Emitter::Sphere { center, radius } => {
                let n = uniform_sphere(u);
                (*center + *radius * n, n)
            }
        }
    }
}

/// A light with a size: a shape glowing with a uniform radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    /// Where it is and which side emits.
    pub emitter: Emitter,
    /// Radiance `L` of its emitting side, per channel.
    pub radiance: Color,
    /// Shadow rays per shaded point (at least 1).
    pub samples: u32,
}

impl AreaLight {
    /// The radiance that makes a light of shape `emitter` send out `power`
    /// (flux): `Φ / (π A)`.
    pub fn radiance_for_power(emitter: &Emitter, power: Color) -> Color {
        power * (1.0 / (PI * emitter.area()))
    }

    /// Its flux: `π L A` (a Lambertian emitter).
    pub fn power(&self) -> Color {
        self.radiance * (PI * self.emitter.area())
    }

    /// The colour its glowing shape shows the camera: `π L`, its radiant
    /// exitance. Whitted's diffuse surfaces show `kd E` for an irradiance
    /// `E` (for every kind of light), so a white surface lit by the light
    /// from its whole sky shows `π L`, as bright as the light itself.
    pub fn glow(&self) -> Color {
        self.radiance * PI
    }

    /// Sample `index` of `count` of the light arriving at `p`, from the
    /// point of the light chosen by `u` (in `[0, 1)²`), carrying `1 /
    /// count` of the estimate of the irradiance; `None` when that point
    /// sends nothing to `p` (its back, or `p` inside a sphere light).
    pub fn sample(&self, p: Vec3, u: [f64; 2], count: u32) -> Option<LightSample> {
        let share = 1.0 / f64::from(count.max(1));
        match &self.emitter {
            Emitter::Sphere { center, radius } => {
                let axis = *center - p;
                let d2 = axis.length_squared();
                let sin2_max = radius * radius / d2;
                if !(sin2_max < 1.0) {
                    return None;
                }
                let d_c = d2.sqrt();
                let axis = axis / d_c;
                // Uniform over the cone of directions that meet the sphere.
                let cos_max = (1.0 - sin2_max).sqrt();
                let cos_theta = 1.0 - u[0] * (1.0 - cos_max);
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let phi = TAU * u[1];
                let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
                let to_light = about_axis(local, axis);
                // The nearer crossing of that direction with the sphere.
                let half_chord = (radius * radius - d2 * sin_theta * sin_theta)
                    .max(0.0)
                    .sqrt();
                let distance = d_c * cos_theta - half_chord;
                let solid_angle = TAU * (1.0 - cos_max);
                Some(LightSample {
                    to_light,
                    distance: shadow_distance(distance, p),
                    intensity: self.radiance * (solid_angle * share),
                })
            }
            flat => {
                let (point, normal) = flat.point(u);
                let delta = point - p;
                let d2 = delta.length_squared();
                let distance = d2.sqrt();
                if !(distance > 0.0 && distance.is_finite()) {
                    return None;
                }
                let to_light = delta / distance;
                let cos_light = -normal.dot(to_light);
                if cos_light <= 0.0 {
                    return None;
                }
                let weight = cos_light * flat.area() / d2 * share;
                Some(LightSample {
                    to_light,
                    distance: shadow_distance(distance, p),
                    intensity: self.radiance * weight,
                })
            }
        }
    }

    /// One ray (photon) the light sends out, chosen by `u`: a uniform point
    /// of its surface (`u[0]`, `u[1]`) and a cosine-weighted direction
    /// about its normal there (`u[2]`, `u[3]`), carrying its whole
    /// [`AreaLight::power`]. The origin is lifted off the surface by
    /// [`SHADOW_GAP`] of the light's size, so the photon does not meet the
    /// light's own glowing shape.
    pub fn emit(&self, u: [f64; 4]) -> EmittedRay {
        let (point, normal) = self.emitter.point([u[0], u[1]]);
        let direction = about_axis(cosine_hemisphere([u[2], u[3]]), normal);
        let lift = SHADOW_GAP * (self.emitter.area().sqrt() + point.abs().max_element());
        EmittedRay {
            origin: point + lift * normal,
            direction,
            power: self.power(),
        }
    }

    /// The shape the camera sees glowing, placed in world space: a
    /// parallelogram, a disk or a sphere (one [`Shape`] with its
    /// transform), or why the light has no such shape.
    pub fn glowing_shape(&self) -> Result<(Shape, Transform), ShapeError> {
        match self.emitter {
            Emitter::Rect {
                corner,
                edge_u,
                edge_v,
            } => Ok((
                Shape::Parallelogram(Parallelogram::new(corner, edge_u, edge_v)?),
                Transform::IDENTITY,
            )),
            Emitter::Disk {
                center,
                normal,
                radius,
            } => {
                let place = Transform::frame(center, normal)
                    .map_err(|_| ShapeError::NotFinite { what: "disk light" })?;
                Ok((Shape::Disk(Disk::new(radius, 0.0)?), place))
            }
            Emitter::Sphere { center, radius } => Ok((
                Shape::Sphere(Sphere::new(center, radius)?),
                Transform::IDENTITY,
            )),
        }
    }
}

/// The length of a shadow ray from `p` towards a point of a light at
/// `distance`: just short of it (see [`SHADOW_GAP`]).
fn shadow_distance(distance: f64, p: Vec3) -> f64 {
    distance - SHADOW_GAP * (distance + p.abs().max_element())
}
