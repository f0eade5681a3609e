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
                if sin2_max.is_nan() || sin2_max >= 1.0 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Aabb;
    use crate::math::random::Rng;
    use crate::shading::{Light, direct_samples};

    /// The irradiance at `p` facing `n` that [`direct_samples`] estimates
    /// from `light` with `samples` shadow rays, unoccluded.
    fn irradiance(light: &AreaLight, samples: u32, p: Vec3, n: Vec3) -> f64 {
        let light = Light::Area(AreaLight {
            samples,
            ..light.clone()
        });
        direct_samples(std::slice::from_ref(&light), p)
            .map(|(_, _, s)| s.intensity.r * n.dot(s.to_light).max(0.0))
            .sum()
    }

    fn disk(radius: f64, height: f64) -> AreaLight {
        AreaLight {
            emitter: Emitter::Disk {
                center: Vec3::new(0.0, height, 0.0),
                normal: -Vec3::Y,
                radius,
            },
            radiance: Color::splat(2.0),
            samples: 1,
        }
    }

    fn close(estimate: f64, exact: f64, tolerance: f64) -> bool {
        ((estimate - exact) / exact).abs() < tolerance
    }

    #[test]
    fn a_disk_light_gives_pi_l_sin_squared_of_its_angular_radius() {
        for (radius, height) in [(1.0, 2.0), (0.3, 5.0), (3.0, 1.0)] {
            let light = disk(radius, height);
            let sin2 = radius * radius / (radius * radius + height * height);
            let exact = PI * 2.0 * sin2;
            let coarse = irradiance(&light, 16, Vec3::ZERO, Vec3::Y);
            let fine = irradiance(&light, 4096, Vec3::ZERO, Vec3::Y);
            assert!(close(fine, exact, 0.005), "{fine} vs {exact}");
            assert!((fine - exact).abs() <= (coarse - exact).abs() + 1e-3 * exact);
        }
    }

    #[test]
    fn a_sphere_light_gives_pi_l_sin_squared_of_its_angular_radius() {
        let light = AreaLight {
            emitter: Emitter::Sphere {
                center: Vec3::new(0.5, 3.0, -0.2),
                radius: 0.8,
            },
            radiance: Color::splat(1.5),
            samples: 1,
        };
        let p = Vec3::new(0.5, 0.0, -0.2);
        let exact = PI * 1.5 * 0.8f64.powi(2) / 9.0;
        let fine = irradiance(&light, 4096, p, Vec3::Y);
        assert!(close(fine, exact, 0.005), "{fine} vs {exact}");
        // Inside the sphere it lights nothing.
        assert_eq!(
            irradiance(&light, 16, Vec3::new(0.5, 3.0, 0.0), Vec3::Y),
            0.0
        );
    }

    /// The form factor from a point to a parallel `a × b` rectangle at
    /// distance `c` with one corner straight above the point.
    fn corner_form_factor(a: f64, b: f64, c: f64) -> f64 {
        let (x, y) = (a / c, b / c);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
    }

    #[test]
    fn a_square_light_over_a_plane_gives_the_analytic_form_factor() {
        let light = AreaLight {
            emitter: Emitter::Rect {
                corner: Vec3::new(0.0, 1.5, 0.0),
                edge_u: Vec3::new(0.0, 0.0, 2.0),
                edge_v: Vec3::new(2.0, 0.0, 0.0),
            },
            radiance: Color::splat(3.0),
            samples: 1,
        };
        // Wrong way round: the front faces up, away from the floor.
        assert_eq!(irradiance(&light, 64, Vec3::ZERO, Vec3::Y), 0.0);
        let light = AreaLight {
            emitter: Emitter::Rect {
                corner: Vec3::new(0.0, 1.5, 0.0),
                edge_u: Vec3::new(2.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, 2.0),
            },
            ..light
        };
        // Under a corner, and under a point that splits it into four.
        let under_corner = PI * 3.0 * corner_form_factor(2.0, 2.0, 1.5);
        let inside = PI
            * 3.0
            * (corner_form_factor(0.5, 0.7, 1.5)
                + corner_form_factor(1.5, 0.7, 1.5)
                + corner_form_factor(0.5, 1.3, 1.5)
                + corner_form_factor(1.5, 1.3, 1.5));
        for (p, exact) in [
            (Vec3::ZERO, under_corner),
            (Vec3::new(0.5, 0.0, 0.7), inside),
        ] {
            let fine = irradiance(&light, 4096, p, Vec3::Y);
            assert!(close(fine, exact, 0.005), "{fine} vs {exact} at {p}");
        }
    }

    #[test]
    fn power_is_pi_radiance_area_and_a_given_power_is_kept() {
        let emitter = Emitter::Disk {
            center: Vec3::ZERO,
            normal: Vec3::Z,
            radius: 0.5,
        };
        let radiance = AreaLight::radiance_for_power(&emitter, Color::new(1.0, 2.0, 3.0));
        let light = AreaLight {
            emitter,
            radiance,
            samples: 4,
        };
        let power = Light::Area(light).power(&Aabb::EMPTY);
        assert!((power - Color::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-12);
    }

    #[test]
    fn photons_from_a_disk_light_reach_a_facing_disk_by_their_form_factor() {
        // Coaxial parallel disks of radii r1 (the light) and r2 at h.
        let (r1, r2, h) = (0.5, 1.0, 1.2);
        let light = Light::Area(AreaLight {
            emitter: Emitter::Disk {
                center: Vec3::ZERO,
                normal: Vec3::Z,
                radius: r1,
            },
            radiance: Color::splat(0.7),
            samples: 1,
        });
        let power = light.power(&Aabb::EMPTY).r;
        assert!((power - 0.7 * PI * PI * r1 * r1).abs() < 1e-12);
        let (a, b) = (r1 / h, r2 / h);
        let x = 1.0 + (1.0 + b * b) / (a * a);
        let form_factor = 0.5 * (x - (x * x - 4.0 * (b / a).powi(2)).sqrt());
        let mut rng = Rng::new(7);
        let n = 200_000;
        let mut arrived = 0.0;
        for _ in 0..n {
            let u = [rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()];
            let ray = light.emit(u, &Aabb::EMPTY).unwrap();
            assert_eq!(ray.power.r, power);
            assert!(ray.direction.z > 0.0 && ray.origin.z > 0.0);
            let t = (h - ray.origin.z) / ray.direction.z;
            let hit = ray.origin + t * ray.direction;
            if hit.x * hit.x + hit.y * hit.y < r2 * r2 {
                arrived += ray.power.r / f64::from(n);
            }
        }
        let exact = power * form_factor;
        assert!(close(arrived, exact, 0.01), "{arrived} vs {exact}");
    }

    #[test]
    fn photons_leave_a_sphere_light_outwards_from_just_outside_it() {
        let light = Light::Area(AreaLight {
            emitter: Emitter::Sphere {
                center: Vec3::new(1.0, 2.0, 3.0),
                radius: 0.5,
            },
            radiance: Color::ONE,
            samples: 1,
        });
        let mut rng = Rng::new(3);
        for _ in 0..1000 {
            let u = [rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()];
            let ray = light.emit(u, &Aabb::EMPTY).unwrap();
            let out = ray.origin - Vec3::new(1.0, 2.0, 3.0);
            assert!(out.length() > 0.5 && out.length() < 0.5 + 1e-6);
            assert!(out.dot(ray.direction) > 0.0);
            assert_eq!(ray.power.r, 4.0 * PI * PI * 0.25);
        }
    }

    #[test]
    fn shadow_rays_end_just_short_of_the_sampled_point() {
        let light = disk(1.0, 2.0);
        let s = light.sample(Vec3::ZERO, [0.0, 0.0], 1).unwrap();
        assert!(s.distance < 2.0 && s.distance > 2.0 - 1e-6);
    }

    #[test]
    fn the_sample_pattern_depends_on_the_point_alone() {
        let light = [Light::Area(AreaLight {
            samples: 9,
            ..disk(1.0, 2.0)
        })];
        let p = Vec3::new(0.1, 0.0, 0.2);
        let once: Vec<_> = direct_samples(&light, p).collect();
        let again: Vec<_> = direct_samples(&light, p).collect();
        assert_eq!(once, again);
        assert_eq!(once.len(), 9);
        let elsewhere: Vec<_> = direct_samples(&light, p + Vec3::X * 1e-9).collect();
        assert_ne!(once[0].2.to_light, elsewhere[0].2.to_light);
    }
}
