//! The shadow cache: per thread and per light, the entry that blocked the
//! last shadow ray is tried first ([`crate::world::ShadowHint`]). The
//! answers are the any-hit query's, so the picture does not depend on which
//! thread traced what before.

use std::cell::Cell;

use crate::math::Ray;
use crate::world::{OpaqueEntries, ShadowHint, ShadowPath, World};

/// Lights with a hint of their own; shadow rays towards the others take the
/// plain query.
const CACHED_LIGHTS: usize = 16;

thread_local! {
    static HINTS: [Cell<ShadowHint>; CACHED_LIGHTS] =
        const { [const { Cell::new(ShadowHint::NONE) }; CACHED_LIGHTS] };
}

/// True when something in `world` blocks `ray`, a shadow ray towards light
/// number `light`.
pub(super) fn occluded(world: &World<'_>, ray: &Ray, light: usize) -> bool {
    if light >= CACHED_LIGHTS {
        return world.occluded(ray);
    }
    with_hint(light, |hint| world.occluded_hinted(ray, hint))
}

/// What lies along `ray`, a shadow ray towards light number `light`, in a
/// world where some surfaces let light through ([`World::shadow_path`]).
pub(super) fn shadow_path(
    world: &World<'_>,
    ray: &Ray,
    opaque: &OpaqueEntries,
    light: usize,
) -> ShadowPath {
    if light >= CACHED_LIGHTS {
        return world.shadow_path(ray, opaque, &mut ShadowHint::default());
    }
    with_hint(light, |hint| world.shadow_path(ray, opaque, hint))
}

/// `query` given this thread's hint for light `light` (below
/// [`CACHED_LIGHTS`]), keeping the hint it leaves.
fn with_hint<T>(light: usize, query: impl FnOnce(&mut ShadowHint) -> T) -> T {
    HINTS.with(|hints| {
        let mut hint = hints[light].get();
        let answer = query(&mut hint);
        hints[light].set(hint);
        answer
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::math::{Transform, Vec3};
    use crate::mesh::TriangleMesh;
    use crate::shape::{Shape, Sphere};
    use crate::world::{MaterialId, Objects};

    #[test]
    fn hinted_shadow_rays_answer_as_the_plain_query() {
        let mut rng = Rng::new(7);
        let mut objects = Objects::default();
        for _ in 0..200 {
            let centre = 10.0 * (rng.unit_vector() * rng.uniform());
            let sphere = Sphere::new(centre, 0.2 + rng.uniform()).unwrap();
            objects.add_primitive(Shape::Sphere(sphere), MaterialId(0), Transform::IDENTITY);
        }
        // A mesh of scattered small triangles: entries tested in the world's
        // leaves, several at once where the processor has AVX.
        let mut positions = Vec::new();
        for _ in 0..300 {
            let corner = 10.0 * (rng.unit_vector() * rng.uniform());
            positions.extend([
                corner,
                corner + rng.unit_vector(),
                corner + rng.unit_vector(),
            ]);
        }
        let triangles = (0..300).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let mesh = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
        objects.add_mesh_instance(mesh, MaterialId(0), Transform::IDENTITY);
        let world = World::new(&objects);
        let light = Vec3::new(3.0, 20.0, -4.0);
        let mut blocked = 0;
        for _ in 0..2000 {
            let from = 12.0 * rng.unit_vector() * rng.uniform();
            let to_light = (light - from).normalize();
            let ray = Ray::segment(from, to_light, (light - from).length());
            let expected = world.occluded(&ray);
            assert_eq!(occluded(&world, &ray, 0), expected);
            assert_eq!(occluded(&world, &ray, 99), expected);
            blocked += usize::from(expected);
        }
        assert!(blocked > 200 && blocked < 1800, "{blocked} of 2000 blocked");
    }
}
