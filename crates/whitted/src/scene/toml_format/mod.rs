//! whitted's own scene format, in TOML. The full reference with an example
//! per section is `docs/scene-format.md`; in short:
//!
//! ```toml
//! [render]                        # optional
//! width = 640
//! height = 480
//! background = [0.1, 0.2, 0.5]
//! colours = "linear"              # or "display"
//!
//! [camera]                        # required
//! eye = [0, 1, -5]
//! look_at = [0, 0, 0]
//!
//! [materials.glass]               # any number, named by their key
//! transmission = 0.9
//! ior = 1.5
//!
//! [[lights]]                      # any number
//! type = "point"
//! position = [5, 5, -5]
//!
//! [[objects]]                     # any number
//! shape = "sphere"
//! radius = 1
//! material = "glass"
//! transform = [{ translate = [0, 1, 0] }]
//! ```
//!
//! The document is parsed by `toml-span`, which keeps the byte span of every
//! key and value, so each error points at what is wrong. A syntax error stops
//! the parser and gives one error; past that, the whole document is walked and
//! every error is reported: unknown keys, wrong types, missing keys, values
//! out of range, unknown names, and shapes, transforms or cameras their
//! constructors refuse.

mod anti_aliasing;
mod area_light;
mod csg;
mod definition;
mod light;
mod material;
mod object;
mod patches;
mod photons;
mod reader;
mod shapes;
mod texture_filter;

use crate::accel::AccelKind;
use std::path::Path;

use toml_span::Span;
use toml_span::value::Value;

use self::definition::Item;
use self::reader::{Parsed, Reader};
use crate::image::ColorSpace;
use crate::math::Vec3;
use crate::render::{Camera, CameraError};
use crate::render::{MAX_DEPTH, MAX_SAMPLES, MAX_SIDE, check_image_size};
use crate::render::{ObjectSource, RenderSettings, Scene};
use crate::scene::{Diagnostic, LoadedScene, SceneError, without_bom};
use crate::shading::Color;
use crate::shading::Material;
use crate::world::MaterialId;

/// Reads a scene from the text of a scene file; `path` is only used in
/// messages.
pub fn parse_scene(source: &str, path: &Path) -> Result<Scene, SceneError> {
    parse_scene_with_warnings(source, path).map(|loaded| loaded.scene)
}

/// [`parse_scene`], keeping the reader's warnings.
pub fn parse_scene_with_warnings(source: &str, path: &Path) -> Result<LoadedScene, SceneError> {
    let source = without_bom(source);
    let root = toml_span::parse(source).map_err(|error| {
        let span = error.span.start..error.span.end;
        let message = match source.get(span.clone()) {
            Some(text) if is_too_large_integer(text) => format!(
                "invalid TOML: {text} is too large for an integer (TOML integers are 64-bit, \
                 from {} to {})",
                i64::MIN,
                i64::MAX
            ),
            _ => format!("invalid TOML: {error}"),
        };
        SceneError::Invalid {
            diagnostics: vec![Diagnostic::new(path, source, span, message)],
        }
    })?;
    let mut reader = Reader::new(source, path);
    let scene = read_document(&mut reader, &root);
    let (scene, warnings) = reader.finish_with_warnings(scene)?;
    Ok(LoadedScene { scene, warnings })
}

/// True when `text` is a whole number (an optional sign, then digits)
/// outside the 64-bit range that TOML integers have: the parser calls it
/// only "invalid number".
fn is_too_large_integer(text: &str) -> bool {
    let digits = text.strip_prefix(['-', '+']).unwrap_or(text);
    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) && text.parse::<i64>().is_err()
}

/// Reads a scene file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_with_warnings(path).map(|loaded| loaded.scene)
}

