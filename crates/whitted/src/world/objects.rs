//! What a scene places in the world, before anything is prepared for ray
//! queries: shapes, mesh instances and instances of definitions, each with
//! a material id and an optional transform, and the tables they index
//! (meshes, transforms, definitions). [`crate::world::World`] is built
//! from it.
//!
//! A definition is itself an [`Objects`] (shapes, meshes and instances of
//! earlier definitions) that is not drawn by itself: only its instances
//! are. Definitions live in the world's table alone, and an instance inside
//! definition `d` may only name a definition before `d`, so there can be no
//! cycle; instances nest at most [`MAX_INSTANCE_DEPTH`] deep.

use crate::math::{Aabb, Transform};
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

/// Index of a definition in the world's [`Objects::definitions`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DefinitionId(pub u32);

/// The deepest instances nest: an instance at the top is at depth 1, one in
/// its definition at depth 2, and so on.
pub const MAX_INSTANCE_DEPTH: usize = 8;

/// A definition placed in the world (or in another definition).
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// The definition placed, in the world's [`Objects::definitions`].
    pub definition: DefinitionId,
    /// A material for every surface of the definition, in place of their
    /// own; `None` keeps theirs. The outermost override wins.
    pub material: Option<MaterialId>,
    /// Where the definition's space sits in the placing space; `None` means
    /// they coincide.
    pub transform: Option<TransformId>,
}

/// Why [`Objects::check_instances`] refuses a world's instances.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum InstanceError {
    /// An instance names a definition that does not exist, or (inside a
    /// definition) one that is not before it.
    #[error(
        "definition {within} places definition {named}, which is not one before it \
         (the world has {count} definitions)"
    )]
    BadDefinition {
        /// The definition holding the instance; `count` for the top level.
        within: usize,
        /// The definition named.
        named: usize,
        /// How many definitions there are.
        count: usize,
    },
    /// A definition has definitions of its own.
    #[error("definition {0} has definitions of its own; only the world's table is used")]
    NestedTable(usize),
    /// Instances nest too deep.
    #[error("instances nest {depth} deep; at most {MAX_INSTANCE_DEPTH} are allowed")]
    TooDeep {
        /// The depth reached.
        depth: usize,
    },
}

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
    /// Definitions, indexed by [`DefinitionId`]: the world's table (a
    /// definition's own is empty).
    pub definitions: Vec<Objects>,
    /// Definitions placed here.
    pub instances: Vec<Instance>,
}

impl Objects {
    /// How many primitives there are: the shapes, the triangles of every
    /// mesh instance and the primitives of every instance of a definition,
    /// counted once per placement (a definition naming one not before it
    /// counts it as empty: see [`Self::check_instances`]); `usize::MAX`
    /// where the count does not fit in a `usize` (nested placements
    /// multiply), far more than a world numbers
    /// ([`crate::world::MAX_PRIMITIVES`]).
    pub fn primitive_count(&self) -> usize {
        self.checked_primitive_count().unwrap_or(usize::MAX)
    }

    /// [`Self::primitive_count`], `None` where it does not fit in a
    /// `usize`: every sum and product checked.
    pub fn checked_primitive_count(&self) -> Option<usize> {
        let mut counts = Vec::with_capacity(self.definitions.len());
        for definition in &self.definitions {
            let count = definition.count_with(&counts);
            counts.push(count);
        }
        self.count_with(&counts)
    }

    /// The primitives here, given those of the definitions before (`None`
    /// for a count that overflowed).
    fn count_with(&self, definitions: &[Option<usize>]) -> Option<usize> {
        let mut count = self.primitives.len();
        for m in &self.mesh_instances {
            count = count.checked_add(self.meshes[m.mesh.0 as usize].len())?;
        }
        for i in &self.instances {
            // A definition not before this one counts as empty.
            let placed = definitions.get(i.definition.0 as usize).copied();
            count = count.checked_add(placed.unwrap_or(Some(0))?)?;
        }
        Some(count)
    }

    /// Checks what [`crate::world::World::build`] relies on: every instance
    /// names a definition of the world's table (inside a definition, one
    /// before it), definitions have no tables of their own, and instances
    /// nest at most [`MAX_INSTANCE_DEPTH`] deep.
    pub fn check_instances(&self) -> Result<(), InstanceError> {
        let count = self.definitions.len();
        // How deep each definition's own instances nest (0: none).
        let mut nesting: Vec<usize> = Vec::with_capacity(count);
        for (d, definition) in self.definitions.iter().enumerate() {
            if !definition.definitions.is_empty() {
                return Err(InstanceError::NestedTable(d));
            }
            nesting.push(Self::nesting(&definition.instances, &nesting, d, count)?);
        }
        let depth = Self::nesting(&self.instances, &nesting, count, count)?;
        if depth > MAX_INSTANCE_DEPTH {
            return Err(InstanceError::TooDeep { depth });
        }
        Ok(())
    }

