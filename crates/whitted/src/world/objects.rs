//! What a scene places in the world, before anything is prepared for ray
//! queries: shapes and mesh instances, each with a material id and an
//! optional transform, and the tables they index (meshes, transforms).
//! [`crate::world::World`] is built from it.

use crate::math::Transform;
use crate::mesh::TriangleMesh;
use crate::shape::Shape;

/// Index of a material in the scene's material table. The world only
/// carries it to the surfaces it reports; shading looks it up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);

/// A primitive's number in the whole world: the shapes of
/// [`Objects::primitives`] first, then each mesh instance's triangles, in
/// order. What a hit reports and the `id` AOV shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PrimitiveId(pub u32);

/// Index of a transform in [`Objects::transforms`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TransformId(pub u32);

/// Index of a mesh in [`Objects::meshes`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(pub u32);

/// A shape placed in the world with a material.
#[derive(Clone, Debug, PartialEq)]
pub struct Primitive {
    /// The geometry, in object space.
    pub shape: Shape,
    /// What its surface is made of.
    pub material: MaterialId,
    /// Where object space sits in the world; `None` means they coincide.
    pub transform: Option<TransformId>,
}

/// A triangle mesh placed in the world with a material. One mesh may be
/// placed many times.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshInstance {
    /// The mesh, in [`Objects::meshes`].
    pub mesh: MeshId,
    /// What its surface is made of.
    pub material: MaterialId,
    /// Where the mesh's space sits in the world; `None` means they coincide.
    pub transform: Option<TransformId>,
}

/// Everything a scene places in the world.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Objects {
    /// Object-to-world transforms, indexed by [`TransformId`].
    pub transforms: Vec<Transform>,
    /// The shapes.
    pub primitives: Vec<Primitive>,
    /// Triangle meshes, indexed by [`MeshId`].
    pub meshes: Vec<TriangleMesh>,
    /// Meshes placed in the world.
    pub mesh_instances: Vec<MeshInstance>,
}

impl Objects {
    /// How many primitives there are: the shapes and the triangles of every
    /// mesh instance.
    pub fn primitive_count(&self) -> usize {
        self.primitives.len()
            + self
                .mesh_instances
                .iter()
                .map(|m| self.meshes[m.mesh.0 as usize].len())
                .sum::<usize>()
    }

    /// The transform `id` names, `None` for none.
    pub fn transform(&self, id: Option<TransformId>) -> Option<&Transform> {
        id.map(|id| &self.transforms[id.0 as usize])
    }

    /// Stores a transform, or nothing for the identity.
    pub fn add_transform(&mut self, transform: Transform) -> Option<TransformId> {
        (!transform.is_identity()).then(|| {
            self.transforms.push(transform);
            TransformId((self.transforms.len() - 1) as u32)
        })
    }

    /// Adds a mesh and returns its id (place it with
    /// [`Objects::add_mesh_instance`]).
    pub fn add_mesh(&mut self, mesh: TriangleMesh) -> MeshId {
        self.meshes.push(mesh);
        MeshId((self.meshes.len() - 1) as u32)
    }

    /// Places a mesh in the world with a material and a transform.
    pub fn add_mesh_instance(&mut self, mesh: MeshId, material: MaterialId, transform: Transform) {
        let transform = self.add_transform(transform);
        self.mesh_instances.push(MeshInstance {
            mesh,
            material,
            transform,
        });
    }

    /// Adds a shape with a material and an object-to-world transform (the
    /// identity is stored as no transform at all).
    pub fn add_primitive(&mut self, shape: Shape, material: MaterialId, transform: Transform) {
        let transform = self.add_transform(transform);
        self.primitives.push(Primitive {
            shape,
            material,
            transform,
        });
    }
}
