//! The scene: what to render, independent of the file format it came from.
//!
//! Every reader (our TOML format, NFF and Wavefront OBJ) produces the same
//! [`Scene`]; the renderer only ever sees this. [`load_any`] picks the
//! reader by the file's extension.

mod camera_override;
mod diagnostic;
mod nff;
pub mod obj;
mod toml_format;

pub use camera_override::CameraOverride;
pub use diagnostic::{
    Diagnostic, MAX_DIAGNOSTICS, MAX_SHOWN_CHARS, SceneError, Severity, push_limited,
};
pub use nff::{load_nff, parse_nff};
pub use obj::{load_obj, parse_obj};
pub use toml_format::{load_scene, parse_scene};

use std::path::Path;

use crate::accel::AccelKind;
use crate::camera::Camera;
use crate::color_space::ColorSpace;
use crate::light::Light;
use crate::material::{Material, MaterialId};
use crate::math::{Color, Transform};
use crate::mesh::{MeshId, TriangleMesh};
use crate::shape::Shape;

/// The scene formats [`load_any`] reads, by file extension (compared
/// without regard to case).
pub const SCENE_EXTENSIONS: &[&str] = &["toml", "nff", "obj"];

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
        LoadedScene {
            scene: load_scene(path)?,
            warnings: Vec::new(),
        }
    } else if is("obj") {
        load_obj(path)?
    } else {
        return Err(SceneError::UnknownFormat {
            path: path.to_path_buf(),
        });
    };
    let scene = &mut loaded.scene;
    scene.camera = options.camera.apply(&scene.camera)?;
    if is("obj") {
        scene.lights = vec![obj::headlight(&scene.camera)];
    }
    Ok(loaded)
}

/// Index of a transform in [`Scene::transforms`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TransformId(pub u32);

/// A shape placed in the world with a material.
#[derive(Clone, Debug, PartialEq)]
pub struct Primitive {
    /// The geometry, in object space.
    pub shape: Shape,
    /// What its surface is made of.
    pub material: MaterialId,
    /// Where object space sits in the world; `None` means they coincide.
    pub transform: Option<TransformId>,
}

/// A triangle mesh placed in the world with a material.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshInstance {
    /// The mesh, in [`Scene::meshes`].
    pub mesh: MeshId,
    /// What its surface is made of.
    pub material: MaterialId,
    /// Where the mesh's space sits in the world; `None` means they coincide.
    pub transform: Option<TransformId>,
}

/// How to render: image size, sampling and recursion limits.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel (1 means exactly the pixel centre).
    pub samples_per_pixel: u32,
    /// Deepest reflection/refraction recursion; 0 traces primary rays only.
    pub max_depth: u32,
    /// A branch whose weight on the pixel falls below this stops early
    /// (adaptive depth control, Hall and Greenberg 1983).
    pub min_weight: f64,
    /// The acceleration structure to build over the primitives.
    pub accel: AccelKind,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: 1,
            max_depth: 8,
            min_weight: 1e-3,
            accel: AccelKind::default(),
        }
    }
}

/// Everything needed to render one picture.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The viewpoint.
    pub camera: Camera,
    /// Image size and quality.
    pub settings: RenderSettings,
    /// Colour of rays that hit nothing.
    pub background: Color,
    /// Global ambient light `Ia`.
    pub ambient: Color,
    /// What the colour values of the scene (and so of its picture) mean:
    /// linear light, or display values (NFF).
    pub color_space: ColorSpace,
    /// Materials, indexed by [`MaterialId`].
    pub materials: Vec<Material>,
    /// Light sources.
    pub lights: Vec<Light>,
    /// Object-to-world transforms, indexed by [`TransformId`].
    pub transforms: Vec<Transform>,
    /// The objects.
    pub primitives: Vec<Primitive>,
    /// Triangle meshes, indexed by [`MeshId`].
    pub meshes: Vec<TriangleMesh>,
    /// Meshes placed in the world.
    pub mesh_instances: Vec<MeshInstance>,
}

