//! Where the scene file defines each placed object: a side table beside
//! [`crate::world::Objects`], filled by the readers, read by
//! `whitted explain` to name what a ray hit. It is kept apart from the
//! primitives so the traced data stays as small as it is.

use crate::render::Scene;
use crate::world::PrimitiveId;

/// A place in a scene file: line and column, both from 1 (columns count
/// characters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SourceLocation {
    /// The line.
    pub line: u32,
    /// The column.
    pub column: u32,
}

impl SourceLocation {
    /// The line and column of byte `offset` of `source` (clamped to its
    /// end and to a character boundary before it).
    pub fn at(source: &str, offset: usize) -> Self {
        let mut offset = offset.min(source.len());
        while !source.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &source[..offset];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Self {
            line: (before.matches('\n').count() + 1) as u32,
            column: (before[line_start..].chars().count() + 1) as u32,
        }
    }
}

/// The lines of a text, to find the line and column of many offsets in
/// it without reading it again for each (a file of many objects): the line
/// by a binary search, the column counted on from the offset asked before
/// where that lies earlier on the same line, so that offsets asked in the
/// order of the file cost time linear in its length, however long its
/// lines (200,000 spheres on one line of NFF).
#[derive(Clone, Debug)]
pub struct LineIndex<'s> {
    source: &'s str,
    /// The byte offset where each line starts.
    starts: Vec<usize>,
    /// The last offset located, and its column.
    last: std::cell::Cell<(usize, u32)>,
}

impl<'s> LineIndex<'s> {
    /// The lines of `source`.
    pub fn new(source: &'s str) -> Self {
        let breaks = source.match_indices('\n').map(|(i, _)| i + 1);
        Self {
            source,
            starts: std::iter::once(0).chain(breaks).collect(),
            last: std::cell::Cell::new((0, 1)),
        }
    }

    /// The line and column of byte `offset` ([`SourceLocation::at`]).
    pub fn location(&self, offset: usize) -> SourceLocation {
        let mut offset = offset.min(self.source.len());
        while !self.source.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&start| start <= offset) - 1;
        let start = self.starts[line];
        let (before, column) = self.last.get();
        let (from, counted) = if (start..=offset).contains(&before) {
            (before, column)
        } else {
            (start, 1)
        };
        let column = counted + self.source[from..offset].chars().count() as u32;
        self.last.set((offset, column));
        SourceLocation {
            line: (line + 1) as u32,
            column,
        }
    }
}

/// How a scene file names one placed object, and where it defines it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ObjectSource {
    /// Its name or index in the file, as the file's format says it:
    /// `objects[2]`, `s (sphere 4)`, `group teapot`.
    pub label: String,
    /// Where its definition starts, when the reader knows.
    pub location: Option<SourceLocation>,
}

/// Where each placed object comes from: one entry per shape of
/// [`crate::world::Objects::primitives`] and per mesh placement of
/// [`crate::world::Objects::mesh_instances`], in the same order. A reader
/// that records nothing leaves both empty; a missing entry means unknown.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ObjectSources {
    /// The source of each shape.
    pub primitives: Vec<ObjectSource>,
    /// The source of each mesh placement.
    pub mesh_instances: Vec<ObjectSource>,
}

/// What a primitive number stands for in a scene, for people.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PrimitiveDescription {
    /// The shape's kind (`sphere`, `triangle` for a mesh's triangles).
    pub kind: &'static str,
    /// For a mesh's triangle: the placement's index in
    /// [`crate::world::Objects::mesh_instances`] and the triangle's in its
    /// mesh.
    pub triangle_of: Option<(u32, u32)>,
    /// How the scene file names it and where, when its reader said.
    pub source: Option<ObjectSource>,
}

