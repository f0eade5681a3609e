//! Loading what the surfaces of hits will read before they are shaded,
//! where that is likely a cache miss: the triangles of meshes too big for
//! the caches (docs/performance-log.md, big meshes' surfaces prefetched).

use crate::mesh::TriangleMesh;
use crate::world::{Hit, PrimitiveRef, World};

/// Triangles placed directly from which [`World::prefetches_surfaces`]:
/// about 8 MB of corner indices, positions and normals, beyond the caches.
/// Below it the prefetch's own work costs more than the misses it saves
/// (measured: docs/performance-log.md, big meshes' surfaces prefetched).
pub(super) const BIG_MESHES: usize = 200_000;

impl World<'_> {
    /// Whether prefetching the surfaces of hits pays
    /// ([`World::prefetch_surface_start`]): only with meshes too big for
    /// the caches.
    pub fn prefetches_surfaces(&self) -> bool {
        self.big_meshes
    }

    /// Starts loading the first data [`World::surface`] will read for
    /// `hit`, where that is likely a cache miss (a mesh triangle's corner
    /// indices); [`World::prefetch_surface`] goes on from there.
    #[inline]
    pub fn prefetch_surface_start(&self, hit: &Hit) {
        if let Some((mesh, triangle)) = self.mesh_triangle(hit) {
            mesh.prefetch_indices(triangle);
        }
    }

    /// Starts loading the rest of what [`World::surface`] will read for
    /// `hit` (a mesh triangle's corners).
    #[inline]
    pub fn prefetch_surface(&self, hit: &Hit) {
        if let Some((mesh, triangle)) = self.mesh_triangle(hit) {
            mesh.prefetch_corners(triangle);
        }
    }

    /// The mesh and triangle number of a hit on a triangle of a mesh
    /// placed directly.
    #[inline]
    fn mesh_triangle(&self, hit: &Hit) -> Option<(&TriangleMesh, u32)> {
        match self.primitive_ref(hit.primitive.0) {
            PrimitiveRef::Triangle { instance, triangle } => {
                let m = &self.objects.mesh_instances[instance as usize];
                Some((&self.objects.meshes[m.mesh.0 as usize], triangle))
            }
            _ => None,
        }
    }
}
