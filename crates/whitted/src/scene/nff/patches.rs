//! The `pp` entity: a flat polygon whose vertices carry shading normals.
//!
//! ```text
//! pp N
//!   x1 y1 z1 nx1 ny1 nz1
//!   ...
//!   xN yN zN nxN nyN nzN
//! ```
//!
//! Patches are read in full, positions and normals both checked, and kept
//! apart from the other shapes in a [`PatchSet`]. [`patches_to_shapes`] then
//! turns them into flat triangles (or polygons): flat shading until meshes
//! with vertex normals exist, when that one function becomes a mesh.

use std::ops::Range;

use super::reader::{Parsed, Reader};
use super::shapes::{flat_shape, vertex_count};
use crate::material::MaterialId;
use crate::math::Vec3;
use crate::shape::{Shape, ShapeError};

/// One `pp` entity.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Patch {
    /// Vertex positions, in order (three in every SPD file).
    pub(super) positions: Vec<Vec3>,
    /// The shading normal at each vertex, as written (not zero, not
    /// normalised).
    pub(super) normals: Vec<Vec3>,
    /// The material current when it was read.
    pub(super) material: MaterialId,
    /// Its bytes in the file, for messages.
    pub(super) span: Range<usize>,
}

/// Every patch of a file, in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct PatchSet {
    /// The patches.
    pub(super) patches: Vec<Patch>,
}

/// Reads a `pp` entity; `at` is the span of its keyword.
pub(super) fn read_patch(
    r: &mut Reader<'_>,
    at: Range<usize>,
    material: MaterialId,
) -> Parsed<Patch> {
    let count = vertex_count(r, "patch")?;
    let capacity = count.min(1024) as usize;
    let mut positions = Vec::with_capacity(capacity);
    let mut normals = Vec::with_capacity(capacity);
    for i in 1..=count {
        positions.push(r.vec3(&format!("the patch's vertex {i}"))?);
        let start = r.next_start();
        let normal = r.vec3(&format!("the patch's normal {i}"))?;
        if normal == Vec3::ZERO {
            let span = r.since(start);
            return Err(r.error(span, format!("the patch's normal {i} is zero")));
        }
        normals.push(normal);
    }
    Ok(Patch {
        positions,
        normals,
        material,
        span: r.since(at.start),
    })
}

/// Flat shading until meshes with vertex normals exist: each patch becomes
/// the flat shape of its positions (a triangle, or a polygon past three
/// vertices), its normals unused. With the patch it came from, for the
/// material and for locating a refusal.
pub(super) fn patches_to_shapes(
    set: &PatchSet,
) -> impl Iterator<Item = (&Patch, Result<Shape, ShapeError>)> {
    set.patches
        .iter()
        .map(|patch| (patch, flat_shape(patch.positions.clone())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn patch(text: &str) -> Result<Patch, Vec<String>> {
        let mut r = Reader::new(text, Path::new("t.nff"));
        let keyword = r.next_token().unwrap();
        read_patch(&mut r, keyword.span, MaterialId(2)).map_err(|_| {
            r.into_diagnostics()
                .into_iter()
                .map(|d| d.message)
                .collect()
        })
    }

    #[test]
    fn a_patch_keeps_positions_normals_and_material() {
        let p = patch("pp 3\n0 0 0 0 0 1\n1 0 0 0 0.5 1\n0 1 0 0 0 2\n").unwrap();
        assert_eq!(p.positions, [Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(p.normals[1], Vec3::new(0.0, 0.5, 1.0));
        assert_eq!(p.material, MaterialId(2));
        assert_eq!(p.span, 0..42);
    }

    #[test]
    fn patches_become_flat_triangles() {
        let set = PatchSet {
            patches: vec![patch("pp 3 0 0 0 0 0 1 1 0 0 0 0 1 0 1 0 0 0 1").unwrap()],
        };
        let shapes: Vec<_> = patches_to_shapes(&set).collect();
        assert_eq!(shapes.len(), 1);
        let Ok(Shape::Triangle(triangle)) = &shapes[0].1 else {
            panic!("{:?}", shapes[0].1);
        };
        assert_eq!(triangle.vertices(), [Vec3::ZERO, Vec3::X, Vec3::Y]);
    }

    #[test]
    fn normals_are_checked_like_positions() {
        assert_eq!(
            patch("pp 3 0 0 0 0 0 1 1 0 0 0 0 0 0 1 0 0 0 1").unwrap_err(),
            ["the patch's normal 2 is zero"]
        );
        assert_eq!(
            patch("pp 3 0 0 0 0 0 1 1 0 0 0 x 1").unwrap_err(),
            ["expected a number for the patch's normal 2, found `x`"]
        );
        assert_eq!(
            patch("pp 3 0 0 0 0 0 1 1 0 0 0 0 1 0 1 0").unwrap_err(),
            ["expected a number for the patch's normal 3, found the end of the file"]
        );
    }
}
