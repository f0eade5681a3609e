//! Wavefront OBJ models with their MTL material libraries. What is read,
//! how materials are mapped and what a bare model is lit and seen by is in
//! `docs/obj.md`; in short:
//!
//! ```text
//! mtllib kitchen.mtl          material library, relative to the OBJ file
//! o table / g legs            objects and groups (read; meshes are per material)
//! v X Y Z                     position        vt U V      texture coordinates
//! vn X Y Z                    normal
//! usemtl Dark Wood            the material of the faces that follow
//! s 1 / s off                 smoothing group; off = flat
//! f 1 2 3 4 / f 1/1 2/2 3/3 / f 1//1 2//2 3//3 / f -3/-3/-3 -2/-2/-2 -1/-1/-1
//! ```
//!
//! Faces are read by us (with their places, for messages; polygons ear
//! clipped in their own plane); MTL files by `tobj`. The scene has one
//! [`crate::mesh::TriangleMesh`] per material, a camera framing the model
//! and a light at the eye.

mod build;
mod file_names;
mod maps;
mod mtl;
mod reader;
mod text;

use std::collections::HashMap;
use std::path::Path;

use self::build::build_meshes;
use self::file_names::library_paths;
use self::mtl::read_library;
use self::reader::{NONE, ObjData, read_obj};
use crate::limits::MemoryBudget;
use crate::math::{Aabb, Transform};
use crate::render::Camera;
use crate::render::{LineIndex, ObjectSource, RenderSettings, Scene};
use crate::scene::{
    Diagnostic, LoadedScene, SceneError, Severity, limit_warnings, push_limited, without_bom,
};
use crate::shading::Color;
use crate::shading::Material;
use crate::shading::texture::ImageCache;
use crate::shading::{Attenuation, Light};
use crate::world::MaterialId;

/// The vertical field of view of the camera framing a bare model, degrees.
pub const DEFAULT_FOV_DEGREES: f64 = 50.0;

/// The ambient light `Ia` of an OBJ scene.
pub const AMBIENT: f64 = 0.1;

/// Reads an OBJ model from its text; `path` names it in messages and is
/// where `mtllib` files are looked for (beside it).
pub fn parse_obj(source: &str, path: &Path) -> Result<LoadedScene, SceneError> {
    let source = without_bom(source);
    let mut data = read_obj(source, path);
    let mut diagnostics = std::mem::take(&mut data.diagnostics);
    let mut materials = HashMap::new();
    let mut images = ImageCache::default();
    let folder = path.parent().unwrap_or(Path::new(""));
    let libraries = data
        .libraries
        .iter()
        .flat_map(|(names, span)| library_paths(names, span.clone(), folder));
    for (file, span) in libraries {
        match crate::limits::read_input_text(&file) {
            Ok(text) => {
                let library = read_library(&text, &file, &mut images);
                diagnostics.extend(library.diagnostics);
                materials.extend(library.materials);
            }
            Err(error) => push_limited(&mut diagnostics, Severity::Warning, || {
                Diagnostic::warning(
                    path,
                    source,
                    span,
                    format!(
                        "cannot read the material library `{}` ({error}); its materials are \
                         grey",
                        file.display()
                    ),
                )
            }),
        }
    }
    if data.faces.is_empty() && diagnostics.iter().all(|d| d.severity != Severity::Error) {
        diagnostics.push(Diagnostic::new(
            path,
            source,
            0..0,
            "the file has no faces `f`: nothing to render",
        ));
    }
    let (errors, mut warnings): (Vec<Diagnostic>, Vec<Diagnostic>) = diagnostics
        .into_iter()
        .partition(|d| d.severity == Severity::Error);
    if !errors.is_empty() {
        return Err(SceneError::Invalid {
            diagnostics: errors,
        });
    }
    // The meshes take about what the data read takes, beside it until
    // they are built (the world charges them again before it is built).
    let _meshes = MemoryBudget::current()
        .charge(
            "building the model's meshes",
            data.heap_bytes(),
            "use a smaller model",
        )
        .map_err(|error| SceneError::Invalid {
            diagnostics: vec![Diagnostic::new(path, source, 0..0, error.to_string())],
        })?;
    let scene = build_scene(&data, &materials, path, source, &mut warnings)?;
    Ok(LoadedScene {
        scene,
        warnings: limit_warnings(warnings),
    })
}

/// Reads an OBJ file and the material libraries it names.
pub fn load_obj(path: &Path) -> Result<LoadedScene, SceneError> {
    let source = crate::limits::read_input_text(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_obj(&source, path)
}

/// The light of a bare model: a white point light at the eye, so whatever
/// the camera sees is lit (and no shadow it could see is cast).
pub fn headlight(camera: &Camera) -> Light {
    Light::Point {
        position: camera.eye(),
        intensity: Color::ONE,
        attenuation: Attenuation::NONE,
    }
}

fn build_scene(
    data: &ObjData,
    materials: &HashMap<String, Material>,
    path: &Path,
    source: &str,
    warnings: &mut Vec<Diagnostic>,
) -> Result<Scene, SceneError> {
    let invalid = |message: String| SceneError::Invalid {
        diagnostics: vec![Diagnostic::new(path, source, 0..0, message)],
    };
    let meshes = build_meshes(data).map_err(|e| invalid(e.to_string()))?;
    let bounds = meshes.iter().fold(Aabb::default(), |b, (_, mesh)| {
        b.union(&Aabb::from_points(mesh.positions().iter().copied()))
    });
    let settings = RenderSettings::default();
    let aspect = f64::from(settings.width) / f64::from(settings.height);
    let camera = Camera::framing(&bounds, aspect, DEFAULT_FOV_DEGREES)
        .map_err(|e| invalid(format!("cannot frame the model: {e}")))?;
    let mut scene = Scene::new(camera);
    scene.settings = settings;
    scene.ambient = Color::splat(AMBIENT);
    scene.lights = vec![headlight(&scene.camera)];
    let lines = LineIndex::new(source);
    for (slot, mesh) in meshes {
        let material = if slot == NONE {
            Material::default()
        } else {
            let (name, span) = &data.material_uses[slot as usize];
            materials.get(name).cloned().unwrap_or_else(|| {
                push_limited(warnings, Severity::Warning, || {
                    Diagnostic::warning(
                        path,
                        source,
                        span.clone(),
                        format!("no material `{name}` in the material libraries; it is grey"),
                    )
                });
                Material::default()
            })
        };
        let used = data.material_uses.get(slot as usize);
        let name = used.map_or("", |(n, _)| n);
        let material: MaterialId = scene.add_named_material(name, material);
        let mesh = scene.add_mesh(mesh);
        scene.add_mesh_instance(mesh, material, Transform::IDENTITY);
        scene.sources.mesh_instances.push(ObjectSource {
            label: used.map_or("the faces before any usemtl".into(), |(name, _)| {
                format!("the faces of usemtl {name}")
            }),
            location: used.map(|(_, span)| lines.location(span.start)),
        });
    }
    warnings.sort_by_key(|d| (d.path.clone(), d.line, d.column));
    Ok(scene)
}

#[cfg(test)]
mod tests;