    /// How deep `instances` nest, given how deep the definitions before
    /// `within` do.
    fn nesting(
        instances: &[Instance],
        nesting: &[usize],
        within: usize,
        count: usize,
    ) -> Result<usize, InstanceError> {
        instances.iter().try_fold(0, |deepest, i| {
            let named = i.definition.0 as usize;
            match nesting.get(named) {
                Some(depth) if named < within => Ok(deepest.max(depth + 1)),
                _ => Err(InstanceError::BadDefinition {
                    within,
                    named,
                    count,
                }),
            }
        })
    }

    /// The transform `id` names, `None` for none.
    pub fn transform(&self, id: Option<TransformId>) -> Option<&Transform> {
        id.map(|id| &self.transforms[id.0 as usize])
    }

    /// The world-space box around `local`, a box in the space that
    /// transform `id` places (`None`: the world's own).
    pub fn bounds_to_world(&self, id: Option<TransformId>, local: Aabb) -> Aabb {
        self.transform(id)
            .map_or(local, |t| t.bounds_to_world(&local))
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

    /// Adds a definition (place it with [`Objects::add_instance`]) and
    /// returns its id.
    pub fn add_definition(&mut self, definition: Objects) -> DefinitionId {
        self.definitions.push(definition);
        DefinitionId((self.definitions.len() - 1) as u32)
    }

    /// Places a definition with a transform and, if `material` is given, a
    /// material for all its surfaces.
    pub fn add_instance(
        &mut self,
        definition: DefinitionId,
        material: Option<MaterialId>,
        transform: Transform,
    ) {
        let transform = self.add_transform(transform);
        self.instances.push(Instance {
            definition,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::shape::Sphere;

    fn sphere() -> Objects {
        let mut o = Objects::default();
        let s = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap());
        o.add_primitive(s, MaterialId(0), Transform::IDENTITY);
        o
    }

    #[test]
    fn instances_count_their_definitions_primitives_once_per_placement() {
        let mut world = sphere();
        let ball = world.add_definition(sphere());
        let mut pair = Objects::default();
        pair.add_instance(ball, None, Transform::IDENTITY);
        pair.add_instance(ball, Some(MaterialId(1)), Transform::IDENTITY);
        let pair = world.add_definition(pair);
        for _ in 0..3 {
            world.add_instance(pair, None, Transform::IDENTITY);
        }
        assert_eq!(world.primitive_count(), 1 + 3 * 2);
        assert_eq!(world.check_instances(), Ok(()));
    }

    #[test]
    fn a_count_past_the_range_of_usize_is_none_not_wrapped() {
        // Seven definitions each placing the one before 256 times, placed
        // 256 times: 256⁸ = 2⁶⁴ spheres, one more than a `usize` holds; the
        // sphere beside them took a wrapping sum to 0.
        let mut world = sphere();
        let mut inner = world.add_definition(sphere());
        for _ in 1..8 {
            let mut many = Objects::default();
            for _ in 0..256 {
                many.add_instance(inner, None, Transform::IDENTITY);
            }
            inner = world.add_definition(many);
        }
        let mut top = world.clone();
        for _ in 0..256 {
            top.add_instance(inner, None, Transform::IDENTITY);
        }
        assert_eq!(top.checked_primitive_count(), None);
        assert_eq!(top.primitive_count(), usize::MAX);
        // One placement fewer fits: 255 · 2⁵⁶ + 1.
        let mut fits = world;
        for _ in 0..255 {
            fits.add_instance(inner, None, Transform::IDENTITY);
        }
        assert_eq!(fits.checked_primitive_count(), Some(255 * (1 << 56) + 1));
    }

    #[test]
    fn forward_references_nested_tables_and_deep_nesting_are_refused() {
        let mut world = Objects::default();
        let mut early = Objects::default();
        early.add_instance(DefinitionId(1), None, Transform::IDENTITY);
        world.add_definition(early);
        world.add_definition(sphere());
        let bad = InstanceError::BadDefinition {
            within: 0,
            named: 1,
            count: 2,
        };
        assert_eq!(world.check_instances(), Err(bad));

        let mut world = Objects::default();
        world.add_instance(DefinitionId(0), None, Transform::IDENTITY);
        assert!(matches!(
            world.check_instances(),
            Err(InstanceError::BadDefinition { named: 0, .. })
        ));

        let mut world = Objects::default();
        let mut nested = sphere();
        nested.add_definition(sphere());
        world.add_definition(nested);
        assert_eq!(world.check_instances(), Err(InstanceError::NestedTable(0)));

        let mut world = Objects::default();
        let mut last = world.add_definition(sphere());
        for _ in 1..MAX_INSTANCE_DEPTH {
            let mut next = Objects::default();
            next.add_instance(last, None, Transform::IDENTITY);
            last = world.add_definition(next);
        }
        world.add_instance(last, None, Transform::IDENTITY);
        assert_eq!(world.check_instances(), Ok(()));
        let mut deeper = Objects::default();
        deeper.add_instance(last, None, Transform::IDENTITY);
        let deeper = world.add_definition(deeper);
        world.add_instance(deeper, None, Transform::IDENTITY);
        let depth = MAX_INSTANCE_DEPTH + 1;
        assert_eq!(
            world.check_instances(),
            Err(InstanceError::TooDeep { depth })
        );
    }
}
