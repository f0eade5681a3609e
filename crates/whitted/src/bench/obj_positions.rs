//! The geometry of a Wavefront OBJ file and nothing else: `v` positions and
//! `f` faces, each polygon fan-triangulated `(v0, vk, vk+1)` in file order,
//! so that a triangle's index is its position in that order. This is what a
//! benchmark needs to trace the same triangles as another renderer (the
//! Embree anchor harness numbers triangles the same way).
//!
//! Texture coordinates and normals in faces (`v/vt/vn`) are skipped, as are
//! all other statements. Positions are read as 32-bit floats, as the anchor
//! does, and widened exactly to `f64`.

use std::ops::Range;
use std::path::Path;

use crate::limits::{Charge, MemoryBudget};
use crate::math::{Aabb, Transform, Vec3};
use crate::mesh::{MeshError, TriangleMesh};
use crate::render::Camera;
use crate::render::Scene;
use crate::scene::{Diagnostic, SceneError, Severity, push_limited, without_bom};
use crate::shading::Material;

/// Positions and triangles as they appear in the file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleSoup {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleSoup {
    /// The box around every position.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter().copied())
    }

    /// The bytes its positions and triangles take.
    fn heap_bytes(&self) -> u64 {
        (self.positions.capacity() * size_of::<Vec3>()
            + self.triangles.capacity() * size_of::<[u32; 3]>()) as u64
    }

    /// A scene of one mesh of these triangles, all of one grey material,
    /// seen by `camera`. Every triangle keeps its index in the file as its
    /// primitive number, zero-area ones included (they are never hit).
    pub fn into_scene(self, camera: Camera) -> Result<Scene, MeshError> {
        let mut scene = Scene::new(camera);
        let material = scene.add_material(Material::default());
        let mesh = TriangleMesh::new(self.positions, self.triangles)?;
        let mesh = scene.add_mesh(mesh);
        scene.add_mesh_instance(mesh, material, Transform::IDENTITY);
        Ok(scene)
    }
}