/// [`load_scene`], keeping the reader's warnings.
pub fn load_scene_with_warnings(path: &Path) -> Result<LoadedScene, SceneError> {
    let source = crate::limits::read_input_text(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_scene_with_warnings(&source, path)
}

/// The keys allowed at the top level.
const SECTIONS: &[&str] = &[
    "render",
    "camera",
    "materials",
    "lights",
    "objects",
    "definitions",
];

/// Walks the whole document.
fn read_document(r: &mut Reader<'_>, root: &Value<'_>) -> Parsed<Scene> {
    let top = r.table(root, "the scene", "the top level")?;
    let keys = r.check_keys(&top, SECTIONS);
    let render = match top.get("render") {
        Some(value) => read_render(r, value),
        None => Ok(Render::default()),
    };
    if let Ok(render) = &render {
        r.set_color_space(render.color_space);
    }
    let camera = match top.get("camera") {
        Some(value) => read_camera(r, value),
        None => Err(r.error(Span::new(0, 0), "missing required table `[camera]`")),
    };
    let materials = material::read_materials(r, top.get("materials"));
    let lights = light::read_lights(r, top.get("lights"));
    let objects = object::read_objects(r, top.get("objects"), &materials.names);
    let definitions = definition::read_definitions(r, top.get("definitions"), &materials.names);
    keys?;
    let render = render?;
    let mut scene = Scene::new(camera?);
    scene.settings = render.settings;
    scene.background = render.background;
    scene.ambient = render.ambient;
    scene.color_space = render.color_space;
    let lights = lights?;
    for (material, name) in materials.list?.into_iter().zip(&materials.names) {
        scene.add_named_material(name, material);
    }
    let (objects, definitions) = (objects?, definitions?);
    let default_material = MaterialId(scene.materials.len() as u32);
    let (tables, objects): (Vec<usize>, Vec<Item>) = objects.into_iter().unzip();
    if definition::needs_default_material(&objects, &definitions) {
        scene.add_material(Material::default());
    }
    // Where each shape the scene places itself is defined, in the order
    // they are added (instances are not shapes of the top level).
    let arrays = top.get("objects").and_then(|value| value.as_array());
    let lines = r.line_index();
    for (table, _) in tables
        .iter()
        .zip(&objects)
        .filter(|(_, item)| matches!(item, Item::Object(_)))
    {
        let span = arrays.and_then(|arrays| arrays.get(*table)).map(|t| t.span);
        scene.sources.primitives.push(ObjectSource {
            label: format!("objects[{table}]"),
            location: span.map(|span| lines.location(span.start)),
        });
    }
    definition::place_all(r, &mut scene, objects, definitions, default_material)?;
    let light_tables = top.get("lights").and_then(|value| value.as_array());
    for (index, light) in lights.into_iter().enumerate() {
        let shapes = scene.objects.primitives.len();
        // Area lights' shapes were checked where they were read.
        scene
            .add_light(light)
            .map_err(|e| r.error(Span::new(0, 0), e.to_string()))?;
        if scene.objects.primitives.len() > shapes {
            // The glowing shape of an area light, named as the light.
            let span = light_tables
                .and_then(|tables| tables.get(index))
                .map(|t| t.span);
            scene.sources.primitives.push(ObjectSource {
                label: format!("lights[{index}]"),
                location: span.map(|span| lines.location(span.start)),
            });
        }
    }
    Ok(scene)
}

/// The `[render]` table.
#[derive(Debug, Default, PartialEq)]
struct Render {
    settings: RenderSettings,
    background: Color,
    ambient: Color,
    color_space: ColorSpace,
}

/// The keys of `[render]`.
const RENDER_KEYS: &[&str] = &[
    "width",
    "height",
    "samples",
    "max_depth",
    "min_weight",
    "background",
    "ambient",
    "accel",
    "accel_top",
    "accel_bottom",
    "colours",
    photons::PHOTON_KEYS[0],
    photons::PHOTON_KEYS[1],
    photons::PHOTON_KEYS[2],
    anti_aliasing::AA_KEYS[0],
    anti_aliasing::AA_KEYS[1],
    anti_aliasing::AA_KEYS[2],
    anti_aliasing::AA_KEYS[3],
    texture_filter::TEXTURE_FILTER_KEY,
];

fn read_render(r: &mut Reader<'_>, value: &Value<'_>) -> Parsed<Render> {
    let f = r.table(value, "render", "[render]")?;
    let keys = r.check_keys(&f, RENDER_KEYS);
    let d = RenderSettings::default();
    let side = |r: &mut Reader<'_>, v: &Value<'_>, k: &str| r.count(v, k, 1, MAX_SIDE);
    let width = r.or_default(&f, "width", d.width, side);
    let height = r.or_default(&f, "height", d.height, side);
    let samples = r.or_default(&f, "samples", d.samples_per_pixel, |r, v, k| {
        r.count(v, k, 1, MAX_SAMPLES)
    });
    let size = match (width, height) {
        (Ok(width), Ok(height)) => match check_image_size(width, height) {
            Ok(()) => Ok((width, height)),
            Err(error) => {
                let span = r.value_span(&f, "height");
                Err(r.error(span, error.to_string()))
            }
        },
        (width, height) => width.and(height).map(|_| (0, 0)),
    };
    let max_depth = r.or_default(&f, "max_depth", d.max_depth, |r, v, k| {
        r.count(v, k, 0, MAX_DEPTH)
    });
    let min_weight = r.or_default(&f, "min_weight", d.min_weight, Reader::non_negative);
    let background = r.or_default(&f, "background", Color::ZERO, Reader::color);
    let ambient = r.or_default(&f, "ambient", Color::ZERO, Reader::color);
    let accel = r.or_default(&f, "accel", d.accel, read_accel);
    let accel_top = r.optional(&f, "accel_top", read_accel);
    let accel_bottom = r.optional(&f, "accel_bottom", read_accel);
    let color_space = r.or_default(&f, "colours", ColorSpace::Linear, read_color_space);
    let photons = photons::read_photons(r, &f);
    let aa = anti_aliasing::read_anti_aliasing(r, &f);
    let texture_filter = texture_filter::read_texture_filter(r, &f);
    keys?;
    let (width, height) = size?;
    Ok(Render {
        settings: RenderSettings {
            width,
            height,
            samples_per_pixel: samples?,
            max_depth: max_depth?,
            min_weight: min_weight?,
            accel: accel?,
            photons: photons?,
            texture_filter: texture_filter?,
            accel_top: accel_top?,
            accel_bottom: accel_bottom?,
            aa: aa?,
            ..d
        },
        background: background?,
        ambient: ambient?,
        color_space: color_space?,
    })
}

/// What the scene's colour values mean.
fn read_color_space(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<ColorSpace> {
    let (name, span) = r.string(value, key)?;
    ColorSpace::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = ColorSpace::ALL.iter().map(ColorSpace::name).collect();
        r.error(
            span,
            format!(
                "unknown colour convention `{name}` for `{key}`; expected one of: {}",
                names.join(", ")
            ),
        )
    })
}

