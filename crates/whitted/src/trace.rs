//! The recursive Whitted integrator.
//!
//! For the closest hit of a ray it sums emission, ambient, direct light from
//! every light (Phong diffuse and specular, each light seen through one
//! shadow ray), and the mirror-reflected and refracted rays, recursively.
//! See [`crate::material`] for the formula and the Fresnel option.
//!
//! - Shading is two-sided: the normal is turned to face the incoming ray.
//!   A material's bump or normal map tilts it (see [`crate::bump`]); a
//!   light behind the geometric surface then lights nothing.
//! - Shadow rays pass through transmissive and dissolved surfaces, each
//!   crossing scaling the light by what that surface lets through
//!   (`α kt + 1 - α`); an opaque surface blocks it.
//! - Refraction follows Snell's law with the index of the medium the ray is
//!   in, tracked on a small stack of the media it has entered; total
//!   internal reflection moves the refracted weight onto the reflected ray.
//! - Recursion stops at `max_depth`, and earlier when a branch's weight on
//!   the pixel falls below `min_weight` (adaptive depth control).

use crate::bump::shading_normal;
use crate::geometry::{Geometry, Hit, Surface};
use crate::light::Light;
use crate::material::{Material, MaterialId};
use crate::math::{Color, Ray, Vec3, offset_ray_origin, reflect, refract, schlick_reflectance};
use crate::scene::{RenderSettings, Scene};

/// How many rays of each kind were traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Rays from the camera.
    pub primary: u64,
    /// Rays towards lights (one per light per shaded point, plus one per
    /// transmissive surface crossed).
    pub shadow: u64,
    /// Mirror-reflected rays.
    pub reflected: u64,
    /// Refracted rays.
    pub refracted: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflected + self.refracted
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
    }
}

/// The media a ray is inside, innermost last: the materials of the objects
/// it has entered, with their indices of refraction. Keyed by material, so a
/// closed mesh of many triangles is one medium, and two overlapping objects
/// of the same material are one medium too. The innermost entry is the
/// medium the ray travels in. Fixed capacity (eight nested media; deeper
/// nesting is not recorded): no allocation per ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct MediumStack {
    entries: [(u32, f64); Self::CAPACITY],
    len: usize,
}

impl MediumStack {
    const CAPACITY: usize = 8;

    /// The index of refraction the ray travels in (1 outside everything).
    pub fn ior(&self) -> f64 {
        if self.len == 0 {
            1.0
        } else {
            self.entries[self.len - 1].1
        }
    }

    /// True when the ray is inside an object of `material`.
    pub fn contains(&self, material: MaterialId) -> bool {
        self.entries[..self.len]
            .iter()
            .any(|&(m, _)| m == material.0)
    }

    /// The stack after entering an object of `material`.
    pub fn entered(mut self, material: MaterialId, ior: f64) -> Self {
        if self.len < Self::CAPACITY {
            self.entries[self.len] = (material.0, ior);
            self.len += 1;
        }
        self
    }

    /// The stack after leaving an object of `material` (its innermost
    /// entry; unchanged if the ray was not known to be inside it).
    pub fn left(mut self, material: MaterialId) -> Self {
        if let Some(i) = self.entries[..self.len]
            .iter()
            .rposition(|&(m, _)| m == material.0)
        {
            self.entries.copy_within(i + 1..self.len, i);
            self.len -= 1;
        }
        self
    }
}

/// What a ray crossing a surface goes from and to.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    /// Index of refraction on the incoming side.
    pub n_from: f64,
    /// Index of refraction on the far side.
    pub n_to: f64,
    /// The media of a ray that goes through.
    pub after: MediumStack,
}

impl MediumStack {
    /// Crossing the surface of an object of `material` (index `ior`),
    /// `entering` it or leaving it.
    pub fn cross(self, material: MaterialId, ior: f64, entering: bool) -> Crossing {
        if entering {
            return Crossing {
                n_from: self.ior(),
                n_to: ior,
                after: self.entered(material, ior),
            };
        }
        // Leaving an object that is not the innermost medium changes nothing
        // for the ray; leaving one the stack does not know (the ray started
        // inside it) goes from that object's material.
        let n_from = if self.contains(material) {
            self.ior()
        } else {
            ior
        };
        let after = self.left(material);
        Crossing {
            n_from,
            n_to: after.ior(),
            after,
        }
    }
}

/// Longest chain of transmissive surfaces one shadow ray passes through.
const MAX_SHADOW_CROSSINGS: usize = 64;

/// Traces rays through a scene.
#[derive(Debug)]
pub struct Tracer<'a> {
    scene: &'a Scene,
    geometry: Geometry<'a>,
    settings: RenderSettings,
    any_transmissive: bool,
}

/// The result of tracing one primary ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimarySample {
    /// The colour seen.
    pub color: Color,
    /// The first hit, if any, with its world-space surface.
    pub first_hit: Option<(Hit, Surface)>,
}