/// The text of the built-in scene, `scenes/whitted.toml`: a homage to
/// Whitted's 1980 picture (a mirror and a glass sphere over a checkered
/// floor).
pub const DEFAULT_SCENE: &str = include_str!("../../../../scenes/whitted.toml");

impl Scene {
    /// The built-in scene, [`DEFAULT_SCENE`].
    ///
    /// # Panics
    ///
    /// Never in a released build: the text is compiled in and the test
    /// `default_scene_parses` proves it valid, so a failure here can only be
    /// a broken build.
    pub fn default_scene() -> Self {
        parse_scene(DEFAULT_SCENE, std::path::Path::new("scenes/whitted.toml"))
            .unwrap_or_else(|error| panic!("the built-in scene is invalid:\n{error}"))
    }

    /// An empty scene seen by `camera`, with default settings, a black
    /// background, no ambient light and linear colours.
    pub fn new(camera: Camera) -> Self {
        Self {
            camera,
            settings: RenderSettings::default(),
            background: Color::ZERO,
            ambient: Color::ZERO,
            color_space: ColorSpace::Linear,
            materials: Vec::new(),
            lights: Vec::new(),
            transforms: Vec::new(),
            primitives: Vec::new(),
            meshes: Vec::new(),
            mesh_instances: Vec::new(),
        }
    }

    /// Adds a material and returns its id.
    pub fn add_material(&mut self, material: Material) -> MaterialId {
        self.materials.push(material);
        MaterialId((self.materials.len() - 1) as u32)
    }

    /// How many primitives the scene has: its shapes and the triangles of
    /// every mesh instance.
    pub fn primitive_count(&self) -> usize {
        self.primitives.len()
            + self
                .mesh_instances
                .iter()
                .map(|m| self.meshes[m.mesh.0 as usize].len())
                .sum::<usize>()
    }

    /// Stores a transform, or nothing for the identity.
    fn add_transform(&mut self, transform: Transform) -> Option<TransformId> {
        (!transform.is_identity()).then(|| {
            self.transforms.push(transform);
            TransformId((self.transforms.len() - 1) as u32)
        })
    }

    /// Adds a mesh and returns its id (place it with [`Scene::add_mesh_instance`]).
    pub fn add_mesh(&mut self, mesh: TriangleMesh) -> MeshId {
        self.meshes.push(mesh);
        MeshId((self.meshes.len() - 1) as u32)
    }

    /// Places a mesh in the world with a material and a transform.
    pub fn add_mesh_instance(&mut self, mesh: MeshId, material: MaterialId, transform: Transform) {
        let transform = self.add_transform(transform);
        self.mesh_instances.push(MeshInstance {
            mesh,
            material,
            transform,
        });
    }

    /// Adds a shape with a material and an object-to-world transform (the
    /// identity is stored as no transform at all).
    pub fn add_primitive(&mut self, shape: Shape, material: MaterialId, transform: Transform) {
        let transform = self.add_transform(transform);
        self.primitives.push(Primitive {
            shape,
            material,
            transform,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(load_any(&toml).unwrap(), Scene::default_scene());
        let error = load_any(Path::new("mesh.ply")).unwrap_err();
        assert!(matches!(error, SceneError::UnknownFormat { .. }));
        assert_eq!(
            error.to_string(),
            "cannot read `mesh.ply`: unknown scene format; expected a file ending in .toml, .nff or .obj"
        );
        assert!(load_any(Path::new("no_extension")).is_err());
    }

    #[test]
    fn default_scene_parses() {
        let scene = Scene::default_scene();
        assert_eq!(scene.primitives.len(), 3);
        assert_eq!(scene.lights.len(), 2);
        assert_eq!((scene.settings.width, scene.settings.height), (640, 480));
    }
}
