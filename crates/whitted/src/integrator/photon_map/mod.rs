//! Photon-mapped caustics (Jensen): light that reaches a diffuse surface
//! by mirror reflection or refraction, which Whitted's shadow rays cannot
//! follow.
//!
//! Before the render, a photon pass ([`trace`]) shoots
//! [`PhotonSettings::count`] photons from the lights (a directional
//! light's at the objects that can start a caustic, [`aim`]) and keeps
//! those that land on a diffuse surface after at least one specular
//! bounce: the
//! caustic map, a balanced kd-tree ([`kd_tree`]) built once. While
//! rendering, the Whitted integrator adds at every diffuse point it shades
//! (seen directly or through mirrors and glass) the irradiance the map
//! estimates there ([`CausticMap::irradiance`]) times the point's diffuse
//! colour, as it does for each light's direct irradiance. With the map on,
//! shadow rays stop at surfaces that bend light ([`bends_light`]): that
//! light comes from the map alone, not a second time through the
//! transparent-shadow shortcut.
//!
//! The estimate gathers the `gather` nearest photons within `radius`
//! arriving on the side of the surface being shaded, weighted by Jensen's
//! cone filter: `E = Σ Φ_p (1 - d_p / r) / ((1 - 2/3) π r²)`, with `r` the
//! distance of the farthest photon gathered when `gather` were found and
//! `radius` when fewer were.
//!
//! Photons carry flux, so attenuation does not apply to them (see
//! [`crate::shading::emission`]): caustics agree with the direct light of
//! lights whose attenuation is physical (`[0, 0, 1]`) or directional.
//!
//! ```toml
//! [render]
//! photons = 200000   # shot from the lights; 0 (the default) is off
//! gather = 50        # nearest photons per estimate
//! radius = 0.05      # largest gathering distance, in scene units
//! ```

mod aim;
mod kd_tree;
mod settings;
mod trace;

pub use kd_tree::{KdTree, Located, Neighbour, Neighbours};
pub use settings::{
    MAX_GATHER, MAX_PHOTONS, PhotonSettings, PhotonSettingsError, RADIUS_OF_DIAGONAL,
};
pub use trace::bends_light;

use std::cell::RefCell;
use std::f64::consts::PI;

use rayon::prelude::*;

use crate::integrator::Shading;
use crate::integrator::visibility::Visibility;
use crate::limits::{MemoryBudget, MemoryError};
use crate::math::{DVec2, Vec3};
use crate::shading::{Color, Material};
use crate::world::World;

/// Photons traced by one task of the parallel pass.
const PHOTONS_PER_TASK: u64 = 4096;

/// The radius used when the scene has no bounded object to size it by.
const RADIUS_WITHOUT_BOUNDS: f64 = 1.0;

/// The smallest gathering radius, as a fraction of the largest: keeps an
/// estimate finite where many photons land on one point.
const SMALLEST_RADIUS: f64 = 1e-6;

/// A photon kept in the map: where it landed, the direction it arrived
/// along and the flux it carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    /// Where it landed.
    pub position: Vec3,
    incident: [f32; 3],
    power: [f32; 3],
}

impl Photon {
    /// A photon at `position` that arrived along `incident` (unit)
    /// carrying `power`.
    pub fn new(position: Vec3, incident: Vec3, power: Color) -> Self {
        let [r, g, b] = power.to_f32();
        Self {
            position,
            incident: incident.as_vec3().to_array(),
            power: [r, g, b],
        }
    }

    /// The direction it arrived along.
    pub fn incident(&self) -> Vec3 {
        Vec3::from(self.incident.map(f64::from))
    }

    /// The flux it carries.
    pub fn power(&self) -> Color {
        let [r, g, b] = self.power.map(f64::from);
        Color::new(r, g, b)
    }
}

impl Located for Photon {
    fn position(&self) -> Vec3 {
        self.position
    }
}

/// The caustic map: photons that reached diffuse surfaces by specular
/// paths, and how to gather them.
#[derive(Clone, Debug)]
pub struct CausticMap {
    tree: KdTree<Photon>,
    emitted: u64,
    gather: usize,
    radius: f64,
}

