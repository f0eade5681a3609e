//! The three ray sets of a scene, generated once and traced by every
//! structure.

use super::{RayKind, RaySet};
use crate::math::random::{Rng, hash64};
use crate::math::{Aabb, Ray, Vec3, offset_ray_origin};
use crate::render::Scene;
use crate::shading::{Color, Light};
use crate::world::World;

/// Largest image (in pixels) to make rays for: a ray takes 88 bytes and a
/// pixel up to three (primary, shadow, diffuse), about 1.1 GB at this size
/// (2048 × 2048), held for the whole measurement.
pub const MAX_RAY_PIXELS: u64 = 1 << 22;

/// Primary rays through the centre of every pixel of a `width` × `height`
/// image, then one shadow ray and one diffuse ray per primary hit. Shadow
/// rays go towards the scene's first light (or, without lights, a point
/// above the scene's bounds) and are cast only where it is above the
/// surface. Diffuse directions are seeded by the pixel index.
pub fn scene_ray_sets(scene: &Scene, world: &World, width: u32, height: u32) -> Vec<RaySet> {
    let mut primary = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let (px, py) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            primary.push(scene.camera.ray(width, height, px, py));
        }
    }
    let light = scene
        .lights
        .first()
        .cloned()
        .unwrap_or_else(|| default_light(world.bounds()));
    let mut shadow = Vec::new();
    let mut diffuse = Vec::new();
    for (index, ray) in primary.iter().enumerate() {
        let Some(hit) = world.intersect(ray) else {
            continue;
        };
        let s = world.surface(ray, &hit);
        let n = if ray.dir.dot(s.normal) < 0.0 {
            s.normal
        } else {
            -s.normal
        };
        if let Some(sample) = light.sample(s.point)
            && sample.to_light.dot(n) > 0.0
        {
            let origin = offset_ray_origin(s.point, s.point_error, s.normal, sample.to_light);
            let t_max = match light {
                Light::Directional { .. } => f64::INFINITY,
                _ => sample.distance,
            };
            shadow.push(Ray::segment(origin, sample.to_light, t_max));
        }
        let mut rng = Rng::new(hash64(index as u64));
        let dir = cosine_direction(n, rng.uniform(), rng.uniform());
        let origin = offset_ray_origin(s.point, s.point_error, s.normal, dir);
        diffuse.push(Ray::new(origin, dir));
    }
    vec![
        RaySet {
            kind: RayKind::Primary,
            rays: primary,
        },
        RaySet {
            kind: RayKind::Shadow,
            rays: shadow,
        },
        RaySet {
            kind: RayKind::Diffuse,
            rays: diffuse,
        },
    ]
}

/// A point light above the scene, placed as the anchor harness places its
/// default light.
fn default_light(bounds: Aabb) -> Light {
    let (c, d) = if bounds.is_empty() || !bounds.is_finite() {
        (Vec3::ZERO, Vec3::ONE)
    } else {
        (bounds.centroid(), bounds.extent())
    };
    Light::Point {
        position: Vec3::new(c.x + 0.2 * d.x, c.y + d.y, c.z + 0.1 * d.z),
        intensity: Color::ONE,
        attenuation: crate::shading::Attenuation::NONE,
    }
}

/// A cosine-distributed unit direction around the unit normal `n` from two
/// uniform numbers (Malley's method in the frame of Duff et al. 2017).
fn cosine_direction(n: Vec3, u1: f64, u2: f64) -> Vec3 {
    let r = u1.sqrt();
    let phi = std::f64::consts::TAU * u2;
    let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
    let (t, b) = n.any_orthonormal_pair();
    (local.x * t + local.y * b + local.z * n).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_directions_stay_in_the_hemisphere_with_mean_cosine_two_thirds() {
        let n = Vec3::new(1.0, 2.0, -0.5).normalize();
        let mut rng = Rng::new(3);
        let count = 20_000;
        let mut sum = 0.0;
        for _ in 0..count {
            let d = cosine_direction(n, rng.uniform(), rng.uniform());
            assert!((d.length() - 1.0).abs() < 1e-12);
            let c = d.dot(n);
            assert!(c >= 0.0);
            sum += c;
        }
        assert!((sum / f64::from(count) - 2.0 / 3.0).abs() < 0.01);
    }

    #[test]
    fn default_scene_gives_every_kind_of_ray() {
        let scene = crate::scene::default_scene();
        let world = World::new(&scene.objects);
        let sets = scene_ray_sets(&scene, &world, 32, 24);
        assert_eq!(sets[0].rays.len(), 32 * 24);
        assert!(!sets[1].rays.is_empty() && !sets[2].rays.is_empty());
        assert!(sets[1].rays.len() <= sets[2].rays.len());
        assert!(sets[1].rays.iter().all(|r| r.t_max.is_finite()));
    }
}
