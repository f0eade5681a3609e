//! Lights as emitters: the flux a light sends out and the rays (photons)
//! that carry it, for photon tracing.
//!
//! A light's flux is its intensity integrated over the directions it sends
//! light into: `4π I` for a point light, `I ∫ cos^falloff dω` over the cone
//! for a spot light (`2π I (1 - c^(f+1)) / (f+1)` with `c` the cut-off
//! cosine, clamped to `[0, 1]` because a spot is dark behind itself), and
//! for a directional light, whose intensity is an irradiance, `I` times the
//! area of the disk that covers the scene's bounds across the light's
//! direction; an area light's is `π L A` (radiance times area, Lambertian).
//! Each emitted ray carries that whole flux: `N` of them, each divided by
//! `N`, are an unbiased estimate of the light, because their
//! directions (and, for a directional light, origins) are drawn in
//! proportion to how the light spreads its intensity.
//!
//! Distance attenuation: photons carry flux, and the physical inverse-square
//! fall-off of irradiance comes out of their thinning with distance by
//! itself. Photons therefore ignore a light's [`Attenuation`]; they agree
//! with [`Light::sample`] exactly for `[0, 0, 1]` (pure inverse square).
//! With any other coefficients, the default no-fall-off `[1, 0, 0]`
//! included, the Whitted direct lighting is not physical and photon-traced
//! light will not match it.
//!
//! [`Attenuation`]: crate::shading::Attenuation

use std::f64::consts::PI;

use crate::math::sampling::{
    about_axis, power_cosine_cone, power_cosine_cone_integral, uniform_disk, uniform_sphere,
};
use crate::math::{Aabb, Vec3};
use crate::shading::{Color, Light};

/// A ray leaving a light, carrying the light's flux.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmittedRay {
    /// Where it starts: the light's position, or for a directional light a
    /// point on a disk upstream of the scene's bounds.
    pub origin: Vec3,
    /// The unit direction it travels in.
    pub direction: Vec3,
    /// The light's whole flux ([`Light::power`]); a photon of `N` emitted
    /// carries this divided by `N`.
    pub power: Color,
}

impl Light {
    /// The flux (radiant power) the light sends out, per channel; see the
    /// module documentation. A directional light's depends on the scene
    /// it lights, `scene_bounds` (the bounds of its finite objects): it is
    /// zero for empty or unbounded bounds. Ignores attenuation.
    pub fn power(&self, scene_bounds: &Aabb) -> Color {
        match self {
            Light::Point { intensity, .. } => *intensity * (4.0 * PI),
            Light::Spot {
                intensity,
                cos_cutoff,
                falloff,
                ..
            } => *intensity * power_cosine_cone_integral(cone_cos(*cos_cutoff), *falloff),
            Light::Directional {
                direction,
                intensity,
            } => match covering_disk(scene_bounds, *direction) {
                Some((_, radius)) => *intensity * (PI * radius * radius),
                None => Color::ZERO,
            },
            Light::Area(area) => area.power(),
        }
    }

    /// One ray the light sends out, chosen by `u` (four numbers in `[0,
    /// 1)`), carrying the whole [`Light::power`]; `None` when the light
    /// sends out nothing (black, a closed cone, a directional light with no
    /// finite bounds to light).
    ///
    /// - Point: a uniform direction (`u[0]`, `u[1]`).
    /// - Spot: a direction in its cone with density proportional to
    ///   `cos^falloff` of its angle to the axis (`u[0]`, `u[1]`).
    /// - Directional: the light's direction, from a uniform point
    ///   (`u[0]`, `u[1]`) of the disk perpendicular to it that covers
    ///   `scene_bounds`, placed upstream of every corner of the bounds.
    ///
    /// - Area: a uniform point of its surface (`u[0]`, `u[1]`) and a
    ///   cosine-weighted direction about its normal there (`u[2]`, `u[3]`);
    ///   see [`crate::shading::area_light`].
    pub fn emit(&self, u: [f64; 4], scene_bounds: &Aabb) -> Option<EmittedRay> {
        let power = self.power(scene_bounds);
        if power.max_element().is_nan() || power.max_element() <= 0.0 {
            return None;
        }
        let (origin, direction) = match self {
            Light::Point { position, .. } => (*position, uniform_sphere([u[0], u[1]])),
            Light::Spot {
                position,
                direction,
                cos_cutoff,
                falloff,
                ..
            } => {
                let local = power_cosine_cone([u[0], u[1]], cone_cos(*cos_cutoff), *falloff);
                (*position, about_axis(local, *direction))
            }
            Light::Directional { direction, .. } => {
                let (centre, radius) = covering_disk(scene_bounds, *direction)?;
                let (x, y) = direction.any_orthonormal_pair();
                let d = uniform_disk([u[0], u[1]]) * radius;
                (centre + d.x * x + d.y * y, *direction)
            }
            Light::Area(area) => return Some(area.emit(u)),
        };
        Some(EmittedRay {
            origin,
            direction,
            power,
        })
    }
}

