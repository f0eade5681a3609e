//! Triangle meshes and their importers.

pub mod obj_positions;

pub use obj_positions::{TriangleSoup, load_obj_positions, parse_obj_positions};
