//! The OBJ statements we read, from text to flat arrays: positions,
//! texture coordinates, normals, and faces as runs of corners, each face
//! with its material and smoothing group. Every problem is recorded with
//! its place and reading carries on with the next line.

use std::collections::{HashMap, HashSet};
use std::ops::Range;
use std::path::Path;

use super::text::{Line, Words, lines};
use crate::limits::{Charge, MemoryBudget, MemoryError};
use crate::math::{DVec2, Vec3, magnitude};
use crate::scene::{Diagnostic, Severity, push_limited};

/// An absent index (a corner without texture coordinates or normal).
pub(super) const NONE: u32 = u32::MAX;

/// One corner of a face: indices from 0 into the attribute arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Corner {
    pub(super) position: u32,
    pub(super) uv: u32,
    pub(super) normal: u32,
}

/// A polygon: `count` corners from `first` in [`ObjData::corners`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Face {
    pub(super) first: u32,
    pub(super) count: u32,
    /// Index into [`ObjData::material_uses`], or [`NONE`] before any `usemtl`.
    pub(super) material: u32,
    /// The smoothing group; 0 is off (flat).
    pub(super) smoothing: u32,
}

/// What an OBJ file says.
#[derive(Debug, Default)]
pub(super) struct ObjData {
    pub(super) positions: Vec<Vec3>,
    pub(super) uvs: Vec<DVec2>,
    pub(super) normals: Vec<Vec3>,
    pub(super) corners: Vec<Corner>,
    pub(super) faces: Vec<Face>,
    /// The names given to `usemtl`, each once, with where first used.
    pub(super) material_uses: Vec<(String, Range<usize>)>,
    /// The files named by `mtllib`, with where.
    pub(super) libraries: Vec<(String, Range<usize>)>,
    /// How many `o` and `g` statements.
    pub(super) groups: usize,
    /// Whether any `s` statement appears.
    pub(super) smoothing_given: bool,
    /// Errors and warnings, in file order.
    pub(super) diagnostics: Vec<Diagnostic>,
    /// The memory its vertices and faces are charged, while it lives.
    pub(super) charge: Charge,
}

impl ObjData {
    /// The bytes its vertices, corners and faces take.
    pub(super) fn heap_bytes(&self) -> u64 {
        (self.positions.capacity() * size_of::<Vec3>()
            + self.uvs.capacity() * size_of::<DVec2>()
            + self.normals.capacity() * size_of::<Vec3>()
            + self.corners.capacity() * size_of::<Corner>()
            + self.faces.capacity() * size_of::<Face>()) as u64
    }
}

/// Reads the statements of `source`, named `path` in messages.
pub(super) fn read_obj(source: &str, path: &Path) -> ObjData {
    let mut reader = Reader {
        source,
        path,
        data: ObjData::default(),
        material: NONE,
        smoothing: 0,
        warned: HashSet::new(),
        material_slots: HashMap::new(),
    };
    let budget = MemoryBudget::current();
    for line in lines(source) {
        let at = line.start..line.start;
        reader.statement(line);
        if let Err(error) = reader.charge(&budget) {
            // Reading stops here: what is left would only take more.
            reader.error(at, error.to_string());
            break;
        }
    }
    reader.data
}

struct Reader<'a> {
    source: &'a str,
    path: &'a Path,
    data: ObjData,
    material: u32,
    smoothing: u32,
    /// Statements already warned about (warned once per file).
    warned: HashSet<String>,
    /// The index in [`ObjData::material_uses`] of each name.
    material_slots: HashMap<String, u32>,
}

/// A problem already recorded.
struct Reported;

