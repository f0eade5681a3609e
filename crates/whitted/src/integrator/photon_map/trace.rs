//! The photon pass: photons leave the lights in proportion to their power,
//! follow mirror reflection and refraction by the materials' own lobes
//! ([`crate::shading::Lobes`], so by the tracer's Fresnel and total
//! internal reflection rules), and are kept where they land on a diffuse
//! surface after at least one specular bounce.
//!
//! Any [`Light`] is an emitter: the pass asks each for its power
//! ([`Light::power`]) and its rays ([`Light::emit`]), so an area light
//! joins by implementing those two.
//!
//! Photon `j` of the whole pass is traced from its index alone: its light
//! and its place in that light's share are fixed by `j`, its emission by a
//! Halton point of that place, its scattering by a generator seeded with
//! `j`. The map is therefore the same whatever the threads and the order
//! they run in.

use std::ops::Range;

use crate::integrator::Shading;
use crate::integrator::visibility::Visibility;
use crate::math::random::{Rng, hash64};
use crate::math::{Aabb, Ray, offset_ray_origin};
use crate::shading::{Color, Light, Material, MediumStack, ScatterKind, shading_normal};

use super::Photon;

/// The most surfaces one photon is followed through. Russian roulette
/// ends almost every path long before; this ends the rest (a clear ball
/// that traps a photon by total internal reflection).
const MAX_BOUNCES: u32 = 64;

/// Salt mixed into a photon's index to seed its scattering, so that its
/// numbers are not those of a pixel with the same hash.
const SCATTER_SEED: u64 = 0x7068_6f74_6f6e_7321;

/// One light's share of the photons.
#[derive(Clone, Copy, Debug)]
pub(super) struct Emitter<'l> {
    light: &'l Light,
    /// Flux of each of its photons: its power divided by its count.
    photon_power: Color,
    /// Index of its first photon in the pass.
    first: u64,
    /// How many photons it sends.
    count: u64,
}

/// Shares `total` photons among `lights` in proportion to their power over
/// `bounds` (the sum of its channels), rounding the cumulative shares so
/// that the counts add up to `total` exactly. Lights that send nothing,
/// and any whose rounded share is 0, get no photons.
pub(super) fn share<'l>(lights: &'l [Light], bounds: &Aabb, total: u64) -> Vec<Emitter<'l>> {
    let powers: Vec<(&Light, Color, f64)> = lights
        .iter()
        .map(|light| {
            let power = light.power(bounds);
            let scalar = power.r + power.g + power.b;
            (light, power, scalar)
        })
        .filter(|(_, _, scalar)| scalar.is_finite() && *scalar > 0.0)
        .collect();
    let sum: f64 = powers.iter().map(|(_, _, s)| s).sum();
    let mut emitters = Vec::new();
    let (mut cumulative, mut first) = (0.0, 0u64);
    for (i, (light, power, scalar)) in powers.iter().enumerate() {
        cumulative += scalar;
        let end = if i + 1 == powers.len() {
            total
        } else {
            ((cumulative / sum) * total as f64).round() as u64
        }
        .clamp(first, total);
        let count = end - first;
        if count > 0 {
            emitters.push(Emitter {
                light,
                photon_power: *power / count as f64,
                first,
                count,
            });
        }
        first = end;
    }
    emitters
}

