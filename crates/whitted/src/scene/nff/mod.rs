//! Eric Haines' Neutral File Format (NFF), the format of the Standard
//! Procedural Databases (SPD). How each entity is read is in
//! `docs/nff.md`; in short:
//!
//! ```text
//! b R G B                       background colour (default black)
//! v                             the view: exactly one
//! from X Y Z
//! at X Y Z
//! up X Y Z
//! angle DEG                     spans the centres of the first and last rows
//! hither H                      checked, not used: rays start at the eye
//! resolution W H
//! l X Y Z [R G B]               point light; 1/sqrt(number of lights) without a colour
//! f R G B Kd Ks Shine T ior     the material of the entities that follow
//! s X Y Z R                     sphere
//! c BX BY BZ BR AX AY AZ AR     open cone, or cylinder when BR = AR
//! p N X1 Y1 Z1 ...              flat polygon, convex or concave
//! pp N X1 Y1 Z1 NX1 NY1 NZ1 ... polygon with vertex normals (shaded flat for now)
//! # ...                         comment to the end of the line
//! ```
//!
//! The file is read as a stream of tokens, so line breaks never matter. Its
//! colours are display values, shaded and written as they are (as the
//! classic renderers and POV-Ray do). The
//! scene gets the SPD's tracing rules: depth 5 counting the eye ray
//! (`max_depth` 4) and no adaptive cut-off (`min_weight` 0); the command
//! line overrides both. Every problem is reported with its place; after one,
//! the reader skips to the next entity keyword and carries on.

mod lexer;
mod material;
mod patches;
mod reader;
mod shapes;
mod view;

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use self::lexer::ENTITY_KEYWORDS;
use self::material::{AMBIENT, Fill, default_light_intensity, read_fill};
use self::patches::{PatchSet, patches_to_meshes, read_patch};
use self::reader::{Parsed, Reader};
use self::shapes::{Placed, flat_shape, read_cone, read_polygon, read_sphere};
use self::view::{View, read_view};
use crate::image::ColorSpace;
use crate::math::{Transform, Vec3};
use crate::render::{LineIndex, ObjectSource, ObjectSources, RenderSettings, Scene};
use crate::scene::{SceneError, without_bom};
use crate::shading::Color;
use crate::shading::Material;
use crate::shading::{Attenuation, Light};
use crate::world::MaterialId;

/// Reads a scene from the text of an NFF file; `path` is only used in
/// messages.
pub fn parse_nff(source: &str, path: &Path) -> Result<Scene, SceneError> {
    let source = without_bom(source);
    let mut r = Reader::new(source, path);
    let mut document = Document::default();
    while let Some(token) = r.next_token() {
        let at = token.span;
        let read = match token.text {
            "v" => read_view(&mut r, at.clone()).and_then(|v| document.set_view(&mut r, v, at)),
            "b" => read_background(&mut r).and_then(|b| document.set_background(&mut r, b, at)),
            "l" => read_light(&mut r).map(|light| document.lights.push(light)),
            "f" => read_fill(&mut r).map(|fill| document.set_fill(fill)),
            "s" => read_sphere(&mut r, at.clone()).map(|placed| document.add(placed, at, "s")),
            "c" => read_cone(&mut r, at.clone()).map(|placed| document.add(placed, at, "c")),
            "p" => read_polygon(&mut r, at.clone()).map(|placed| document.add(placed, at, "p")),
            "pp" => {
                let material = document.material();
                read_patch(&mut r, at, material).map(|patch| document.patches.patches.push(patch))
            }
            other => Err(unknown_entity(&mut r, other, at)),
        };
        if read.is_err() {
            document.view_seen |= token.text == "v";
            r.skip_to_entity();
        }
    }
    let sources = object_sources(source, &document);
    let scene = document.finish(&mut r).map(|mut scene| {
        scene.sources = sources;
        scene
    });
    let diagnostics = r.into_diagnostics();
    match scene {
        Some(scene) if diagnostics.is_empty() => Ok(scene),
        _ => Err(SceneError::Invalid { diagnostics }),
    }
}

