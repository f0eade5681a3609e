//! Where a directional light's photons are aimed: at the objects that can
//! start a caustic, not the whole scene.
//!
//! A photon becomes a caustic at the first surface that mirrors or bends
//! it, and it travels there in a straight line from the light (through
//! surfaces of index 1 at most). For a directional light it then starts
//! inside the disk covering that surface's box, so the disk covering the
//! box around every such surface loses no caustic photon, and the photons
//! that would have landed straight on a diffuse table are not shot at all.
//! The flux of the smaller disk is what those photons carry
//! ([`crate::shading::Light::power`] over the same bounds), so the map is
//! unchanged in expectation and far less noisy. Point and spot lights send
//! their photons over all directions, as before.

use crate::math::Aabb;
use crate::shading::Material;
use crate::world::{MaterialId, Objects};

use super::bends_light;

/// True when a surface of `material` can mirror or bend a photon.
pub(super) fn starts_caustics(material: &Material) -> bool {
    !material.reflection.is_black() || (material.is_transmissive() && bends_light(material))
}

/// The box around every object whose material starts caustics; the box
/// around everything, `scene`, when one of them is unbounded (an infinite
/// mirror plane). Empty when there is none.
pub(super) fn caustic_bounds(objects: &Objects, materials: &[Material], scene: Aabb) -> Aabb {
    let starts = |id: MaterialId| materials.get(id.0 as usize).is_some_and(starts_caustics);
    let mut bounds = Aabb::EMPTY;
    for p in objects.primitives.iter().filter(|p| starts(p.material)) {
        let local = p.shape.bounds();
        let world = objects.bounds_to_world(p.transform, local);
        if !world.is_finite() {
            return scene;
        }
        bounds = bounds.union(&world);
    }
    for m in objects.mesh_instances.iter().filter(|m| starts(m.material)) {
        let mesh = &objects.meshes[m.mesh.0 as usize];
        let local = Aabb::from_points(mesh.positions().iter().copied());
        let world = objects.bounds_to_world(m.transform, local);
        bounds = bounds.union(&world);
    }
    bounds
}