/// Traces the photons numbered `photons` and appends those it keeps to
/// `out`.
pub(super) fn shoot(
    visibility: &Visibility<'_>,
    shading: &Shading<'_>,
    (emitters, bounds): (&[Emitter<'_>], &Aabb),
    photons: Range<u64>,
    out: &mut Vec<Photon>,
) {
    for j in photons {
        let Some(emitter) = emitters
            .iter()
            .find(|e| (e.first..e.first + e.count).contains(&j))
        else {
            continue;
        };
        let place = j - emitter.first;
        let u = [2, 3, 5, 7].map(|base| radical_inverse(base, place));
        let Some(ray) = emitter.light.emit(u, bounds) else {
            continue;
        };
        let mut rng = Rng::new(hash64(j ^ SCATTER_SEED));
        follow(
            visibility,
            shading,
            Ray::new(ray.origin, ray.direction),
            emitter.photon_power,
            &mut rng,
            out,
        );
    }
}

/// Follows one photon of flux `power` along `ray` through specular
/// scattering, keeping it where it lands on a diffuse surface after at
/// least one bend.
fn follow(
    visibility: &Visibility<'_>,
    shading: &Shading<'_>,
    mut ray: Ray,
    mut power: Color,
    rng: &mut Rng,
    out: &mut Vec<Photon>,
) {
    let mut media = MediumStack::default();
    let mut specular = false;
    let mut from = None;
    for _ in 0..MAX_BOUNCES {
        let hit = match from {
            None => visibility.closest(&ray),
            Some(from) => visibility.closest_from(&ray, from),
        };
        let Some(hit) = hit else {
            return;
        };
        from = Some(hit.primitive);
        let s = visibility.world().surface(&ray, &hit);
        let m = &shading.materials[s.material.0 as usize];
        let incident = ray.dir;
        let entering = incident.dot(s.normal) < 0.0;
        let facing = if entering { s.normal } else { -s.normal };
        let n = shading_normal(m.bump.as_ref(), &s, facing, -incident);
        let crossing = media.cross(
            s.medium,
            shading.materials[s.medium.0 as usize].ior,
            entering,
        );
        let lobes = m.lobes(s.uv, incident, n, crossing.n_from, crossing.n_to);
        if specular && lobes.diffuse != Color::ZERO {
            out.push(Photon::new(s.point, incident, power));
        }
        let u = [rng.uniform(), rng.uniform(), rng.uniform()];
        let Some(scattered) = lobes.sample(incident, n, u) else {
            return;
        };
        match scattered.kind {
            // A diffuse bounce ends a caustic path.
            ScatterKind::Diffuse => return,
            ScatterKind::Mirror => specular = true,
            ScatterKind::Refract => {
                media = crossing.after();
                specular |= bends_light(m);
            }
        }
        power *= scattered.weight;
        let origin = offset_ray_origin(s.point, s.point_error, s.normal, scattered.direction);
        ray = Ray::new(origin, scattered.direction);
    }
}

/// True when light going through a surface of `material` is bent (its
/// index of refraction is not 1), so that the caustic map carries it
/// rather than a straight shadow ray. Light through a dissolved or
/// transmissive surface of index 1 goes straight on: shadow rays keep
/// passing through it, and photons crossing it do not become caustics.
pub fn bends_light(material: &Material) -> bool {
    material.ior != 1.0
}

/// The radical inverse of `index` in `base`: its digits mirrored about the
/// point, the `index`-th Halton coordinate; in `[0, 1)`.
fn radical_inverse(base: u64, mut index: u64) -> f64 {
    let inverse_base = 1.0 / base as f64;
    let (mut reversed, mut scale) = (0.0, inverse_base);
    while index > 0 {
        reversed += (index % base) as f64 * scale;
        index /= base;
        scale *= inverse_base;
    }
    reversed.min(1.0 - f64::EPSILON / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::shading::Attenuation;

    fn point(intensity: f64) -> Light {
        Light::Point {
            position: Vec3::ZERO,
            intensity: Color::splat(intensity),
            attenuation: Attenuation::NONE,
        }
    }

    #[test]
    fn photons_are_shared_in_proportion_to_power_and_add_up() {
        let lights = [point(1.0), point(0.0), point(3.0), point(1e-9)];
        let emitters = share(&lights, &Aabb::EMPTY, 1000);
        let counts: Vec<u64> = emitters.iter().map(|e| e.count).collect();
        // The black light and the one too faint for a photon get none.
        assert_eq!(counts, vec![250, 750]);
        assert_eq!(emitters[1].first, 250);
        // Each light's photons carry its whole power between them.
        for e in &emitters {
            let whole = e.photon_power * e.count as f64;
            assert!((whole - e.light.power(&Aabb::EMPTY)).abs().max_element() < 1e-12);
        }
        assert!(share(&lights, &Aabb::EMPTY, 0).is_empty());
        assert!(share(&[], &Aabb::EMPTY, 10).is_empty());
    }

    #[test]
    fn radical_inverses_are_the_mirrored_digits() {
        assert_eq!(radical_inverse(2, 0), 0.0);
        assert_eq!(radical_inverse(2, 1), 0.5);
        assert_eq!(radical_inverse(2, 6), 0.375); // 110 → 0.011
        assert_eq!(radical_inverse(3, 5), 2.0 / 3.0 + 1.0 / 9.0); // 12 → 0.21
        assert!(radical_inverse(7, u64::MAX) < 1.0);
    }
}
