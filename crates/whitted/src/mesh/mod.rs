//! Triangle meshes: vertices stored once and shared by their triangles.

pub mod triangle_mesh;

pub use triangle_mesh::{MeshError, MeshSurface, TriangleMesh};
