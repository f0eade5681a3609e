//! Shadow rays in worlds where some surfaces let light through. The
//! integrator must then walk such a ray from surface to surface, scaling
//! the light at each crossing; but most shadow rays meet an opaque surface
//! or nothing at all, and one any-hit walk tells those apart: it stops at
//! the first entry whose material lets nothing through, and only notes the
//! others. Only a ray that crosses such surfaces and nothing opaque needs
//! the surface-to-surface walk.

use crate::accel::{AccelerationStructure, QueryContext};
use crate::math::Ray;
use crate::shape::Shape;
use crate::world::entry::{Entry, EntryKind, Query, leaf_meets};
use crate::world::{MaterialId, PrimitiveRef, ShadowHint, World};

/// Which of a world's entries stop light: those every hit of which shows a
/// material that lets nothing through ([`World::opaque_entries`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OpaqueEntries {
    /// Per entry of the structure, in the world's entry order.
    entries: Vec<bool>,
    /// Per unbounded entry.
    unbounded: Vec<bool>,
}

/// What lies along a shadow ray's interval ([`World::shadow_path`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowPath {
    /// Nothing: all the light arrives.
    Clear,
    /// Something opaque: no light arrives, whatever else lies in the way.
    Blocked,
    /// Only surfaces that may let light through: the light that arrives is
    /// what each lets through, found by walking from one to the next.
    Crossed,
}