impl<'a> Tracer<'a> {
    /// Prepares `scene` for tracing with `settings`.
    pub fn new(scene: &'a Scene, settings: RenderSettings) -> Self {
        Self {
            scene,
            geometry: Geometry::with_accel(scene, settings.accel),
            settings,
            any_transmissive: scene.materials.iter().any(Material::is_transmissive),
        }
    }

    /// The prepared geometry.
    pub fn geometry(&self) -> &Geometry<'a> {
        &self.geometry
    }

    /// The scene being traced.
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }

    /// The first hit along a ray and its surface, without shading.
    pub fn first_hit(&self, ray: &Ray) -> Option<(Hit, Surface)> {
        let hit = self.geometry.intersect(ray)?;
        Some((hit, self.geometry.surface(ray, &hit)))
    }

    /// The colour seen along a camera ray (unit direction), and its first hit.
    pub fn trace_primary(&self, ray: &Ray, counts: &mut RayCounts) -> PrimarySample {
        counts.primary += 1;
        match self.geometry.intersect(ray) {
            None => PrimarySample {
                color: self.scene.background,
                first_hit: None,
            },
            Some(hit) => {
                let surface = self.geometry.surface(ray, &hit);
                let color = self.shade(ray, &surface, 0, 1.0, MediumStack::default(), counts);
                PrimarySample {
                    color,
                    first_hit: Some((hit, surface)),
                }
            }
        }
    }

    /// The colour seen along a secondary ray (unit direction).
    fn trace(
        &self,
        ray: &Ray,
        depth: u32,
        weight: f64,
        media: MediumStack,
        counts: &mut RayCounts,
    ) -> Color {
        match self.geometry.intersect(ray) {
            None => self.scene.background,
            Some(hit) => {
                let surface = self.geometry.surface(ray, &hit);
                self.shade(ray, &surface, depth, weight, media, counts)
            }
        }
    }

    /// The colour leaving `s` back along `ray`. `weight` is the largest
    /// factor by which this colour reaches the pixel.
    fn shade(
        &self,
        ray: &Ray,
        s: &Surface,
        depth: u32,
        weight: f64,
        media: MediumStack,
        counts: &mut RayCounts,
    ) -> Color {
        let m = &self.scene.materials[s.material.0 as usize];
        let incident = ray.dir;
        let view = -incident;
        let entering = incident.dot(s.normal) < 0.0;
        let facing = if entering { s.normal } else { -s.normal };
        // The shading normal (interpolated on meshes, tilted by a bump or
        // normal map) on the viewer's side.
        let n = shading_normal(m.bump.as_ref(), s, facing, view);
        // A tilted normal may see a light that is behind the surface itself.
        let bumped = m.bump.is_some();

        // The opacity weighs the surface's own light and mirror; the
        // dissolved rest joins the transmitted ray.
        let alpha = m.opacity.at(s.uv);
        let mut local = m.emission.at(s.uv) + m.ambient.at(s.uv) * self.scene.ambient;

        let diffuse = m.diffuse.at(s.uv);
        let specular = m.specular.at(s.uv);
        if alpha != Color::ZERO && (diffuse != Color::ZERO || specular != Color::ZERO) {
            for light in &self.scene.lights {
                let Some(sample) = light.sample(s.point) else {
                    continue;
                };
                let n_dot_l = n.dot(sample.to_light);
                if n_dot_l <= 0.0 || (bumped && facing.dot(sample.to_light) <= 0.0) {
                    continue;
                }
                let shadow = self.transmittance(s, light, sample.to_light, sample.distance, counts);
                if shadow == Color::ZERO {
                    continue;
                }
                let mut direct = diffuse * n_dot_l;
                let r_dot_v = reflect(-sample.to_light, n).dot(view);
                if r_dot_v > 0.0 && specular != Color::ZERO {
                    direct += specular * r_dot_v.powf(m.shininess);
                }
                local += shadow * sample.intensity * direct;
            }
        }
        let mut color = alpha * local;

        if depth >= self.settings.max_depth {
            return color;
        }
        let kr = m.reflection.at(s.uv);
        let kt = m.transmission.at(s.uv);
        if kr == Color::ZERO && kt == Color::ZERO && alpha == Color::ONE {
            return color;
        }

        let Crossing {
            n_from,
            n_to,
            after: inside_after,
        } = media.cross(s.material, m.ior, entering);
        let cos_i = view.dot(n).clamp(0.0, 1.0);
        let (reflected, transmitted) = if m.fresnel && kt != Color::ZERO {
            let f = schlick_reflectance(cos_i, n_from, n_to);
            (kr + kt * f, kt * (1.0 - f))
        } else {
            (kr, kt)
        };
        let mut reflected_weight = alpha * reflected;
        let mut transmitted_weight = alpha * transmitted + (Color::ONE - alpha);
        let refracted = if transmitted_weight == Color::ZERO {
            None
        } else {
            refract(incident, n, n_from / n_to)
        };
        if refracted.is_none() {
            reflected_weight += transmitted_weight;
            transmitted_weight = Color::ZERO;
        }

        let child = weight * reflected_weight.max_element();
        if child >= self.settings.min_weight && reflected_weight != Color::ZERO {
            counts.reflected += 1;
            let dir = reflect(incident, n);
            let origin = offset_ray_origin(s.point, s.point_error, s.normal, dir);
            let c = self.trace(&Ray::new(origin, dir), depth + 1, child, media, counts);
            color += reflected_weight * c;
        }
        if let Some(dir) = refracted {
            let child = weight * transmitted_weight.max_element();
            if child >= self.settings.min_weight {
                counts.refracted += 1;
                let dir = dir.normalize();
                let origin = offset_ray_origin(s.point, s.point_error, s.normal, dir);
                let c = self.trace(
                    &Ray::new(origin, dir),
                    depth + 1,
                    child,
                    inside_after,
                    counts,
                );
                color += transmitted_weight * c;
            }
        }
        color
    }

    /// How much of `light` reaches `s` along `to_light` (unit) over
    /// `distance`: 0 behind an opaque surface, the product of what every
    /// transmissive or dissolved surface crossed lets through otherwise
    /// ([`Material::pass_through`]).
    fn transmittance(
        &self,
        s: &Surface,
        light: &Light,
        to_light: Vec3,
        distance: f64,
        counts: &mut RayCounts,
    ) -> Color {
        counts.shadow += 1;
        let origin = offset_ray_origin(s.point, s.point_error, s.normal, to_light);
        let target = match light {
            Light::Directional { .. } => None,
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(*position),
        };
        let segment = |origin: Vec3| {
            let t_max = target.map_or(distance, |p| (p - origin).dot(to_light));
            Ray::segment(origin, to_light, t_max)
        };
        let mut ray = segment(origin);
        if !self.any_transmissive {
            return if self.geometry.occluded(&ray) {
                Color::ZERO
            } else {
                Color::ONE
            };
        }
        let mut through = Color::ONE;
        for _ in 0..MAX_SHADOW_CROSSINGS {
            let Some(hit) = self.geometry.intersect(&ray) else {
                return through;
            };
            let blocker = self.geometry.surface(&ray, &hit);
            let m = &self.scene.materials[blocker.material.0 as usize];
            through *= m.pass_through(blocker.uv);
            if through.max_element() <= 0.0 {
                return Color::ZERO;
            }
            counts.shadow += 1;
            let origin =
                offset_ray_origin(blocker.point, blocker.point_error, blocker.normal, to_light);
            ray = segment(origin);
        }
        Color::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medium_stack_tracks_nested_objects() {
        let glass = MaterialId(1);
        let water = MaterialId(2);
        let s = MediumStack::default();
        assert_eq!(s.ior(), 1.0);
        let s = s.entered(glass, 1.5);
        let s = s.entered(water, 1.33);
        assert_eq!(s.ior(), 1.33);
        let s = s.left(water);
        assert_eq!(s.ior(), 1.5);
        assert_eq!(s.left(MaterialId(9)).ior(), 1.5);
        assert_eq!(s.left(glass).ior(), 1.0);
    }

    #[test]
    fn crossings_refract_only_where_the_medium_really_changes() {
        let (glass, bubble) = (MaterialId(1), MaterialId(2));
        let air = MediumStack::default();
        let into_glass = air.cross(glass, 1.5, true);
        assert_eq!((into_glass.n_from, into_glass.n_to), (1.0, 1.5));
        let out_of_glass = into_glass.after.cross(glass, 1.5, false);
        assert_eq!((out_of_glass.n_from, out_of_glass.n_to), (1.5, 1.0));
        // Entering an overlapping ior-1 object from air, then the glass, then
        // leaving the first object while still in the glass: no interface.
        let in_both = air
            .cross(bubble, 1.0, true)
            .after
            .cross(glass, 1.5, true)
            .after;
        let leave_outer = in_both.cross(bubble, 1.0, false);
        assert_eq!((leave_outer.n_from, leave_outer.n_to), (1.5, 1.5));
        // A ray that started inside the glass leaves it into air.
        let unknown = air.cross(glass, 1.5, false);
        assert_eq!((unknown.n_from, unknown.n_to), (1.5, 1.0));
    }

    #[test]
    fn medium_stack_leaving_an_outer_object_keeps_the_inner_one() {
        let s = MediumStack::default()
            .entered(MaterialId(1), 1.5)
            .entered(MaterialId(2), 1.33)
            .left(MaterialId(1));
        assert_eq!(s.ior(), 1.33);
        assert_eq!(s.left(MaterialId(2)).ior(), 1.0);
    }
}
