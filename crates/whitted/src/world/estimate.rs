//! What a world of given objects will take, estimated before it is built,
//! so that the memory budget can refuse it first.

use super::entry::Entry;
use super::objects::{MeshInstance, Objects};
use crate::accel::AccelKind;
use crate::math::Aabb;
use crate::mesh::TriangleMesh;

/// What each slot of a level's structure takes besides the structure: its
/// entry and the box it is built from.
const SLOT_BYTES: u64 = (size_of::<Entry>() + size_of::<Aabb>()) as u64;

impl Objects {
    /// Per mesh of [`Objects::meshes`], how many mesh instances place it.
    pub(super) fn placements(&self) -> Vec<u32> {
        let mut placements = vec![0u32; self.meshes.len()];
        for m in &self.mesh_instances {
            placements[m.mesh.0 as usize] = placements[m.mesh.0 as usize].saturating_add(1);
        }
        placements
    }

    /// Whether the world keeps mesh instance `m` as an instance, given
    /// [`Objects::placements`]: a mesh placed more than once, or moved,
    /// gets a structure of its own; one placed once where it was modelled
    /// has its triangles in the level's structure.
    pub(super) fn kept_as_instance(m: &MeshInstance, placements: &[u32]) -> bool {
        m.transform.is_some() || placements[m.mesh.0 as usize] > 1
    }

    /// Per definition of [`Objects::definitions`], whether something
    /// placed places it: the world prepares those alone. A definition
    /// places only earlier ones, so one pass from the last finds them all.
    pub(super) fn placed_definitions(&self) -> Vec<bool> {
        let mut placed = vec![false; self.definitions.len()];
        for i in &self.instances {
            placed[i.definition.0 as usize] = true;
        }
        for d in (0..placed.len()).rev() {
            if placed[d] {
                for i in &self.definitions[d].instances {
                    placed[i.definition.0 as usize] = true;
                }
            }
        }
        placed
    }

    /// An estimate of the most bytes the objects and the world built from
    /// them take together, with structures of kind `top` at the top level
    /// and `bottom` below: the meshes' vertices and triangles, each
    /// level's entries and boxes, and each structure as
    /// [`AccelKind::bytes_per_primitive`] estimates it. Instances count
    /// once per definition or mesh, not per placement, as the world keeps
    /// them; a definition nothing places, only its meshes' data.
    /// Saturates rather than wrap.
    pub fn estimated_world_bytes(&self, top: AccelKind, bottom: AccelKind) -> u64 {
        self.definitions
            .iter()
            .zip(self.placed_definitions())
            .map(|(d, placed)| {
                if placed {
                    d.level_bytes(bottom, bottom)
                } else {
                    d.mesh_bytes()
                }
            })
            .fold(self.level_bytes(top, bottom), u64::saturating_add)
    }

    /// The bytes of this level's meshes' vertices and triangles.
    fn mesh_bytes(&self) -> u64 {
        self.meshes
            .iter()
            .map(TriangleMesh::heap_bytes)
            .fold(0, u64::saturating_add)
    }

    /// [`Objects::estimated_world_bytes`] of this level alone, its
    /// structure of kind `kind`, its meshes kept as instances under `bottom`.
    fn level_bytes(&self, kind: AccelKind, bottom: AccelKind) -> u64 {
        let placements = self.placements();
        let mut instanced = vec![false; self.meshes.len()];
        let mut slots = (self.primitives.len() + self.instances.len()) as u64;
        for m in &self.mesh_instances {
            let mesh = &self.meshes[m.mesh.0 as usize];
            if Self::kept_as_instance(m, &placements) {
                instanced[m.mesh.0 as usize] = true;
                slots = slots.saturating_add(1);
            } else {
                slots = slots.saturating_add(mesh.len() as u64);
            }
        }
        let mut instanced_triangles = 0u64;
        for (mesh, instanced) in self.meshes.iter().zip(instanced) {
            if instanced {
                instanced_triangles = instanced_triangles.saturating_add(mesh.len() as u64);
            }
        }
        let per_slot = |kind: AccelKind| SLOT_BYTES + kind.bytes_per_primitive();
        self.mesh_bytes()
            .saturating_add(slots.saturating_mul(per_slot(kind)))
            .saturating_add(instanced_triangles.saturating_mul(per_slot(bottom)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Transform, Vec3};
    use crate::shape::{Shape, Sphere};
    use crate::world::MaterialId;

    fn mesh(triangles: u32) -> TriangleMesh {
        let positions = (0..3 * triangles)
            .map(|i| Vec3::new(f64::from(i), f64::from(i % 7), 1.0))
            .collect();
        let faces = (0..triangles)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        TriangleMesh::new(positions, faces).unwrap()
    }

    #[test]
    fn a_mesh_placed_many_times_counts_once_and_its_placements_as_slots() {
        let per_slot = |kind: AccelKind| SLOT_BYTES + kind.bytes_per_primitive();
        let mut objects = Objects::default();
        let sphere = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap());
        objects.add_primitive(sphere, MaterialId(0), Transform::IDENTITY);
        let data = mesh(1000).heap_bytes();
        assert_eq!(data, 3000 * 24 + 1000 * 12);
        let once = objects.add_mesh(mesh(1000));
        objects.add_mesh_instance(once, MaterialId(0), Transform::IDENTITY);
        let (top, bottom) = (AccelKind::KdTree, AccelKind::Bvh);
        // Placed once where it was modelled: its triangles are slots.
        assert_eq!(
            objects.estimated_world_bytes(top, bottom),
            data + 1001 * per_slot(top)
        );
        // Placed a hundred more times, moved: one structure of its own under
        // `bottom`, and a slot a placement.
        for i in 0..100 {
            let moved = Transform::translate(Vec3::new(f64::from(i), 0.0, 0.0)).unwrap();
            objects.add_mesh_instance(once, MaterialId(0), moved);
        }
        assert_eq!(
            objects.estimated_world_bytes(top, bottom),
            data + 102 * per_slot(top) + 1000 * per_slot(bottom)
        );
    }

    #[test]
    fn definitions_count_once_under_the_bottom_kind_and_sums_saturate() {
        let per_slot = |kind: AccelKind| SLOT_BYTES + kind.bytes_per_primitive();
        let mut definition = Objects::default();
        let sphere = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap());
        for _ in 0..10 {
            definition.add_primitive(sphere.clone(), MaterialId(0), Transform::IDENTITY);
        }
        let mut objects = Objects::default();
        let id = objects.add_definition(definition);
        for _ in 0..50 {
            objects.add_instance(id, None, Transform::IDENTITY);
        }
        assert_eq!(
            objects.estimated_world_bytes(AccelKind::Grid, AccelKind::Linear),
            50 * per_slot(AccelKind::Grid) + 10 * per_slot(AccelKind::Linear)
        );
        // A definition nothing places adds its meshes' data alone.
        let mut unplaced = Objects::default();
        let model = unplaced.add_mesh(mesh(100));
        unplaced.add_mesh_instance(model, MaterialId(0), Transform::IDENTITY);
        objects.add_definition(unplaced);
        assert_eq!(
            objects.estimated_world_bytes(AccelKind::Grid, AccelKind::Linear),
            50 * per_slot(AccelKind::Grid)
                + 10 * per_slot(AccelKind::Linear)
                + mesh(100).heap_bytes()
        );
    }
}