/// The cosine of the cone a spot light really lights: its cut-off, but
/// never past 90° ([`Light::sample`] is dark for directions behind it).
fn cone_cos(cos_cutoff: f64) -> f64 {
    cos_cutoff.clamp(0.0, 1.0)
}

/// The disk perpendicular to the unit `direction` from which parallel rays
/// cover all of `bounds`: its centre, a little upstream of every corner,
/// and its radius (the largest distance of a corner from the axis through
/// the centroid). `None` for empty, unbounded or flat-along-the-light
/// bounds.
fn covering_disk(bounds: &Aabb, direction: Vec3) -> Option<(Vec3, f64)> {
    if bounds.is_empty() || !bounds.is_finite() {
        return None;
    }
    let centroid = bounds.centroid();
    let (mut radius, mut upstream) = (0.0f64, 0.0f64);
    for corner in bounds.corners() {
        let v = corner - centroid;
        let along = v.dot(direction);
        radius = radius.max((v - along * direction).length());
        upstream = upstream.min(along);
    }
    // Back off by a millionth of the box's size so that no ray starts on or
    // inside the box through rounding.
    let margin = 1e-6 * (radius - upstream);
    (radius > 0.0).then(|| (centroid + (upstream - margin) * direction, radius))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use crate::math::random::Rng;
    use crate::shading::Attenuation;

    fn four(rng: &mut Rng) -> [f64; 4] {
        [rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()]
    }

    fn unit_cube() -> Aabb {
        Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
    }

    fn spot(cos_cutoff: f64, falloff: f64) -> Light {
        Light::Spot {
            position: Vec3::new(1.0, 2.0, 3.0),
            direction: Vec3::new(0.0, -0.6, -0.8),
            intensity: Color::new(2.0, 1.0, 0.5),
            cos_cutoff,
            falloff,
            attenuation: Attenuation::NONE,
        }
    }

    fn close(a: Color, b: Color, relative: f64) -> bool {
        (a - b).abs().max_element() <= relative * b.abs().max_element()
    }

    #[test]
    fn power_is_the_intensity_integrated_over_the_lit_directions() {
        let bounds = unit_cube();
        let point = Light::Point {
            position: Vec3::ZERO,
            intensity: Color::new(1.0, 2.0, 3.0),
            attenuation: Attenuation::NONE,
        };
        assert_eq!(point.power(&bounds), Color::new(1.0, 2.0, 3.0) * (4.0 * PI));
        let i = Color::new(2.0, 1.0, 0.5);
        // A 90° spot without fall-off lights a hemisphere: half a point light.
        assert!(close(spot(0.0, 0.0).power(&bounds), i * (2.0 * PI), 1e-15));
        // Wider than 90° lights no more: the spot is dark behind itself.
        assert_eq!(
            spot(-0.5, 0.0).power(&bounds),
            spot(0.0, 0.0).power(&bounds)
        );
        // ∫ cos² over the 60° cone = 2π (1 - 0.5³) / 3.
        let expected = i * (2.0 * PI * 0.875 / 3.0);
        assert!(close(spot(0.5, 2.0).power(&bounds), expected, 1e-15));
        // A light along -y sees the cube as a 2×2 square, covered by a
        // disk of radius √2.
        let sun = Light::Directional {
            direction: -Vec3::Y,
            intensity: Color::ONE,
        };
        assert!(close(sun.power(&bounds), Color::splat(2.0 * PI), 1e-12));
    }

    #[test]
    fn photons_carry_the_intensity_that_sample_reports() {
        // Flux into a small cone of directions around ω, estimated from the
        // photons, must be the intensity towards ω times the cone's solid
        // angle.
        let lights = [
            (
                Light::Point {
                    position: Vec3::new(1.0, 2.0, 3.0),
                    intensity: Color::new(1.0, 0.5, 0.25),
                    attenuation: Attenuation::NONE,
                },
                Vec3::new(0.3, -0.4, 0.5).normalize(),
            ),
            (
                spot(45f64.to_radians().cos(), 3.0),
                about_axis(
                    Vec3::new(20f64.to_radians().sin(), 0.0, 20f64.to_radians().cos()),
                    Vec3::new(0.0, -0.6, -0.8),
                ),
            ),
        ];
        let bounds = unit_cube();
        let cos_delta = 0.2f64.cos();
        let solid_angle = 2.0 * PI * (1.0 - cos_delta);
        let mut rng = Rng::new(31);
        for (light, towards) in lights {
            let count = 400_000;
            let (mut flux, mut total) = (Color::ZERO, Color::ZERO);
            for _ in 0..count {
                let ray = light.emit(four(&mut rng), &bounds).unwrap();
                total += ray.power / count as f64;
                if ray.direction.dot(towards) >= cos_delta {
                    flux += ray.power / count as f64;
                }
            }
            assert!(close(total, light.power(&bounds), 1e-9));
            let position = match light {
                Light::Point { position, .. } | Light::Spot { position, .. } => position,
                Light::Directional { .. } | Light::Area(_) => unreachable!(),
            };
            let intensity = light.sample(position + towards).unwrap().intensity;
            let expected = intensity * solid_angle;
            assert!(
                close(flux, expected, 0.05),
                "{light:?}: {flux} vs {expected}"
            );
        }
    }

    #[test]
    fn spot_photons_stay_inside_the_cone_it_lights() {
        let mut rng = Rng::new(32);
        let bounds = unit_cube();
        for (cos_cutoff, falloff) in [(0.9, 0.0), (0.5, 10.0), (-0.3, 0.0)] {
            let light = spot(cos_cutoff, falloff);
            let Light::Spot {
                position,
                direction,
                ..
            } = light
            else {
                unreachable!()
            };
            let mut nearest_edge = f64::INFINITY;
            for _ in 0..50_000 {
                let ray = light.emit(four(&mut rng), &bounds).unwrap();
                assert_eq!(ray.origin, position);
                assert!((ray.direction.length() - 1.0).abs() < 1e-12);
                let cos_axis = ray.direction.dot(direction);
                assert!(cos_axis >= cos_cutoff - 1e-12 && cos_axis >= -1e-12);
                // And sample() agrees that the light reaches along it.
                let at_edge = cos_axis - cos_cutoff.max(0.0) < 1e-9;
                assert!(light.sample(position + ray.direction).is_some() || at_edge);
                nearest_edge = nearest_edge.min(cos_axis - cos_cutoff.max(0.0));
            }
            // Without fall-off the cone is filled out to its edge.
            if falloff == 0.0 {
                assert!(nearest_edge < 1e-3, "{nearest_edge}");
            }
        }
    }

    #[test]
    fn point_photons_leave_in_uniform_directions() {
        let light = Light::Point {
            position: Vec3::new(-1.0, 0.5, 2.0),
            intensity: Color::ONE,
            attenuation: Attenuation::NONE,
        };
        let mut rng = Rng::new(33);
        let count = 200_000;
        let (mut mean, mut square) = (Vec3::ZERO, Vec3::ZERO);
        for _ in 0..count {
            let ray = light.emit(four(&mut rng), &Aabb::EMPTY).unwrap();
            assert_eq!(ray.origin, Vec3::new(-1.0, 0.5, 2.0));
            mean += ray.direction;
            square += ray.direction * ray.direction;
        }
        let (mean, square) = (mean / count as f64, square / count as f64);
        assert!(mean.length() < 0.01, "{mean}");
        // Each coordinate squared averages 1/3 on the uniform sphere.
        assert!((square - Vec3::splat(1.0 / 3.0)).abs().max_element() < 0.005);
    }

    #[test]
    fn directional_photons_start_upstream_and_light_the_bounds_evenly() {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(0.0, 2.0, 5.0));
        let direction = Vec3::new(0.3, -0.8, 0.4).normalize();
        let intensity = Color::new(0.5, 1.0, 2.0);
        let light = Light::Directional {
            direction,
            intensity,
        };
        let power = light.power(&bounds);
        let (_, radius) = covering_disk(&bounds, direction).unwrap();
        let mut rng = Rng::new(34);
        let rays: Vec<EmittedRay> = (0..200_000)
            .map(|_| light.emit(four(&mut rng), &bounds).unwrap())
            .collect();
        let upstream = bounds
            .corners()
            .map(|c| c.dot(direction))
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        for ray in &rays {
            assert_eq!(ray.direction, direction);
            assert_eq!(ray.power, power);
            assert!(ray.origin.dot(direction) < upstream);
        }
        let passes_within = |p: Vec3, ray: &EmittedRay, distance: f64| {
            let v = p - ray.origin;
            (v - v.dot(direction) * direction).length() < distance
        };
        // Every corner of the bounds, the hardest points to reach, is lit.
        for corner in bounds.corners() {
            assert!(
                rays.iter()
                    .any(|ray| passes_within(corner, ray, 0.01 * radius))
            );
        }
        // Through a small disk across the light around a point of the
        // bounds passes the irradiance times the disk's area (points of the
        // middle half of the box, whose small disks stay inside the covering
        // one).
        let rho = 0.25 * radius;
        let (centre, half) = (bounds.centroid(), bounds.extent() / 4.0);
        for _ in 0..5 {
            let p = rng.point_in(centre - half, centre + half);
            let flux: Color = rays
                .iter()
                .filter(|ray| passes_within(p, ray, rho))
                .map(|ray| ray.power / rays.len() as f64)
                .sum();
            let expected = intensity * (PI * rho * rho);
            assert!(close(flux, expected, 0.05), "at {p}: {flux} vs {expected}");
        }
    }

    #[test]
    fn directional_photons_hit_a_cube_in_proportion_to_its_shadow() {
        // Along -y a 2×2×2 cube casts a 2×2 shadow on the covering disk of
        // radius √2: 4 / 2π of the photons hit it.
        let light = Light::Directional {
            direction: -Vec3::Y,
            intensity: Color::ONE,
        };
        let bounds = unit_cube();
        let mut rng = Rng::new(35);
        let count = 100_000;
        let hits = (0..count)
            .filter(|_| {
                let ray = light.emit(four(&mut rng), &bounds).unwrap();
                bounds
                    .intersect_ray(&Ray::new(ray.origin, ray.direction))
                    .is_some()
            })
            .count();
        let fraction = hits as f64 / count as f64;
        assert!((fraction - 2.0 / PI).abs() < 0.005, "{fraction}");
    }

    #[test]
    fn lights_that_send_nothing_emit_no_photon() {
        let sun = Light::Directional {
            direction: -Vec3::Y,
            intensity: Color::ONE,
        };
        let u = [0.5; 4];
        for bounds in [Aabb::EMPTY, Aabb::INFINITE] {
            assert_eq!(sun.power(&bounds), Color::ZERO);
            assert_eq!(sun.emit(u, &bounds), None);
        }
        // A box that is a segment along the light casts no shadow.
        let needle = Aabb::new(Vec3::ZERO, Vec3::Y);
        assert_eq!(sun.emit(u, &needle), None);
        let dark = Light::Point {
            position: Vec3::ZERO,
            intensity: Color::ZERO,
            attenuation: Attenuation::NONE,
        };
        assert_eq!(dark.emit(u, &unit_cube()), None);
        // A spot whose cone is closed.
        assert_eq!(spot(1.0, 0.0).emit(u, &unit_cube()), None);
    }
}
