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
//! apart from the other shapes in a [`PatchSet`]. [`patches_to_meshes`] then
//! turns each run of patches of one material into a triangle mesh whose
//! vertex normals are the patches' normals, so a patch is shaded smoothly: at
//! a vertex the shading normal is that vertex's normal. A patch of more than
//! three vertices is cut into triangles that cover it by the even-odd rule
//! ([`crate::mesh::triangulate_even_odd`]: ear clipping for a simple
//! outline, as for OBJ faces), so a patch covers exactly what a `p` polygon
//! with the same vertices covers, concave or crossing itself; a zero-area
//! one is kept and never hit.

use std::ops::Range;

use super::reader::{Parsed, Reader};
use super::shapes::vertex_count;
use crate::math::Vec3;
use crate::mesh::{Corner, TriangleMesh, triangulate_even_odd};
use crate::world::MaterialId;

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

/// One mesh per run of consecutive patches of the same material, with the
/// material.
pub(super) fn patches_to_meshes(set: &PatchSet) -> Vec<(TriangleMesh, MaterialId)> {
    set.patches
        .chunk_by(|a, b| a.material == b.material)
        .filter_map(|run| {
            let mut positions = Vec::new();
            let mut normals = Vec::new();
            let mut triangles = Vec::new();
            for patch in run {
                let first = positions.len() as u32;
                let unit: Vec<Vec3> = patch
                    .normals
                    .iter()
                    .map(|n| n.normalize_or_zero())
                    .collect();
                positions.extend_from_slice(&patch.positions);
                normals.extend_from_slice(&unit);
                for triangle in triangulate_even_odd(&patch.positions) {
                    triangles.push(triangle.map(|corner| match corner {
                        Corner::Vertex(i) => first + i as u32,
                        // A corner on an edge (where the outline crosses
                        // itself) gets the edge's normals interpolated.
                        Corner::OnEdge { .. } => {
                            positions.push(corner.lerp(&patch.positions));
                            normals.push(corner.lerp(&unit).normalize_or_zero());
                            positions.len() as u32 - 1
                        }
                    }));
                }
            }
            // Positions and normals were checked finite as they were read,
            // and every index is in range by construction.
            let mesh = TriangleMesh::new(positions, triangles).ok()?;
            Some((mesh.with_normals(normals).ok()?, run[0].material))
        })
        .collect()
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
    fn runs_of_patches_of_one_material_become_one_smooth_mesh() {
        let mut second = patch("pp 4 0 0 1 0 0 1 1 0 1 0 0 1 1 1 1 0 0 1 0 1 1 0 0 1").unwrap();
        second.material = MaterialId(2);
        let mut third = patch("pp 3 0 0 2 1 0 0 1 0 2 0 1 0 0 1 2 0 0 1").unwrap();
        third.material = MaterialId(5);
        let set = PatchSet {
            patches: vec![
                patch("pp 3 0 0 0 0 0 2 1 0 0 0 0 1 0 1 0 0 0 1").unwrap(),
                second,
                third,
            ],
        };
        let meshes = patches_to_meshes(&set);
        assert_eq!(meshes.len(), 2);
        let (mesh, material) = &meshes[0];
        assert_eq!(*material, MaterialId(2));
        assert_eq!(mesh.len(), 3);
        // The square is cut by ear clipping into two triangles over its
        // corners 3..7.
        assert_eq!(mesh.triangles(), [[0, 1, 2], [6, 3, 4], [4, 5, 6]]);
        assert_eq!(meshes[1].1, MaterialId(5));
    }

    #[test]
    fn a_patch_is_shaded_with_its_vertex_normal_at_that_vertex() {
        let set = PatchSet {
            patches: vec![patch("pp 3 0 0 0 1 0 1 1 0 0 0 0 1 0 1 0 0 0 1").unwrap()],
        };
        let (mesh, _) = &patches_to_meshes(&set)[0];
        let ray = crate::math::Ray::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z);
        let hit = crate::shape::ShapeHit {
            t: 1.0,
            u: 0.0,
            v: 0.0,
            part: 0,
        };
        let n = mesh.surface(0, &ray, &hit).shading_normal;
        assert!((n - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-15);
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
