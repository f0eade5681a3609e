//! Bézier patch text (`.bpt`): a file of bicubic Bézier patches, as the
//! Utah teapot is distributed (see `docs/bpt.md`).
//!
//! ```text
//! N                  number of patches
//! 3 3                degrees of the patch in u and v (only bicubic is read)
//! x y z              16 control points, row by row: point (i, j) is line
//! ...                i*4 + j of the patch, i along u
//! ```
//!
//! Whitespace separates numbers; lines do not matter beyond that. Every
//! error names `path:line:column`: a word that is not a number, a count or
//! degree out of range, a point out of range, a degenerate patch (at its
//! degrees), the file ending early or going on after the last patch.
//!
//! [`parse_bpt`] reads a file as a scene of its own, as a bare OBJ model
//! is: the file's z axis turned to point up the screen (each point
//! `(x, y, z)` becomes `(x, z, -y)`, which is exact), a grey material, a
//! camera framing the model and a light at the eye.

use std::ops::Range;
use std::path::Path;

use crate::limits::{Charge, MemoryBudget};
use crate::math::{Aabb, Vec3, magnitude};
use crate::render::{Camera, RenderSettings, Scene};
use crate::scene::obj::{AMBIENT, DEFAULT_FOV_DEGREES, headlight};
use crate::scene::{Diagnostic, LoadedScene, SceneError, WholeNumberError, without_bom};
use crate::shading::{Color, Material};
use crate::shape::{BezierPatch, Shape, ShapeError};

/// The most patches a file may declare (the budget bounds what is really
/// read; this bounds the count itself).
const MAX_PATCHES: u64 = 1 << 24;

/// Bytes charged to the memory ledger for each piece a patch puts in the
/// scene, besides the patch's own data ([`BezierPatch::new`] charges
/// that): the scene's record and source of the piece and its share of
/// the world's entries and structure. An estimate from a measurement:
/// 5.8 million pieces of 10,000 crumpled patches peaked at 6.0 GB, about
/// 1,030 bytes a piece, some 500 of them the patches' data.
const PIECE_BYTES: u64 = 512;

/// Reads the patches of a `.bpt` file's text; `path` names it in messages.
pub fn parse_bpt_patches(source: &str, path: &Path) -> Result<Vec<BezierPatch>, SceneError> {
    let source = without_bom(source);
    let mut reader = Words {
        source,
        path,
        rest: source.char_indices().peekable(),
        diagnostics: Vec::new(),
    };
    let patches = reader.patches();
    match (patches, reader.diagnostics.is_empty()) {
        (Some(patches), true) => Ok(patches),
        _ => Err(SceneError::Invalid {
            diagnostics: reader.diagnostics,
        }),
    }
}