/// Reads and parses an OBJ file.
pub fn load_obj_positions(path: &Path) -> Result<TriangleSoup, SceneError> {
    let source = crate::limits::read_input_text(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_obj_positions(&source, path)
}

/// Parses OBJ text; `path` is only used in messages. Every malformed line is
/// reported. The positions and triangles are charged to the memory ledger
/// while they are read ([`Charge::follow`]); reading stops at the line
/// where they pass the budget. The charge ends with the reading: a scene
/// made of them is charged with its world before that is built.
pub fn parse_obj_positions(source: &str, path: &Path) -> Result<TriangleSoup, SceneError> {
    let source = without_bom(source);
    let budget = MemoryBudget::current();
    let mut charge = Charge::none();
    let mut soup = TriangleSoup::default();
    let mut diagnostics = Vec::new();
    let mut face: Vec<u32> = Vec::new();
    let mut line_start = 0;
    for line in source.split_inclusive('\n') {
        let start = line_start;
        line_start += line.len();
        let mut tokens = tokens(line, start);
        let Some((keyword, keyword_span)) = tokens.next() else {
            continue;
        };
        let mut report = |span: Range<usize>, message: String| {
            push_limited(&mut diagnostics, Severity::Error, || {
                Diagnostic::new(path, source, span, message)
            });
        };
        match keyword {
            "v" => {
                let mut xyz = [0.0f32; 3];
                let mut ok = true;
                for (axis, value) in xyz.iter_mut().enumerate() {
                    match tokens.next() {
                        Some((text, span)) => match text.parse::<f32>() {
                            Ok(v) if v.is_finite() => *value = v,
                            _ => {
                                report(span, format!("expected a number, found `{text}`"));
                                ok = false;
                            }
                        },
                        None => {
                            report(
                                keyword_span.clone(),
                                format!("a vertex needs 3 coordinates, found {axis}"),
                            );
                            ok = false;
                            break;
                        }
                    }
                }
                let [x, y, z] = xyz.map(f64::from);
                soup.positions
                    .push(if ok { Vec3::new(x, y, z) } else { Vec3::ZERO });
            }
            "f" => {
                face.clear();
                let mut ok = true;
                for (text, span) in tokens {
                    match vertex_index(text, soup.positions.len()) {
                        Ok(i) => face.push(i),
                        Err(message) => {
                            report(span, message);
                            ok = false;
                        }
                    }
                }
                if ok && face.len() < 3 {
                    report(
                        keyword_span,
                        format!("a face needs at least 3 vertices, found {}", face.len()),
                    );
                } else if ok {
                    for k in 1..face.len() - 1 {
                        soup.triangles.push([face[0], face[k], face[k + 1]]);
                    }
                }
            }
            _ => {}
        }
        let charged = charge.follow(
            &budget,
            "reading the model's vertices and faces",
            soup.heap_bytes(),
            "use a smaller model",
        );
        if let Err(error) = charged {
            // Reading stops here: what is left would only take more.
            push_limited(&mut diagnostics, Severity::Error, || {
                Diagnostic::new(path, source, start..start, error.to_string())
            });
            break;
        }
    }
    if diagnostics.is_empty() {
        Ok(soup)
    } else {
        Err(SceneError::Invalid { diagnostics })
    }
}

/// The whitespace-separated tokens of a line before any `#` comment, with
/// their byte ranges in the whole source.
fn tokens(line: &str, offset: usize) -> impl Iterator<Item = (&str, Range<usize>)> {
    let content = line.split('#').next().unwrap_or("");
    content.split_ascii_whitespace().map(move |token| {
        let at = token.as_ptr() as usize - line.as_ptr() as usize;
        (token, offset + at..offset + at + token.len())
    })
}

/// The 0-based position index of a face vertex `v`, `v/vt`, `v//vn` or
/// `v/vt/vn`, with `count` positions read so far (negative indices count
/// back from the last).
fn vertex_index(text: &str, count: usize) -> Result<u32, String> {
    let position = text.split('/').next().unwrap_or("");
    let index: i64 = position
        .parse()
        .map_err(|_| format!("expected a vertex index, found `{text}`"))?;
    let resolved = match index {
        0 => return Err("vertex indices start at 1; 0 is not one".to_string()),
        i if i > 0 => i - 1,
        i => count as i64 + i,
    };
    if resolved < 0 || resolved >= count as i64 {
        return Err(format!(
            "vertex index {index} is out of range: {count} vertices are defined before this face"
        ));
    }
    u32::try_from(resolved).map_err(|_| format!("vertex index {index} is too large"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<TriangleSoup, String> {
        parse_obj_positions(text, Path::new("m.obj")).map_err(|e| e.to_string())
    }

    #[test]
    fn a_byte_order_mark_does_not_hide_the_first_vertex() {
        let soup = parse("\u{feff}v 0 0 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_eq!(soup.positions.len(), 3);
        assert_eq!(soup.positions[0], Vec3::new(0.0, 0.0, 1.0));
    }

    #[test]
    fn polygons_are_fan_triangulated_in_file_order() {
        let soup = parse(
            "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
             vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -1 -2 -3\n",
        )
        .unwrap();
        assert_eq!(soup.positions.len(), 4);
        assert_eq!(soup.triangles, vec![[0, 1, 2], [0, 2, 3], [3, 2, 1]]);
    }

    #[test]
    fn every_face_form_gives_the_position_index() {
        for face in [
            "f 1 2 3",
            "f 1/1 2/2 3/3",
            "f 1//1 2//2 3//3",
            "f 1/1/1 2/2/2 3/3/3",
        ] {
            let soup = parse(&format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\n")).unwrap();
            assert_eq!(soup.triangles, vec![[0, 1, 2]], "{face}");
        }
    }

    #[test]
    fn positions_are_read_as_f32_then_widened() {
        let soup = parse("v 0.1 1e-3 -2.5\n").unwrap();
        assert_eq!(soup.positions[0].x, f64::from(0.1f32));
    }

    #[test]
    fn every_bad_line_is_reported_with_its_location() {
        let err = parse("v 0 0 0\nv 1 zero 0\nv 2 2\nf 1 2 7\nf 1 2\nf 0 1 2\n").unwrap_err();
        assert_eq!(
            err,
            "m.obj:2:5: error: expected a number, found `zero`\n  |\n2 | v 1 zero 0\n  |     ^^^^\n\n\
             m.obj:3:1: error: a vertex needs 3 coordinates, found 2\n  |\n3 | v 2 2\n  | ^\n\n\
             m.obj:4:7: error: vertex index 7 is out of range: 3 vertices are defined before this face\n  |\n4 | f 1 2 7\n  |       ^\n\n\
             m.obj:5:1: error: a face needs at least 3 vertices, found 2\n  |\n5 | f 1 2\n  | ^\n\n\
             m.obj:6:3: error: vertex indices start at 1; 0 is not one\n  |\n6 | f 0 1 2\n  |   ^\n\n\
             5 errors"
        );
    }

    #[test]
    fn the_scene_numbers_triangles_as_the_file_does_zero_area_ones_included() {
        let soup = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 4\nf 1 2 3\n").unwrap();
        let camera = Camera::framing(&soup.bounds(), 1.0, 50.0).unwrap();
        let scene = soup.into_scene(camera).unwrap();
        let world = crate::world::World::new(&scene.objects);
        assert_eq!(world.len(), 2);
        let ray = crate::math::Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        assert_eq!(world.intersect(&ray).unwrap().primitive.0, 1);
    }

    #[test]
    fn a_missing_file_is_an_io_error_naming_it() {
        let err = load_obj_positions(Path::new("/no/such/mesh.obj")).unwrap_err();
        assert!(err.to_string().contains("/no/such/mesh.obj"));
    }
}