thread_local! {
    /// Each thread's neighbour heap, reused by every estimate.
    static NEIGHBOURS: RefCell<Neighbours> = RefCell::default();
}

impl CausticMap {
    /// Runs the photon pass over `world` (on the current rayon pool) with
    /// `shading`'s lights and materials, and builds the map. Photons find
    /// their hits by the fast paths, or with `fast_paths` false by the
    /// plain closest-hit query (the same map). Refuses a count whose
    /// photons could exceed the memory budget.
    pub fn build(
        world: &World<'_>,
        shading: &Shading<'_>,
        settings: &PhotonSettings,
        fast_paths: bool,
    ) -> Result<Self, MemoryError> {
        let bytes = settings
            .count
            .saturating_mul((std::mem::size_of::<Photon>() + 1) as u64);
        MemoryBudget::current().check(
            &format!("a map of {} photons", settings.count),
            bytes,
            "shoot fewer photons",
        )?;
        let bounds = world.bounds();
        let aimed = aim::caustic_bounds(world.objects(), shading.materials, bounds);
        let emitters = trace::share(shading.lights, &aimed, settings.count);
        let visibility = Visibility::new(world, shading.materials).with_fast_paths(fast_paths);
        let tasks = settings.count.div_ceil(PHOTONS_PER_TASK);
        let parts: Vec<Vec<Photon>> = (0..tasks)
            .into_par_iter()
            .map(|task| {
                let start = task * PHOTONS_PER_TASK;
                let end = (start + PHOTONS_PER_TASK).min(settings.count);
                let mut kept = Vec::new();
                let sources = (&emitters[..], &aimed);
                trace::shoot(&visibility, shading, sources, start..end, &mut kept);
                kept
            })
            .collect();
        let photons: Vec<Photon> = parts.concat();
        let radius = settings.radius.unwrap_or_else(|| {
            if bounds.is_empty() || !bounds.is_finite() {
                RADIUS_WITHOUT_BOUNDS
            } else {
                RADIUS_OF_DIAGONAL * bounds.extent().length()
            }
        });
        Ok(Self {
            tree: KdTree::build(photons),
            emitted: settings.count,
            gather: settings.gather as usize,
            radius,
        })
    }

    /// The photons kept, in the tree's order.
    pub fn photons(&self) -> &[Photon] {
        self.tree.items()
    }

    /// How many photons the lights sent.
    pub fn emitted(&self) -> u64 {
        self.emitted
    }

    /// The largest gathering distance.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The irradiance the caustic photons bring to `point` on a surface
    /// whose normal on the side being shaded is `normal` (photons arriving
    /// from the other side are left out); see the module documentation
    /// for the cone filter.
    pub fn irradiance(&self, point: Vec3, normal: Vec3) -> Color {
        if self.tree.items().is_empty() {
            return Color::ZERO;
        }
        NEIGHBOURS.with(|cell| {
            let found = &mut cell.borrow_mut();
            let max_squared = self.radius * self.radius;
            self.tree.nearest(
                point,
                self.gather,
                max_squared,
                |p| p.incident().dot(normal) < 0.0,
                found,
            );
            let r_squared = if found.len() == self.gather {
                found.farthest_squared().unwrap_or(max_squared)
            } else {
                max_squared
            }
            .max(max_squared * SMALLEST_RADIUS * SMALLEST_RADIUS);
            let r = r_squared.sqrt();
            let mut sum = Color::ZERO;
            for n in found.as_slice() {
                let weight = 1.0 - n.distance_squared.sqrt() / r;
                sum += self.tree.items()[n.index as usize].power() * weight.max(0.0);
            }
            sum / ((1.0 - 2.0 / 3.0) * PI * r_squared)
        })
    }
}

/// What a shadow ray lets through a surface of `material` at `uv` when the
/// caustic map carries the light it bends: nothing where it bends light
/// ([`bends_light`]), what [`Material::pass_through`] says elsewhere.
pub fn shadow_pass_through(material: &Material, uv: DVec2) -> Color {
    if bends_light(material) {
        Color::ZERO
    } else {
        material.pass_through(uv)
    }
}

#[cfg(test)]
mod tests;