/// Reads a `.bpt` file's patches.
pub fn load_bpt_patches(path: &Path) -> Result<Vec<BezierPatch>, SceneError> {
    let source = crate::limits::read_input_text(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_bpt_patches(&source, path)
}

/// Reads a `.bpt` file's text as a scene (see the module's documentation).
pub fn parse_bpt(source: &str, path: &Path) -> Result<LoadedScene, SceneError> {
    let upright = |p: Vec3| Vec3::new(p.x, p.z, -p.y);
    let patches: Vec<BezierPatch> = parse_bpt_patches(source, path)?
        .iter()
        .filter_map(|patch| BezierPatch::new(patch.points().map(|row| row.map(upright))).ok())
        .collect();
    let bounds = patches
        .iter()
        .fold(Aabb::EMPTY, |b, patch| b.union(&patch.bounds()));
    let settings = RenderSettings::default();
    let aspect = f64::from(settings.width) / f64::from(settings.height);
    let camera =
        Camera::framing(&bounds, aspect, DEFAULT_FOV_DEGREES).map_err(|e| SceneError::Invalid {
            diagnostics: vec![Diagnostic::new(
                path,
                source,
                0..0,
                format!("cannot frame the model: {e}"),
            )],
        })?;
    let mut scene = Scene::new(camera);
    scene.settings = settings;
    scene.ambient = Color::splat(AMBIENT);
    scene.lights = vec![headlight(&scene.camera)];
    let material = scene.add_material(Material::default());
    let budget = MemoryBudget::current();
    let mut charge = Charge::none();
    for (index, patch) in patches.iter().enumerate() {
        let pieces: Vec<BezierPatch> = patch.pieces().collect();
        let bytes = pieces.len() as u64 * PIECE_BYTES;
        let what = format!("the {} pieces of patch {}", pieces.len(), index + 1);
        if let Err(error) = charge.grow(&budget, &what, bytes, "use fewer or flatter patches") {
            return Err(SceneError::Invalid {
                diagnostics: vec![Diagnostic::new(path, source, 0..0, error.to_string())],
            });
        }
        for piece in pieces {
            scene.add_primitive(
                Shape::BezierPatch(piece),
                material,
                crate::math::Transform::IDENTITY,
            );
            scene.sources.primitives.push(crate::render::ObjectSource {
                label: format!("patch {}", index + 1),
                location: None,
            });
        }
    }
    scene.held.keep(charge);
    Ok(LoadedScene {
        scene,
        warnings: Vec::new(),
    })
}

/// Reads a `.bpt` file as a scene.
pub fn load_bpt(path: &Path) -> Result<LoadedScene, SceneError> {
    let source = crate::limits::read_input_text(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_bpt(&source, path)
}

/// The words of the text, with their places, and the errors found.
struct Words<'s> {
    source: &'s str,
    path: &'s Path,
    rest: std::iter::Peekable<std::str::CharIndices<'s>>,
    diagnostics: Vec<Diagnostic>,
}

impl Words<'_> {
    /// Every patch; `None` after an error that stops reading.
    fn patches(&mut self) -> Option<Vec<BezierPatch>> {
        let (count, _) = self.whole("the number of patches", 1, MAX_PATCHES)?;
        let mut patches = Vec::with_capacity(count.min(1024) as usize);
        for index in 1..=count {
            let what = format!("the degrees of patch {index}");
            let (u, at_u) = self.whole(&what, 0, u64::MAX)?;
            let (v, at_v) = self.whole(&what, 0, u64::MAX)?;
            if (u, v) != (3, 3) {
                let message = format!(
                    "patch {index} has degrees {u} {v}; only bicubic patches (3 3) are read"
                );
                self.error(at_u.start..at_v.end, message);
                return None;
            }
            let mut net = [[Vec3::ZERO; 4]; 4];
            for (k, point) in net.iter_mut().flatten().enumerate() {
                let what = format!("point {} of patch {index}", k + 1);
                *point = Vec3::new(
                    self.coordinate(&what)?,
                    self.coordinate(&what)?,
                    self.coordinate(&what)?,
                );
            }
            match BezierPatch::new(net) {
                Ok(patch) => patches.push(patch),
                // Past the budget, reading on would only repeat it.
                Err(error @ ShapeError::Memory(_)) => {
                    self.error(at_u.start..at_v.end, format!("patch {index}: {error}"));
                    return None;
                }
                Err(error) => self.error(at_u.start..at_v.end, format!("patch {index}: {error}")),
            }
        }
        if let Some((_, at)) = self.word() {
            self.error(
                at,
                format!("expected the end of the file after {count} patches"),
            );
        }
        Some(patches)
    }

    /// The next word and its place.
    fn word(&mut self) -> Option<(&str, Range<usize>)> {
        while self.rest.next_if(|(_, c)| c.is_whitespace()).is_some() {}
        let start = self.rest.peek()?.0;
        let mut end = start;
        while let Some((at, c)) = self.rest.next_if(|(_, c)| !c.is_whitespace()) {
            end = at + c.len_utf8();
        }
        Some((&self.source[start..end], start..end))
    }

    /// The next word, or an error saying `what` was expected.
    fn expect(&mut self, what: &str) -> Option<(String, Range<usize>)> {
        match self.word() {
            Some((word, at)) => Some((word.to_string(), at)),
            None => {
                let end = self.source.len();
                self.error(end..end, format!("the file ends where {what} was expected"));
                None
            }
        }
    }

    /// A whole number in `min..=max`.
    fn whole(&mut self, what: &str, min: u64, max: u64) -> Option<(u64, Range<usize>)> {
        let (word, at) = self.expect(what)?;
        match crate::scene::parse_whole_number(&word, min, max) {
            Ok(n) => Some((n, at)),
            Err(error) => {
                let why = match error {
                    WholeNumberError::NotANumber => "not a number".to_string(),
                    WholeNumberError::NotWhole => "not a whole number".to_string(),
                    WholeNumberError::Negative => "negative".to_string(),
                    WholeNumberError::BelowMinimum => format!("below {min}"),
                    WholeNumberError::AboveMaximum => format!("above {max}"),
                };
                self.error(at, format!("expected {what}, found `{word}` ({why})"));
                None
            }
        }
    }

    /// A finite coordinate within ±[`magnitude::MAX_COORDINATE`].
    fn coordinate(&mut self, what: &str) -> Option<f64> {
        let (word, at) = self.expect(what)?;
        let number = word.parse::<f64>().ok().filter(|x| x.is_finite());
        let Some(number) = number else {
            self.error(at, format!("expected a number for {what}, found `{word}`"));
            return None;
        };
        match magnitude::coordinate(number) {
            Ok(x) => Some(x),
            Err(error) => {
                self.error(at, format!("{what} is out of range: {error}"));
                None
            }
        }
    }

    fn error(&mut self, at: Range<usize>, message: String) {
        let d = Diagnostic::new(self.path, self.source, at, message);
        self.diagnostics.push(d);
    }
}

#[cfg(test)]
mod tests;