/// The name of an acceleration structure.
fn read_accel(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<AccelKind> {
    let (name, span) = r.string(value, key)?;
    AccelKind::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = AccelKind::ALL.iter().map(AccelKind::name).collect();
        r.error(
            span,
            format!(
                "unknown acceleration structure `{name}`; expected one of: {}",
                names.join(", ")
            ),
        )
    })
}

/// The keys of `[camera]`.
const CAMERA_KEYS: &[&str] = &["eye", "look_at", "up", "fov"];

fn read_camera(r: &mut Reader<'_>, value: &Value<'_>) -> Parsed<Camera> {
    let f = r.table(value, "camera", "[camera]")?;
    let keys = r.check_keys(&f, CAMERA_KEYS);
    let eye = r.require(&f, "eye", Reader::vec3);
    let look_at = r.require(&f, "look_at", Reader::vec3);
    let up = r.or_default(&f, "up", Vec3::Y, Reader::vec3);
    let fov = r.or_default(&f, "fov", 45.0, Reader::number);
    let camera = Camera::new(eye?, look_at?, up?, fov?);
    keys?;
    camera.map_err(|error| {
        let key = match error {
            CameraError::NoViewDirection => Some("look_at"),
            CameraError::BadUp => Some("up"),
            CameraError::BadFov(_) => Some("fov"),
            CameraError::OutOfRange { what, .. } => Some(what),
            CameraError::NotFinite | CameraError::ModelOutOfRange(_) => None,
        };
        let span = key.map_or(f.span(), |key| r.value_span(&f, key));
        r.error(span, error.to_string())
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The scene in `source`, which must be valid.
    pub(crate) fn scene(source: &str) -> Scene {
        match parse_scene(source, Path::new("test.toml")) {
            Ok(scene) => scene,
            Err(error) => panic!("{error}"),
        }
    }

    /// The messages of the errors in `source`, which must be invalid.
    pub(crate) fn errors(source: &str) -> Vec<String> {
        match parse_scene(source, Path::new("test.toml")) {
            Ok(_) => panic!("no error in:\n{source}"),
            Err(SceneError::Invalid { diagnostics }) => {
                diagnostics.into_iter().map(|d| d.message).collect()
            }
            Err(error) => panic!("{error}"),
        }
    }

    /// A valid camera table, to put in front of a test's own sections.
    pub(crate) const CAMERA: &str = "[camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\n";

    #[test]
    fn a_camera_alone_is_a_scene_with_every_default() {
        let s = scene(CAMERA);
        assert_eq!(s.settings, RenderSettings::default());
        assert_eq!((s.background, s.ambient), (Color::ZERO, Color::ZERO));
        assert_eq!(s.color_space, ColorSpace::Linear);
        assert_eq!(s.camera.up(), Vec3::Y);
        assert_eq!(s.camera.fov_degrees(), 45.0);
        assert!(s.materials.is_empty() && s.lights.is_empty() && s.objects.primitives.is_empty());
    }

    #[test]
    fn render_settings_are_read() {
        let s = scene(&format!(
            "{CAMERA}[render]\nwidth = 32\nheight = 24\nsamples = 4\nmax_depth = 0\n\
             min_weight = 0\nbackground = [0.1, 0.2, 0.3]\nambient = 0.5\naccel = 'linear'\n\
             colours = 'display'\n"
        ));
        assert_eq!(
            s.settings,
            RenderSettings {
                width: 32,
                height: 24,
                samples_per_pixel: 4,
                max_depth: 0,
                min_weight: 0.0,
                accel: AccelKind::Linear,
                ..RenderSettings::default()
            }
        );
        assert_eq!(s.background, Color::new(0.1, 0.2, 0.3));
        assert_eq!(s.ambient, Color::splat(0.5));
        assert_eq!(s.color_space, ColorSpace::Display);
    }

    #[test]
    fn camera_is_read() {
        let s = scene("[camera]\neye = [1, 2, 3]\nlook_at = [0, 1, 0]\nup = [0, 0, 1]\nfov = 30.5");
        assert_eq!(s.camera.eye(), Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(s.camera.look_at(), Vec3::Y);
        assert_eq!(s.camera.up(), Vec3::Z);
        assert_eq!(s.camera.fov_degrees(), 30.5);
    }

    #[test]
    fn every_render_error_is_reported_at_once() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[render]\nwidth = 0\nheight = 1.5\nsamples = '4'\nmax_depth = -1\n\
                 min_weight = -0.5\nbackground = [1, 1]\nambient = -1\nsize = 3\naccel = 'octree'\n\
                 colours = 'srgb'\n"
            )),
            [
                "`width` must be at least 1, got 0",
                "expected an integer for `height`, found a float",
                "expected an integer for `samples`, found a string",
                "`max_depth` must be at least 0, got -1",
                "`min_weight` must not be negative, got -0.5",
                "expected 3 numbers for `background`, found 2",
                "`ambient` must not be negative, got -1",
                "unknown key `size` in [render]; expected one of: width, height, samples, \
                 max_depth, min_weight, background, ambient, accel, accel_top, accel_bottom, colours, \
                 photons, gather, radius, aa, aa_threshold, aa_depth, aa_min_depth, texture_filter",
                "unknown acceleration structure `octree`; expected one of: bvh, kdtree, grid, linear",
                "unknown colour convention `srgb` for `colours`; expected one of: linear, display",
            ]
        );
    }

    #[test]
    fn samples_and_pixels_are_bounded_by_the_render_limits() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[render]\nwidth = 1\nheight = 1\nsamples = 4294967295\n"
            )),
            ["`samples` must be at most 65536, got 4294967295"]
        );
        assert_eq!(
            errors(&format!(
                "{CAMERA}[render]\nwidth = 65535\nheight = 65535\n"
            )),
            ["the image 65535x65535 is too large: at most 268435456 pixels are allowed"]
        );
        assert_eq!(
            errors(&format!(
                "{CAMERA}[render]\nsamples = 99999999999999999999\n"
            )),
            [
                "invalid TOML: 99999999999999999999 is too large for an integer (TOML integers \
                 are 64-bit, from -9223372036854775808 to 9223372036854775807)"
            ]
        );
        assert!(!is_too_large_integer("9223372036854775807"));
        assert!(is_too_large_integer("-9223372036854775809"));
        assert!(!is_too_large_integer("1_000"));
        let s = scene(&format!("{CAMERA}[render]\nsamples = 65536\n"));
        assert_eq!(s.settings.samples_per_pixel, MAX_SAMPLES);
    }

    #[test]
    fn camera_errors_point_at_the_culprit() {
        assert_eq!(
            errors("[render]\nwidth = 3\n"),
            ["missing required table `[camera]`"]
        );
        assert_eq!(
            errors("[camera]\nlook_at = [0, 0, 0]\nfov = 'wide'\nzoom = 2\n"),
            [
                "missing required key `eye` in [camera]",
                "expected a number for `fov`, found a string",
                "unknown key `zoom` in [camera]; expected one of: eye, look_at, up, fov",
            ]
        );
        assert_eq!(
            errors("[camera]\neye = [0, 0, 0]\nlook_at = [0, 0, 0]\n"),
            ["the camera's eye and look_at are the same point"]
        );
        assert_eq!(
            errors(&format!("{CAMERA}up = [0, 0, 2]\n")),
            ["the camera's up vector is zero or parallel to the view direction"]
        );
        assert_eq!(
            errors(&format!("{CAMERA}fov = 180\n")),
            ["the field of view must be between 0 and 180 degrees, got 180"]
        );
        assert_eq!(
            errors("camera = 3"),
            ["expected a table for `camera`, found an integer"]
        );
    }

    #[test]
    fn unknown_top_level_keys_are_errors() {
        assert_eq!(
            errors(&format!("title = 'x'\n{CAMERA}")),
            [
                "unknown key `title` in the top level; expected one of: render, camera, \
              materials, lights, objects, definitions"
            ]
        );
    }

    #[test]
    fn a_syntax_error_gives_one_error_at_its_place() {
        let Err(SceneError::Invalid { diagnostics }) =
            parse_scene("[camera]\neye = [0, 0\n", Path::new("s.toml"))
        else {
            panic!("expected a syntax error");
        };
        assert_eq!(diagnostics.len(), 1);
        assert!(diagnostics[0].message.starts_with("invalid TOML: "));
        assert_eq!(diagnostics[0].line, 2);
    }

    #[test]
    fn errors_are_sorted_by_their_place_in_the_file() {
        let Err(SceneError::Invalid { diagnostics }) = parse_scene(
            "[render]\nwidth = 0\n[camera]\neye = 1\nlook_at = 1\n",
            Path::new("s.toml"),
        ) else {
            panic!("expected errors");
        };
        let lines: Vec<usize> = diagnostics.iter().map(|d| d.line).collect();
        assert_eq!(lines, [2, 4, 5]);
    }

    #[test]
    fn a_missing_file_is_an_io_error_naming_it() {
        let error = load_scene(Path::new("/nonexistent/scene.toml")).unwrap_err();
        assert!(matches!(error, SceneError::Io { .. }));
        assert!(error.to_string().contains("/nonexistent/scene.toml"));
    }
}