/// Reads an NFF file.
pub fn load_nff(path: &Path) -> Result<Scene, SceneError> {
    let source = crate::limits::read_input_text(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_nff(&source, path)
}

/// What a file has said so far.
#[derive(Default)]
struct Document {
    view: Option<View>,
    /// A `v` was met, even one that could not be read.
    view_seen: bool,
    background: Option<Color>,
    /// Position and colour, if given.
    lights: Vec<(Vec3, Option<Color>)>,
    materials: Vec<Material>,
    /// The material of each distinct `f` (by the bits of its numbers), so
    /// that repeated `f` entities share one material.
    fills: HashMap<[u64; 8], MaterialId>,
    /// The material of the last `f`, or none before the first.
    current: Option<MaterialId>,
    /// Shapes with their placements and materials, in file order.
    objects: Vec<(Placed, MaterialId)>,
    /// Each shape's entity keyword and where it starts.
    object_entities: Vec<(&'static str, usize)>,
    patches: PatchSet,
}

impl Document {
    fn set_view(&mut self, r: &mut Reader<'_>, view: View, at: Range<usize>) -> Parsed<()> {
        if self.view_seen {
            return Err(r.error(at, "a second view `v`: a file has only one"));
        }
        self.view_seen = true;
        self.view = Some(view);
        Ok(())
    }

    fn set_background(&mut self, r: &mut Reader<'_>, color: Color, at: Range<usize>) -> Parsed<()> {
        if self.background.is_some() {
            return Err(r.error(at, "a second background `b`: a file has only one"));
        }
        self.background = Some(color);
        Ok(())
    }

    fn set_fill(&mut self, fill: Fill) {
        let key = [
            fill.color.r,
            fill.color.g,
            fill.color.b,
            fill.kd,
            fill.ks,
            fill.shine,
            fill.t,
            fill.ior,
        ]
        .map(f64::to_bits);
        let next = MaterialId(self.materials.len() as u32);
        let id = *self.fills.entry(key).or_insert(next);
        if id == next {
            self.materials.push(fill.material());
        }
        self.current = Some(id);
    }

    /// The current material; before any `f`, our default matte grey.
    fn material(&mut self) -> MaterialId {
        *self.current.get_or_insert_with(|| {
            self.materials.push(Material::default());
            MaterialId((self.materials.len() - 1) as u32)
        })
    }

    fn add(&mut self, placed: Placed, at: Range<usize>, entity: &'static str) {
        let material = self.material();
        self.objects.push((placed, material));
        self.object_entities.push((entity, at.start));
    }

    /// The scene, once every entity is read; `None` without a view.
    fn finish(self, r: &mut Reader<'_>) -> Option<Scene> {
        let objects = self.objects;
        for patch in &self.patches.patches {
            // A patch with no area would never be seen: refused like a `p`.
            if let Err(error) = flat_shape(patch.positions.clone()) {
                r.error(patch.span.clone(), error.to_string());
            }
        }
        let meshes = patches_to_meshes(&self.patches);
        let Some(view) = self.view else {
            if !self.view_seen {
                r.error(0..0, "the file has no view `v`: an NFF scene needs one");
            }
            return None;
        };
        let mut scene = Scene::new(view.camera);
        scene.settings = RenderSettings {
            width: view.width,
            height: view.height,
            max_depth: 4,
            min_weight: 0.0,
            ..RenderSettings::default()
        };
        scene.color_space = ColorSpace::Display;
        scene.background = self.background.unwrap_or(Color::ZERO);
        scene.ambient = Color::splat(AMBIENT);
        scene.materials = self.materials;
        let default_intensity = default_light_intensity(self.lights.len());
        scene.lights = self
            .lights
            .into_iter()
            .map(|(position, color)| Light::Point {
                position,
                intensity: color.unwrap_or(default_intensity),
                attenuation: Attenuation::NONE,
            })
            .collect();
        for ((shape, placement), material) in objects {
            scene.add_primitive(shape, material, placement);
        }
        for (mesh, material) in meshes {
            let mesh = scene.add_mesh(mesh);
            scene.add_mesh_instance(mesh, material, Transform::IDENTITY);
        }
        Some(scene)
    }
}

/// Where each shape and each run of patches of `document` (read from
/// `source`) is defined: `s 3` is the file's third sphere.
fn object_sources(source: &str, document: &Document) -> ObjectSources {
    let lines = LineIndex::new(source);
    let mut seen: HashMap<&str, usize> = HashMap::new();
    let primitives = document
        .object_entities
        .iter()
        .map(|&(entity, start)| {
            let count = seen.entry(entity).or_default();
            *count += 1;
            ObjectSource {
                label: format!("{entity} {count}"),
                location: Some(lines.location(start)),
            }
        })
        .collect();
    // One mesh per run of patches of one material (see `patches_to_meshes`).
    let mesh_instances = document
        .patches
        .patches
        .chunk_by(|a, b| a.material == b.material)
        .map(|run| ObjectSource {
            label: format!("pp ({} patches)", run.len()),
            location: Some(lines.location(run[0].span.start)),
        })
        .collect();
    ObjectSources {
        primitives,
        mesh_instances,
    }
}

/// Reads a `b` entity.
fn read_background(r: &mut Reader<'_>) -> Parsed<Color> {
    r.color("the background colour")
}

/// Reads an `l` entity: a position and, if numbers follow, a colour.
fn read_light(r: &mut Reader<'_>) -> Parsed<(Vec3, Option<Color>)> {
    let position = r.vec3("the light's position")?;
    let color = if r.at_number() {
        Some(r.color("the light's colour")?)
    } else {
        None
    };
    Ok((position, color))
}

/// Reports a token where an entity keyword was expected.
fn unknown_entity(r: &mut Reader<'_>, text: &str, at: Range<usize>) -> reader::Reported {
    let keywords = ENTITY_KEYWORDS.join(", ");
    let message = if text.parse::<f64>().is_ok() {
        format!(
            "expected an entity keyword ({keywords}), found the number `{text}`: \
             too many numbers for the entity before it?"
        )
    } else {
        format!("unknown entity `{text}`; expected one of: {keywords} (or a # comment)")
    };
    r.error(at, message)
}

#[cfg(test)]
mod tests;
