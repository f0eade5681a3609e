//! Triangle meshes: vertices stored once and shared by their triangles,
//! and the triangulation of polygons into them.

pub mod triangle_mesh;
pub mod triangulate;

pub use triangle_mesh::{MeshError, MeshSurface, TriangleMesh};
pub use triangulate::{newell_normal, triangulate};
