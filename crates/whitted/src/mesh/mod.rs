//! Triangle meshes: vertices stored once and shared by their triangles,
//! and the triangulation of polygons into them.

pub mod even_odd;
pub mod triangle_mesh;
pub mod triangulate;

pub use even_odd::{Corner, triangulate_even_odd};
pub use triangle_mesh::{MeshError, MeshSurface, TriangleMesh};
pub use triangulate::{newell_normal, triangulate};
