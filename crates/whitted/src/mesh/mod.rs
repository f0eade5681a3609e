//! Triangle meshes and their importers.

pub mod obj_positions;
pub mod triangle_mesh;

pub use obj_positions::{TriangleSoup, load_obj_positions, parse_obj_positions};
pub use triangle_mesh::{MeshError, MeshId, MeshSurface, TriangleMesh};
