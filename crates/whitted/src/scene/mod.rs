//! Scene readers: our TOML format, NFF and Wavefront OBJ, each producing the
//! same [`Scene`] (defined in [`crate::render`](mod@crate::render), which renders it).
//! [`load_any`] picks the reader by the file's extension; every error names
//! `path:line:column`.

mod bom;
mod bpt;
mod camera_override;
mod diagnostic;
mod nff;
pub mod obj;
mod toml_format;
mod whole_number;

pub use bom::{BYTE_ORDER_MARK, without_bom};
pub use bpt::{load_bpt, load_bpt_patches, parse_bpt, parse_bpt_patches};
pub use camera_override::CameraOverride;
pub use diagnostic::{
    Diagnostic, MAX_DIAGNOSTICS, MAX_QUOTED_CHARS, MAX_SHOWN_CHARS, SceneError, Severity,
    limit_warnings, push_limited, quotes_cut,
};
pub use nff::{load_nff, parse_nff};
pub use obj::{load_obj, parse_obj};
pub use toml_format::{
    load_scene, load_scene_with_warnings, parse_scene, parse_scene_with_warnings,
};
pub use whole_number::{WholeNumberError, parse_whole_number};

use std::path::Path;

use crate::render::Scene;

/// The scene formats [`load_any`] reads, by file extension (compared
/// without regard to case).
pub const SCENE_EXTENSIONS: &[&str] = &["toml", "nff", "obj", "bpt"];

/// A scene read from a file, with the warnings of its reader (things in
/// the file that were ignored or replaced).
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene.
    pub scene: Scene,
    /// Warnings, in the order of the files and lines they point at.
    pub warnings: Vec<Diagnostic>,
}

/// What to change in a scene as it is loaded.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// Parts of the camera to replace.
    pub camera: CameraOverride,
}

/// Reads a scene file in the format its extension names: `.toml` (ours),
/// `.nff` (Eric Haines' Neutral File Format) or `.obj` (Wavefront); its
/// warnings are dropped (see [`load_any_with`]).
pub fn load_any(path: &Path) -> Result<Scene, SceneError> {
    load_any_with(path, &LoadOptions::default()).map(|loaded| loaded.scene)
}

/// Reads a scene file like [`load_any`], keeping the reader's warnings, and
/// applies `options`. The light of a bare OBJ model follows a replaced
/// camera's eye.
pub fn load_any_with(path: &Path, options: &LoadOptions) -> Result<LoadedScene, SceneError> {
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let is = |name: &str| extension.eq_ignore_ascii_case(name);
    let mut loaded = if is("nff") {
        LoadedScene {
            scene: load_nff(path)?,
            warnings: Vec::new(),
        }
    } else if is("toml") {
        load_scene_with_warnings(path)?
    } else if is("obj") {
        load_obj(path)?
    } else if is("bpt") {
        load_bpt(path)?
    } else {
        return Err(SceneError::UnknownFormat {
            path: path.to_path_buf(),
        });
    };
    let scene = &mut loaded.scene;
    scene.camera = options.camera.apply(&scene.camera)?;
    if is("obj") || is("bpt") {
        scene.lights = vec![obj::headlight(&scene.camera)];
    }
    Ok(loaded)
}

/// The text of the built-in scene, `scenes/whitted.toml`: a homage to
/// Whitted's 1980 picture (a mirror and a glass sphere over a checkered
/// floor).
pub const DEFAULT_SCENE: &str = include_str!("../../../../scenes/whitted.toml");

/// The built-in scene, [`DEFAULT_SCENE`].
///
/// # Panics
///
/// Never in a released build: the text is compiled in and the test
/// `default_scene_parses` proves it valid, so a failure here can only be
/// a broken build.
pub fn default_scene() -> Scene {
    parse_scene(DEFAULT_SCENE, std::path::Path::new("scenes/whitted.toml"))
        .unwrap_or_else(|error| panic!("the built-in scene is invalid:\n{error}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::shading::Color;

    #[test]
    fn load_any_reads_by_extension_and_refuses_others() {
        let folder = tempfile::tempdir().unwrap();
        let nff = folder.path().join("scene.NFF");
        std::fs::write(
            &nff,
            "v from 0 0 5 at 0 0 0 up 0 1 0 angle 30 hither 1 resolution 4 2",
        )
        .unwrap();
        assert_eq!(load_any(&nff).unwrap().settings.width, 4);
        let toml = folder.path().join("scene.toml");
        std::fs::write(&toml, DEFAULT_SCENE).unwrap();
        assert_eq!(load_any(&toml).unwrap(), default_scene());
        let error = load_any(Path::new("mesh.ply")).unwrap_err();
        assert!(matches!(error, SceneError::UnknownFormat { .. }));
        assert_eq!(
            error.to_string(),
            "cannot read `mesh.ply`: unknown scene format; expected a file ending in .toml, .nff, .obj or .bpt"
        );
        assert!(load_any(Path::new("no_extension")).is_err());
    }

    #[test]
    fn every_reader_reads_a_file_that_starts_with_a_byte_order_mark() {
        let folder = tempfile::tempdir().unwrap();
        let write = |name: &str, text: &str| {
            let path = folder.path().join(name);
            std::fs::write(&path, format!("{BYTE_ORDER_MARK}{text}")).unwrap();
            path
        };
        write("red.mtl", "newmtl red\nKd 1 0 0\n");
        let obj = write(
            "tri.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nmtllib red.mtl\nusemtl red\nf 1 2 3\n",
        );
        let loaded = load_any_with(&obj, &LoadOptions::default()).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        assert_eq!(loaded.scene.objects.meshes[0].positions()[0], Vec3::ZERO);
        assert_eq!(
            loaded.scene.materials[0].diffuse,
            Color::new(1.0, 0.0, 0.0).into()
        );
        let nff = write(
            "a.nff",
            "b 0 0 1\nv from 0 0 5 at 0 0 0 up 0 1 0 angle 30 hither 1 resolution 4 2",
        );
        assert_eq!(
            load_any(&nff).unwrap().background,
            Color::new(0.0, 0.0, 1.0)
        );
        let toml = write("a.toml", DEFAULT_SCENE);
        assert_eq!(load_any(&toml).unwrap(), default_scene());
        // A message's column counts from after the mark.
        let error = parse_nff("\u{feff}x", Path::new("a.nff")).unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("a.nff:1:1: error: unknown entity `x`"),
            "{error}"
        );
    }

    #[test]
    fn default_scene_parses() {
        let scene = default_scene();
        assert_eq!(scene.objects.primitives.len(), 3);
        assert_eq!(scene.lights.len(), 2);
        assert_eq!((scene.settings.width, scene.settings.height), (640, 480));
    }
}