impl Scene {
    /// What primitive `id` is (numbered as the world numbers them: the
    /// shapes first, then each mesh placement's triangles); `None` past
    /// the last.
    pub fn describe_primitive(&self, id: PrimitiveId) -> Option<PrimitiveDescription> {
        let objects = &self.objects;
        let index = id.0 as usize;
        if let Some(primitive) = objects.primitives.get(index) {
            return Some(PrimitiveDescription {
                kind: primitive.shape.kind(),
                triangle_of: None,
                source: self.sources.primitives.get(index).cloned(),
            });
        }
        let mut first = objects.primitives.len();
        for (instance, placed) in objects.mesh_instances.iter().enumerate() {
            let triangles = objects.meshes[placed.mesh.0 as usize].len();
            if index < first + triangles {
                return Some(PrimitiveDescription {
                    kind: "triangle",
                    triangle_of: Some((instance as u32, (index - first) as u32)),
                    source: self.sources.mesh_instances.get(instance).cloned(),
                });
            }
            first += triangles;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_byte_offset_becomes_a_line_and_a_character_column() {
        let text = "a = 1\n[[objects]]\nname = \"é\" x";
        assert_eq!(
            SourceLocation::at(text, 0),
            SourceLocation { line: 1, column: 1 }
        );
        assert_eq!(
            SourceLocation::at(text, 6),
            SourceLocation { line: 2, column: 1 }
        );
        let x = text.find('x').unwrap();
        assert_eq!(
            SourceLocation::at(text, x),
            SourceLocation {
                line: 3,
                column: 12
            }
        );
        // Inside the two bytes of `é`: its own column.
        let e = text.find('é').unwrap();
        assert_eq!(
            SourceLocation::at(text, e + 1),
            SourceLocation { line: 3, column: 9 }
        );
        assert_eq!(SourceLocation::at(text, 999).line, 3);
        let index = LineIndex::new(text);
        for offset in 0..=text.len() + 2 {
            assert_eq!(
                index.location(offset),
                SourceLocation::at(text, offset),
                "{offset}"
            );
        }
        // Asked backwards and out of order, from the memo of the last.
        let shuffled = (0..=text.len() + 2).rev().chain([7, 3, 20, 19, 30, 2, 25]);
        for offset in shuffled {
            assert_eq!(
                index.location(offset),
                SourceLocation::at(text, offset),
                "{offset}"
            );
        }
    }

    use crate::scene::{parse_nff, parse_scene};
    use std::path::Path;

    #[test]
    fn a_toml_object_is_described_by_its_table_and_its_line() {
        let text = "[camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\n\n\
                    [[objects]]\nshape = \"sphere\"\nradius = 1\n\n\
                    [[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n";
        let scene = parse_scene(text, Path::new("a.toml")).unwrap();
        let plane = scene.describe_primitive(PrimitiveId(1)).unwrap();
        assert_eq!(plane.kind, "plane");
        let source = plane.source.unwrap();
        assert_eq!(source.label, "objects[1]");
        assert_eq!(
            source.location.unwrap(),
            SourceLocation { line: 9, column: 1 }
        );
        assert_eq!(scene.describe_primitive(PrimitiveId(2)), None);
    }

    #[test]
    fn nff_shapes_and_patch_triangles_are_described_by_entity() {
        let text = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 30 hither 1 resolution 4 2\n\
                    s 0 0 0 1\ns 2 0 0 1\n\
                    pp 3 0 0 0 0 0 1 1 0 0 0 0 1 0 1 0 0 0 1\n";
        let scene = parse_nff(text, Path::new("a.nff")).unwrap();
        let second = scene.describe_primitive(PrimitiveId(1)).unwrap();
        assert_eq!(second.source.unwrap().label, "s 2");
        let triangle = scene.describe_primitive(PrimitiveId(2)).unwrap();
        assert_eq!(
            (triangle.kind, triangle.triangle_of),
            ("triangle", Some((0, 0)))
        );
        let source = triangle.source.unwrap();
        assert_eq!(source.label, "pp (1 patches)");
        assert_eq!(
            source.location.unwrap(),
            SourceLocation { line: 4, column: 1 }
        );
    }
}
