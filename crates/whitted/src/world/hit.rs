//! What a query reports: the small record kept during traversal ([`Hit`])
//! and the full world-space surface computed once for the final hit
//! ([`Surface`]).

use crate::math::{DVec2, Transform, Vec3};
use crate::shape::{LocalSurface, ShapeHit};
use crate::world::{MaterialId, PrimitiveId};

/// The closest hit found by [`crate::world::World::intersect`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The primitive's number in the whole world.
    pub primitive: PrimitiveId,
    /// What the shape recorded (its `t` is the ray parameter).
    pub shape_hit: ShapeHit,
}

impl Hit {
    /// The ray parameter of the hit.
    pub fn t(&self) -> f64 {
        self.shape_hit.t
    }
}

/// The surface at a hit, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// The hit point.
    pub point: Vec3,
    /// Absolute bound on the error of `point`, per axis.
    pub point_error: Vec3,
    /// Unit geometric normal, outward (not yet turned towards the ray).
    pub normal: Vec3,
    /// Unit normal for shading: the geometric one, or the one interpolated
    /// from a mesh's vertex normals.
    pub shading_normal: Vec3,
    /// Texture coordinates. With the tangents below, zero where
    /// [`crate::world::World::surface_for`] was told the material reads
    /// none of them.
    pub uv: DVec2,
    /// Derivative of the point along u (a tangent; not normalised).
    pub dpdu: Vec3,
    /// Derivative of the point along v (a tangent; not normalised).
    pub dpdv: Vec3,
    /// The surface's material.
    pub material: MaterialId,
    /// The material whose index of refraction fills the solid behind the
    /// surface, the key of the medium stack: the surface's own material,
    /// except on a CSG object, which is one medium whatever its children's
    /// materials ([`crate::shape::Csg::medium`]).
    pub medium: MaterialId,
}

impl Surface {
    pub(crate) fn from_local(
        s: LocalSurface,
        shading_normal: Vec3,
        material: MaterialId,
        medium: MaterialId,
    ) -> Self {
        Self {
            point: s.point,
            point_error: s.point_error,
            normal: s.normal,
            shading_normal,
            uv: s.uv,
            dpdu: s.dpdu,
            dpdv: s.dpdv,
            material,
            medium,
        }
    }

    /// The surface seen from the space `t` carries this one's into: the
    /// point with its error bound, the normals (renormalised) and the
    /// tangents carried by `t`; uv, material and medium unchanged.
    pub(crate) fn to_outer(self, t: &Transform) -> Self {
        let (point, point_error) = t.point_with_error_to_world(self.point, self.point_error);
        Self {
            point,
            point_error,
            normal: t.normal_to_world(self.normal).normalize(),
            shading_normal: t.normal_to_world(self.shading_normal).normalize(),
            uv: self.uv,
            dpdu: t.vector_to_world(self.dpdu),
            dpdv: t.vector_to_world(self.dpdv),
            material: self.material,
            medium: self.medium,
        }
    }
}
