//! `shape = "patches"`: every Bézier patch of a `.bpt` file, each piece of
//! each patch ([`BezierPatch::pieces`]) its own primitive with the object's
//! material and transform, so the patches share the scene's acceleration
//! structure like a mesh's triangles.
//!
//! ```toml
//! [[objects]]
//! shape = "patches"
//! file = "teapot.bpt"     # relative to the scene file
//! material = "glass"
//! transform = { rotate = { axis = [1, 0, 0], angle = -90 } }
//! ```
//!
//! The file's own errors are reported at `file`, each with its own place
//! in the `.bpt` file.

use super::reader::{Fields, Parsed, Reader};
use crate::scene::{SceneError, load_bpt_patches};
use crate::shape::{BezierPatch, Shape};

/// The value of `shape` that reads a file of patches.
pub(super) const KIND: &str = "patches";

/// Its keys, besides `shape`, `material` and `transform`.
pub(super) const KEYS: &[&str] = &["file"];

/// The patches of the file named by `file`, as shapes.
pub(super) fn read(r: &mut Reader<'_>, f: &Fields<'_, '_>) -> Parsed<Vec<Shape>> {
    let (name, span) = r.require(f, "file", Reader::string)?;
    let path = r.beside(name);
    let patches = load_bpt_patches(&path).map_err(|error| {
        let message = match error {
            SceneError::Invalid { diagnostics } => {
                let lines: Vec<String> = diagnostics.iter().map(|d| d.to_string()).collect();
                format!("the patches in `{name}` are invalid:\n{}", lines.join("\n"))
            }
            other => other.to_string(),
        };
        r.error(span, message)
    })?;
    Ok(patches
        .iter()
        .flat_map(BezierPatch::pieces)
        .map(Shape::BezierPatch)
        .collect())
}