impl World<'_> {
    /// Which entries stop light, given which materials let nothing through
    /// (`opaque`, by material id): an entry does when every hit on it shows
    /// one such material (a shape's own or a placed mesh's). A CSG object,
    /// whose children may show other materials, counts as letting light
    /// through. `None` for a world with instances, whose materials an
    /// enclosing instance may replace: its shadow rays take the
    /// surface-to-surface walk.
    pub fn opaque_entries(&self, opaque: &[bool]) -> Option<OpaqueEntries> {
        if self.instance_count != 0 {
            return None;
        }
        let stops = |e: &Entry| {
            self.entry_material(e)
                .is_some_and(|m| opaque.get(m.0 as usize) == Some(&true))
        };
        Some(OpaqueEntries {
            entries: self.entries.iter().map(stops).collect(),
            unbounded: self.unbounded.iter().map(stops).collect(),
        })
    }

    /// The one material every hit on entry `e` shows, if there is one.
    fn entry_material(&self, e: &Entry) -> Option<MaterialId> {
        if !matches!(
            e.kind,
            EntryKind::Triangle
                | EntryKind::Sphere
                | EntryKind::Polygon
                | EntryKind::Axial
                | EntryKind::Primitive
        ) {
            return None;
        }
        match self.primitive_ref(e.number) {
            PrimitiveRef::Shape(i) => {
                let p = &self.objects.primitives[i as usize];
                (!matches!(p.shape, Shape::Csg(_))).then_some(p.material)
            }
            PrimitiveRef::Triangle { instance, .. } => {
                Some(self.objects.mesh_instances[instance as usize].material)
            }
            PrimitiveRef::Placed { .. } => None,
        }
    }

    /// What lies in `ray`'s interval, told apart by `opaque` (this world's
    /// [`World::opaque_entries`]): [`ShadowPath::Blocked`] as soon as an
    /// entry that stops light is found, [`ShadowPath::Crossed`] when only
    /// others are, [`ShadowPath::Clear`] when nothing is, as
    /// [`World::occluded`] would say of the same ray. The entry in `hint`
    /// is tried first (the shadow cache, as [`World::occluded_hinted`]
    /// uses it), and the entry that blocked is left in it.
    pub fn shadow_path(
        &self,
        ray: &Ray,
        opaque: &OpaqueEntries,
        hint: &mut ShadowHint,
    ) -> ShadowPath {
        let query = Query::new(ray, self.has_triangles);
        // A hint left by another query may name any entry: only one that
        // stops light can answer for the walk.
        if opaque.entries.get(hint.0 as usize) == Some(&true) && self.hint_blocks(*hint, &query) {
            return ShadowPath::Blocked;
        }
        *hint = ShadowHint::NONE;
        let mut crossed = false;
        for (e, &stops) in self.unbounded.iter().zip(&opaque.unbounded) {
            if self.shape_occludes(e.number, &query) {
                if stops {
                    return ShadowPath::Blocked;
                }
                crossed = true;
            }
        }
        let mut ctx = QueryContext::default();
        let blocked = self.accel.occluded_in_leaf_order(ray, &mut ctx, |range| {
            let blocker = leaf_meets(
                &self.entries,
                range,
                &query,
                self.wide,
                |e| self.shape_occludes(e.number, &query),
                |entry| {
                    crossed |= !opaque.entries[entry as usize];
                    opaque.entries[entry as usize]
                },
            );
            if let Some(entry) = blocker {
                *hint = ShadowHint(entry);
            }
            blocker.is_some()
        });
        if blocked {
            ShadowPath::Blocked
        } else if crossed {
            ShadowPath::Crossed
        } else {
            ShadowPath::Clear
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::math::random::Rng;
    use crate::math::{Transform, Vec3};
    use crate::mesh::TriangleMesh;
    use crate::shape::{Plane, Sphere};
    use crate::world::Objects;

    /// Spheres of two materials (0 opaque, 1 clear), a mesh of scattered
    /// triangles of each, and a plane of the clear one.
    fn mixed_scene(rng: &mut Rng) -> Objects {
        let mut objects = Objects::default();
        for i in 0..150 {
            let centre = 10.0 * (rng.unit_vector() * rng.uniform());
            let sphere = Sphere::new(centre, 0.2 + 0.8 * rng.uniform()).unwrap();
            objects.add_primitive(
                Shape::Sphere(sphere),
                MaterialId(i % 2),
                Transform::IDENTITY,
            );
        }
        for material in 0..2 {
            let mut positions = Vec::new();
            for _ in 0..200 {
                let corner = 10.0 * (rng.unit_vector() * rng.uniform());
                positions.extend([
                    corner,
                    corner + rng.unit_vector(),
                    corner + rng.unit_vector(),
                ]);
            }
            let triangles = (0..200).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
            let mesh = objects.add_mesh(TriangleMesh::new(positions, triangles).unwrap());
            objects.add_mesh_instance(mesh, MaterialId(material), Transform::IDENTITY);
        }
        let floor = Plane::new(Vec3::new(0.0, -11.0, 0.0), Vec3::Y).unwrap();
        objects.add_primitive(Shape::Plane(floor), MaterialId(1), Transform::IDENTITY);
        objects
    }

    /// What the surface-to-surface walk finds along `ray`: every surface
    /// in its interval, in order, by its material.
    fn walk(world: &World<'_>, ray: &Ray) -> ShadowPath {
        let mut ray = *ray;
        let mut crossed = false;
        while let Some(hit) = world.intersect(&ray) {
            let material = world.surface(&ray, &hit).material;
            if material == MaterialId(0) {
                return ShadowPath::Blocked;
            }
            crossed = true;
            ray.t_min = hit.shape_hit.t;
        }
        if crossed {
            ShadowPath::Crossed
        } else {
            ShadowPath::Clear
        }
    }

    #[test]
    fn the_any_hit_walk_tells_blocked_crossed_and_clear_as_the_surface_walk_does() {
        let mut rng = Rng::new(11);
        let objects = mixed_scene(&mut rng);
        for kind in [
            AccelKind::Bvh,
            AccelKind::KdTree,
            AccelKind::Grid,
            AccelKind::Linear,
        ] {
            let world = World::build(&objects, kind);
            let opaque = world.opaque_entries(&[true, false]).unwrap();
            let mut seen = [0; 3];
            let mut hint = ShadowHint::NONE;
            for _ in 0..1500 {
                let from = 12.0 * rng.unit_vector() * rng.uniform();
                let light = Vec3::new(3.0, 20.0, -4.0) + 4.0 * rng.unit_vector();
                let ray = Ray::segment(from, (light - from).normalize(), (light - from).length());
                let path = world.shadow_path(&ray, &opaque, &mut ShadowHint::default());
                assert_eq!(world.shadow_path(&ray, &opaque, &mut hint), path, "hinted");
                assert_eq!(path, walk(&world, &ray), "{kind:?} {ray:?}");
                assert_eq!(path != ShadowPath::Clear, world.occluded(&ray), "{kind:?}");
                seen[path as usize] += 1;
            }
            assert!(seen.iter().all(|&n| n > 100), "{kind:?}: {seen:?}");
        }
    }

    #[test]
    fn with_every_material_clear_nothing_blocks() {
        let mut rng = Rng::new(12);
        let objects = mixed_scene(&mut rng);
        let world = World::new(&objects);
        let opaque = world.opaque_entries(&[false, false]).unwrap();
        let ray = Ray::segment(Vec3::new(0.0, -30.0, 0.0), Vec3::Y, 60.0);
        assert_eq!(
            world.shadow_path(&ray, &opaque, &mut ShadowHint::default()),
            ShadowPath::Crossed
        );
        let all = world.opaque_entries(&[true, true]).unwrap();
        assert_eq!(
            world.shadow_path(&ray, &all, &mut ShadowHint::default()),
            ShadowPath::Blocked
        );
        let away = Ray::segment(Vec3::new(0.0, 40.0, 0.0), Vec3::Y, 10.0);
        assert_eq!(
            world.shadow_path(&away, &all, &mut ShadowHint::default()),
            ShadowPath::Clear
        );
    }
}