impl Reader<'_> {
    /// Charges what the data took since the last charge (see
    /// [`crate::limits::Charge::follow`]).
    fn charge(&mut self, budget: &MemoryBudget) -> Result<(), MemoryError> {
        let data = &mut self.data;
        let bytes = data.heap_bytes();
        data.charge.follow(
            budget,
            "reading the model's vertices and faces",
            bytes,
            "use a smaller model",
        )
    }

    fn error(&mut self, span: Range<usize>, message: impl Into<String>) -> Reported {
        let (path, source) = (self.path, self.source);
        push_limited(&mut self.data.diagnostics, Severity::Error, || {
            Diagnostic::new(path, source, span, message)
        });
        Reported
    }

    fn warn_once(&mut self, keyword: &str, span: Range<usize>, message: String) {
        if self.warned.insert(keyword.to_string()) {
            let (path, source) = (self.path, self.source);
            push_limited(&mut self.data.diagnostics, Severity::Warning, || {
                Diagnostic::warning(path, source, span, message)
            });
        }
    }

    fn statement(&mut self, line: Line<'_>) {
        let mut words = line.words();
        let Some((keyword, at)) = words.next() else {
            return;
        };
        let _ = match keyword {
            // A value that cannot be read still takes its place (as zero),
            // so that the indices after it mean what the file says.
            "v" => {
                let n = self.numbers(&mut words, at, 3, "a vertex position `v x y z`");
                self.data.positions.push(Vec3::new(n[0], n[1], n[2]));
                Ok(())
            }
            "vt" => {
                let n = self.numbers(&mut words, at, 1, "texture coordinates `vt u [v]`");
                self.data.uvs.push(DVec2::new(n[0], n[1]));
                Ok(())
            }
            "vn" => {
                let n = self.numbers(&mut words, at, 3, "a normal `vn x y z`");
                self.data.normals.push(Vec3::new(n[0], n[1], n[2]));
                Ok(())
            }
            "f" | "fo" => self.face(words, at),
            "o" | "g" => {
                self.data.groups += 1;
                Ok(())
            }
            "s" => self.smoothing_group(words.next(), at),
            "usemtl" => self.use_material(line, at),
            "mtllib" => self.library(line, at),
            "l" | "p" => {
                let message = format!("points and lines (`{keyword}`) are not rendered; ignored");
                self.warn_once(keyword, at, message);
                Ok(())
            }
            _ => {
                let message = format!("unknown statement `{keyword}`; ignored");
                self.warn_once(keyword, at, message);
                Ok(())
            }
        };
    }

    /// At least `min` finite numbers within ±[`magnitude::MAX_COORDINATE`]
    /// (beyond it, a model's size cannot be squared), the first three returned (missing
    /// ones as zero); numbers after them (a `w`, a vertex colour) are
    /// ignored. A problem is recorded and gives zeros.
    fn numbers(
        &mut self,
        words: &mut Words<'_>,
        at: Range<usize>,
        min: usize,
        what: &str,
    ) -> [f64; 3] {
        let mut values = [0.0; 3];
        let mut count = 0;
        for (word, span) in words.by_ref() {
            let Ok(value) = word.parse::<f64>() else {
                self.error(span, format!("expected a number in {what}, found `{word}`"));
                return [0.0; 3];
            };
            if !value.is_finite() {
                self.error(span, format!("`{word}` is not a finite number"));
                return [0.0; 3];
            }
            if let Err(error) = magnitude::coordinate(value) {
                self.error(span, format!("`{word}` is out of range: {error}"));
                return [0.0; 3];
            }
            if let Some(slot) = values.get_mut(count) {
                *slot = value;
            }
            count += 1;
        }
        if count < min {
            self.error(at, format!("expected {what}: too few numbers"));
            return [0.0; 3];
        }
        values
    }

    fn face(&mut self, words: Words<'_>, at: Range<usize>) -> Result<(), Reported> {
        let first = self.data.corners.len();
        let mut failed = false;
        let mut missing = [None, None];
        for (word, span) in words {
            match self.corner(word, span.start, &mut missing) {
                Ok(corner) => self.data.corners.push(corner),
                Err(Reported) => failed = true,
            }
        }
        let count = self.data.corners.len() - first;
        if failed {
            self.data.corners.truncate(first);
            return Err(Reported);
        }
        self.drop_missing(first, missing);
        if count < 3 {
            self.data.corners.truncate(first);
            return Err(self.error(
                at,
                format!("a face needs at least 3 corners, found {count}"),
            ));
        }
        self.data.faces.push(Face {
            first: first as u32,
            count: count as u32,
            material: self.material,
            smoothing: self.smoothing,
        });
        Ok(())
    }

    /// Drops the texture coordinates or the normals of the face whose
    /// corners start at `first` when one of its corners refers to some that
    /// do not exist (`missing`: where, and what was said, for texture
    /// coordinates and normals): the face is read as one without them
    /// (as other readers do), with a warning once per file.
    fn drop_missing(&mut self, first: usize, missing: [Option<(Range<usize>, String)>; 2]) {
        let [uv, normal] = missing;
        if let Some((span, what)) = uv {
            for corner in &mut self.data.corners[first..] {
                corner.uv = NONE;
            }
            let message = format!(
                "{what}; faces that refer to texture coordinates that do not exist are read without texture coordinates (warned once per file)"
            );
            self.warn_once("missing vt", span, message);
        }
        if let Some((span, what)) = normal {
            for corner in &mut self.data.corners[first..] {
                corner.normal = NONE;
            }
            let message = format!(
                "{what}; faces that refer to normals that do not exist get normals computed as for a face without any (warned once per file)"
            );
            self.warn_once("missing vn", span, message);
        }
    }

    /// A corner `v`, `v/vt`, `v//vn` or `v/vt/vn` starting at byte `start`.
    /// A texture coordinate or normal index out of range is recorded in
    /// `missing` (by slot, the first only) and read as absent.
    fn corner(
        &mut self,
        word: &str,
        start: usize,
        missing: &mut [Option<(Range<usize>, String)>; 2],
    ) -> Result<Corner, Reported> {
        let mut parts = word.split('/');
        let mut offset = start;
        let mut indices = [NONE; 3];
        let counts = [
            self.data.positions.len(),
            self.data.uvs.len(),
            self.data.normals.len(),
        ];
        let names = ["vertex", "texture coordinate", "normal"];
        for slot in 0..3 {
            let Some(part) = parts.next() else { break };
            let span = offset..offset + part.len();
            offset += part.len() + 1;
            if part.is_empty() && slot > 0 {
                continue;
            }
            indices[slot] = match self.index(part, &span, counts[slot], names[slot])? {
                Ok(index) => index,
                Err(out_of_range) if slot > 0 => {
                    missing[slot - 1].get_or_insert((span, out_of_range));
                    NONE
                }
                Err(out_of_range) => return Err(self.error(span, out_of_range)),
            };
        }
        if parts.next().is_some() {
            let span = start..start + word.len();
            return Err(self.error(
                span,
                format!("expected a corner v, v/vt, v//vn or v/vt/vn, found `{word}`"),
            ));
        }
        Ok(Corner {
            position: indices[0],
            uv: indices[1],
            normal: indices[2],
        })
    }

    /// An index from 1, or negative counting back from the last defined;
    /// one past those defined is `Ok(Err(what to say))`.
    fn index(
        &mut self,
        text: &str,
        span: &Range<usize>,
        count: usize,
        name: &str,
    ) -> Result<Result<u32, String>, Reported> {
        let Ok(value) = text.parse::<i64>() else {
            return Err(self.error(
                span.clone(),
                format!("expected a {name} index (a whole number), found `{text}`"),
            ));
        };
        let resolved = if value > 0 {
            value - 1
        } else {
            count as i64 + value
        };
        if value == 0 {
            return Err(self.error(
                span.clone(),
                format!("{name} index 0: indices count from 1 (or back from -1)"),
            ));
        }
        if resolved < 0 || resolved >= count as i64 || resolved >= i64::from(NONE) {
            let plural = match name {
                "vertex" => "vertices",
                "normal" => "normals",
                _ => "texture coordinates",
            };
            let defined = match count {
                1 => format!("1 {name} is"),
                _ => format!("{count} {plural} are"),
            };
            return Ok(Err(format!(
                "{name} index {value} is out of range: {defined} defined before this line"
            )));
        }
        Ok(Ok(resolved as u32))
    }

    fn smoothing_group(
        &mut self,
        word: Option<(&str, Range<usize>)>,
        at: Range<usize>,
    ) -> Result<(), Reported> {
        self.data.smoothing_given = true;
        let Some((word, span)) = word else {
            return Err(self.error(
                at,
                "expected a smoothing group after `s`: a number or `off`",
            ));
        };
        self.smoothing = if word.eq_ignore_ascii_case("off") {
            0
        } else {
            word.parse::<u32>().map_err(|_| {
                self.error(
                    span,
                    format!("expected a smoothing group (a number or `off`), found `{word}`"),
                )
            })?
        };
        Ok(())
    }

    fn use_material(&mut self, line: Line<'_>, at: Range<usize>) -> Result<(), Reported> {
        let (name, span) = line.rest();
        if name.is_empty() {
            return Err(self.error(at, "expected a material name after `usemtl`"));
        }
        let uses = &mut self.data.material_uses;
        let next = uses.len() as u32;
        self.material = *self
            .material_slots
            .entry(name.to_string())
            .or_insert_with(|| {
                uses.push((name.to_string(), span));
                next
            });
        Ok(())
    }

    fn library(&mut self, line: Line<'_>, at: Range<usize>) -> Result<(), Reported> {
        let (name, span) = line.rest();
        if name.is_empty() {
            return Err(self.error(at, "expected a file name after `mtllib`"));
        }
        self.data.libraries.push((name.to_string(), span));
        Ok(())
    }
}
