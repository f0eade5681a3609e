//! Definitions and their instances: named groups of objects, or OBJ
//! models, that are not drawn by themselves, and objects that place one.
//!
//! ```toml
//! [definitions.leaf]              # a group of objects, not drawn itself
//! objects = [
//!     { shape = "sphere", radius = 0.2, material = "green" },
//! ]
//!
//! [[definitions.branch.objects]]  # the same, one table per object
//! instance = "leaf"               # instances of other definitions too
//! transform = { translate = [0, 1, 0] }
//!
//! [definitions.bunny]
//! mesh = "models/bunny.obj"       # an OBJ model, relative to the scene
//!
//! [[objects]]
//! instance = "branch"             # places a definition
//! material = "gold"               # optional: every surface of it is gold
//! transform = [{ rotate = { axis = [0, 1, 0], angle = 30 } }]
//! ```
//!
//! Names are resolved once every definition is read, so a definition may
//! place one written after it. A definition that places itself, directly
//! or through others, is an error naming the chain; so is an unknown name
//! and a chain deeper than [`MAX_INSTANCE_DEPTH`].

use std::collections::HashMap;

use toml_span::Span;
use toml_span::value::Value;

use super::object::{Object, read_objects};
use super::reader::{Fields, Parsed, Reader, all, list};
use crate::math::Transform;
use crate::mesh::TriangleMesh;
use crate::render::Scene;
use crate::scene::{SceneError, load_obj};
use crate::shading::Material;
use crate::world::{DefinitionId, MAX_INSTANCE_DEPTH, MaterialId, Objects};

/// The key of an object that places a definition.
pub(super) const INSTANCE_KEY: &str = "instance";

/// Keys of an object that places a definition.
const PLACEMENT_KEYS: &[&str] = &[INSTANCE_KEY, "material", "transform"];

/// Keys of a definition: exactly one of them.
const DEFINITION_KEYS: &[&str] = &["objects", "mesh"];

/// What `[[objects]]` (or a definition's `objects`) holds.
#[derive(Debug)]
pub(super) enum Item {
    /// A shape.
    Object(Object),
    /// An instance of a definition.
    Instance(Placement),
}

/// An object that places a definition, its name not yet resolved.
#[derive(Debug)]
pub(super) struct Placement {
    /// The definition's name.
    name: String,
    /// Where the name is written.
    span: Span,
    /// Index of the material replacing the definition's own, if any.
    material: Option<usize>,
    /// Definition space to the placing space.
    transform: Transform,
}

/// A definition read from the file.
#[derive(Debug)]
pub(super) struct Definition {
    name: String,
    content: Content,
}

#[derive(Debug)]
enum Content {
    Objects(Vec<Item>),
    /// The meshes of an OBJ model, one per material, with the material.
    Mesh(Vec<(TriangleMesh, String, Material)>),
}

/// Reads an object with an `instance` key; `material` and `transform` are
/// what the object's own reader found.
pub(super) fn read_placement(
    r: &mut Reader<'_>,
    f: &Fields<'_, '_>,
    material: Parsed<Option<usize>>,
    transform: Parsed<Transform>,
) -> Parsed<Item> {
    let keys = r.check_keys(f, PLACEMENT_KEYS);
    let name = r.require(f, INSTANCE_KEY, Reader::string);
    keys?;
    let (name, span) = name?;
    Ok(Item::Instance(Placement {
        name: name.to_string(),
        span,
        material: material?,
        transform: transform?,
    }))
}

/// Reads the `[definitions]` table, if any; `materials` are the names
/// defined.
pub(super) fn read_definitions(
    r: &mut Reader<'_>,
    value: Option<&Value<'_>>,
    materials: &[String],
) -> Parsed<Vec<Definition>> {
    let Some(value) = value else {
        return Ok(Vec::new());
    };
    let table = r.table(value, "definitions", "`[definitions]`")?;
    let entries = table.entries_in_file_order();
    all(entries.into_iter().map(|(key, value)| {
        let name = key.name.to_string();
        let f = r.table(value, &name, "definition")?;
        let keys = r.check_keys(&f, DEFINITION_KEYS);
        let content = match (f.get("objects"), f.get("mesh")) {
            (Some(objects), None) => read_objects(r, Some(objects), materials)
                .map(|items| Content::Objects(items.into_iter().map(|(_, item)| item).collect())),
            (None, Some(mesh)) => read_mesh(r, mesh).map(Content::Mesh),
            (Some(_), Some(mesh)) => Err(r.error(
                r.span_of(mesh),
                format!("definition `{name}` has both `objects` and `mesh`; give one"),
            )),
            (None, None) => Err(r.error(
                key.span,
                format!(
                    "definition `{name}` is empty; expected one of: {}",
                    list(DEFINITION_KEYS)
                ),
            )),
        };
        keys?;
        Ok(Definition {
            name,
            content: content?,
        })
    }))
}

/// The meshes of the OBJ file `mesh` names, with their materials. The
/// file's errors are reported at `mesh`; its warnings are passed on, at
/// their own places.
fn read_mesh(
    r: &mut Reader<'_>,
    value: &Value<'_>,
) -> Parsed<Vec<(TriangleMesh, String, Material)>> {
    let (name, span) = r.string(value, "mesh")?;
    let path = r.beside(name);
    let problems = |diagnostics: &[crate::scene::Diagnostic]| {
        let lines: Vec<String> = diagnostics.iter().map(|d| d.to_string()).collect();
        lines.join("\n")
    };
    let loaded = match load_obj(&path) {
        Ok(loaded) => loaded,
        Err(SceneError::Invalid { diagnostics }) => {
            // Its own errors say what is wrong: the file, or the memory
            // budget it passed.
            let message = format!(
                "the model `{name}` cannot be read:\n{}",
                problems(&diagnostics)
            );
            return Err(r.error(span, message));
        }
        Err(SceneError::Io { path, source }) => {
            let message = format!("cannot read the model `{}`: {source}", path.display());
            return Err(r.error(span, message));
        }
        Err(other) => return Err(r.error(span, other.to_string())),
    };
    r.pass_on_warnings(loaded.warnings);
    let mut scene = loaded.scene;
    let meshes = std::mem::take(&mut scene.objects.meshes);
    Ok(scene
        .objects
        .mesh_instances
        .iter()
        .zip(meshes)
        .map(|(placed, mesh)| {
            let m = placed.material;
            (
                mesh,
                scene.material_name(m),
                scene.materials[m.0 as usize].clone(),
            )
        })
        .collect())
}

/// Puts the objects and the definitions they place into `scene`:
/// resolves names, refuses unknown ones, cycles and chains deeper than
/// [`MAX_INSTANCE_DEPTH`], and adds the definitions children first.
/// Objects without a material get `default_material`.
pub(super) fn place_all(
    r: &mut Reader<'_>,
    scene: &mut Scene,
    objects: Vec<Item>,
    definitions: Vec<Definition>,
    default_material: MaterialId,
) -> Parsed<()> {
    let names: HashMap<&str, usize> = definitions
        .iter()
        .enumerate()
        .map(|(i, d)| (d.name.as_str(), i))
        .collect();
    let known: Vec<&str> = definitions.iter().map(|d| d.name.as_str()).collect();
    // Each item's definition, resolved: `None` for a shape.
    let mut resolve = |items: &[Item]| -> Parsed<Vec<Option<usize>>> {
        all(items.iter().map(|item| match item {
            Item::Object(_) => Ok(None),
            Item::Instance(p) => names
                .get(p.name.as_str())
                .map(|&d| Some(d))
                .ok_or_else(|| r.error(p.span, unknown_definition(&p.name, &known))),
        }))
    };
    let top = resolve(&objects);
    let inner: Vec<Parsed<Vec<Option<usize>>>> = definitions
        .iter()
        .map(|d| match &d.content {
            Content::Objects(items) => resolve(items),
            Content::Mesh(_) => Ok(Vec::new()),
        })
        .collect();
    let top = top?;
    let inner = all(inner)?;
    let order = children_first(r, &definitions, &inner)?;
    // How deep each definition's instances nest, itself included.
    let mut nesting = vec![0usize; definitions.len()];
    for &d in &order {
        nesting[d] = 1 + inner[d]
            .iter()
            .flatten()
            .map(|&c| nesting[c])
            .max()
            .unwrap_or(0);
    }
    let too_deep: Vec<Parsed<()>> = objects
        .iter()
        .zip(&top)
        .filter_map(|(item, d)| Some((item, (*d)?)))
        .filter(|&(_, d)| nesting[d] > MAX_INSTANCE_DEPTH)
        .map(|(item, d)| {
            let Item::Instance(p) = item else {
                unreachable!("only instances resolve to a definition")
            };
            let chain = deepest_chain(d, &definitions, &inner, &nesting);
            Err(r.error(
                p.span,
                format!(
                    "instances nest {} deep here ({chain}); at most {MAX_INSTANCE_DEPTH} are \
                     allowed",
                    nesting[d]
                ),
            ))
        })
        .collect();
    all(too_deep)?;

    let mut definitions: Vec<Option<Definition>> = definitions.into_iter().map(Some).collect();
    let mut ids = vec![DefinitionId(u32::MAX); definitions.len()];
    for &d in &order {
        let definition = definitions[d]
            .take()
            .expect("each definition is added once");
        let mut placed = Objects::default();
        match definition.content {
            Content::Objects(items) => {
                add_items(&mut placed, items, &inner[d], &ids, default_material);
            }
            Content::Mesh(meshes) => {
                for (mesh, name, material) in meshes {
                    let material = scene.add_named_material(&name, material);
                    let mesh = placed.add_mesh(mesh);
                    placed.add_mesh_instance(mesh, material, Transform::IDENTITY);
                }
            }
        }
        ids[d] = scene.objects.add_definition(placed);
    }
    add_items(&mut scene.objects, objects, &top, &ids, default_material);
    Ok(())
}

/// Whether any object here or in a definition has no material of its own.
pub(super) fn needs_default_material(objects: &[Item], definitions: &[Definition]) -> bool {
    let lacks = |items: &[Item]| {
        items
            .iter()
            .any(|item| matches!(item, Item::Object(o) if o.material.is_none()))
    };
    lacks(objects)
        || definitions
            .iter()
            .any(|d| matches!(&d.content, Content::Objects(items) if lacks(items)))
}

/// Adds `items` to `objects`, `resolved` giving each instance's
/// definition and `ids` where it was added.
fn add_items(
    objects: &mut Objects,
    items: Vec<Item>,
    resolved: &[Option<usize>],
    ids: &[DefinitionId],
    default_material: MaterialId,
) {
    let material = |index: Option<usize>| index.map(|i| MaterialId(i as u32));
    for (item, definition) in items.into_iter().zip(resolved) {
        match item {
            Item::Object(o) => {
                let m = material(o.material).unwrap_or(default_material);
                objects.add_primitive(o.shape, m, o.transform);
            }
            Item::Instance(p) => {
                let id = ids[definition.expect("an instance is resolved")];
                objects.add_instance(id, material(p.material), p.transform);
            }
        }
    }
}

/// The definitions in an order where each comes after those it places;
/// a cycle is reported at the instance that closes it, with its chain.
fn children_first(
    r: &mut Reader<'_>,
    definitions: &[Definition],
    inner: &[Vec<Option<usize>>],
) -> Parsed<Vec<usize>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    let mut marks = vec![Mark::New; definitions.len()];
    let mut order = Vec::with_capacity(definitions.len());
    let mut failed = None;
    for start in 0..definitions.len() {
        if marks[start] != Mark::New {
            continue;
        }
        // Depth-first, without recursion: (definition, next item to look at).
        let mut path: Vec<(usize, usize)> = vec![(start, 0)];
        marks[start] = Mark::Open;
        while let Some(&mut (d, ref mut next)) = path.last_mut() {
            let Some(item) = inner[d].get(*next).copied() else {
                marks[d] = Mark::Done;
                order.push(d);
                path.pop();
                continue;
            };
            let at = *next;
            *next += 1;
            let Some(child) = item else { continue };
            match marks[child] {
                Mark::Done => {}
                Mark::New => {
                    marks[child] = Mark::Open;
                    path.push((child, 0));
                }
                Mark::Open => {
                    let from = path.iter().position(|&(p, _)| p == child).unwrap_or(0);
                    let mut chain: Vec<String> = path[from..]
                        .iter()
                        .map(|&(p, _)| format!("`{}`", definitions[p].name))
                        .collect();
                    chain.push(format!("`{}`", definitions[child].name));
                    let Content::Objects(items) = &definitions[d].content else {
                        unreachable!("only groups place definitions")
                    };
                    let Item::Instance(p) = &items[at] else {
                        unreachable!("only instances resolve to a definition")
                    };
                    failed = Some(r.error(
                        p.span,
                        format!(
                            "definitions place each other in a cycle: {}",
                            chain.join(" → ")
                        ),
                    ));
                }
            }
        }
    }
    match failed {
        Some(reported) => Err(reported),
        None => Ok(order),
    }
}

/// The names along the deepest chain of instances from `d`.
fn deepest_chain(
    mut d: usize,
    definitions: &[Definition],
    inner: &[Vec<Option<usize>>],
    nesting: &[usize],
) -> String {
    let mut names = vec![format!("`{}`", definitions[d].name)];
    while let Some(&child) = inner[d].iter().flatten().max_by_key(|&&c| nesting[c]) {
        names.push(format!("`{}`", definitions[child].name));
        d = child;
    }
    names.join(" → ")
}

fn unknown_definition(name: &str, known: &[&str]) -> String {
    if known.is_empty() {
        format!(
            "unknown definition `{name}`; no definitions are defined (add a \
             [definitions.{name}] table)"
        )
    } else {
        format!(
            "unknown definition `{name}`; the definitions are: {}",
            known.join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, scene};
    use crate::world::{DefinitionId, MaterialId};

    #[test]
    fn definitions_are_added_children_first_and_placed_with_their_overrides() {
        let s = scene(&format!(
            "{CAMERA}[materials.gold]\n\
             [[definitions.tree.objects]]\nshape = 'sphere'\nradius = 1\n\
             [[definitions.tree.objects]]\ninstance = 'leaf'\nmaterial = 'gold'\n\
             transform = {{ translate = [0, 1, 0] }}\n\
             [definitions.leaf]\nobjects = [{{ shape = 'sphere', radius = 0.1 }}]\n\
             [[objects]]\ninstance = 'tree'\n\
             [[objects]]\ninstance = 'tree'\ntransform = {{ scale = 2 }}\n\
             [[objects]]\nshape = 'sphere'\nradius = 3\nmaterial = 'gold'\n"
        ));
        let o = &s.objects;
        assert_eq!(o.definitions.len(), 2);
        // `leaf` is placed by `tree`, so it comes first.
        assert_eq!(o.definitions[0].primitives[0].shape.bounds().max.x, 0.1);
        let tree = &o.definitions[1];
        assert_eq!(tree.instances[0].definition, DefinitionId(0));
        assert_eq!(tree.instances[0].material, Some(MaterialId(0)));
        assert!(tree.instances[0].transform.is_some());
        // Objects without a material share the default one.
        assert_eq!(tree.primitives[0].material, MaterialId(1));
        assert_eq!(o.instances.len(), 2);
        assert!(o.instances.iter().all(|i| i.definition == DefinitionId(1)));
        assert!(o.instances[0].transform.is_none() && o.instances[1].transform.is_some());
        assert_eq!(o.primitives.len(), 1);
        assert_eq!(o.primitive_count(), 1 + 2 * 2);
    }

    #[test]
    fn a_mesh_definition_brings_the_model_and_its_materials() {
        let folder = std::env::temp_dir().join(format!("whitted-def-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        std::fs::write(
            folder.join("quad.obj"),
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
        )
        .unwrap();
        let source = format!(
            "{CAMERA}[definitions.quad]\nmesh = 'quad.obj'\n\
             [[objects]]\ninstance = 'quad'\n"
        );
        let s = crate::scene::parse_scene(&source, &folder.join("scene.toml")).unwrap();
        std::fs::remove_dir_all(&folder).unwrap();
        let quad = &s.objects.definitions[0];
        assert_eq!(quad.meshes.len(), 1);
        assert_eq!(quad.meshes[0].len(), 2);
        assert_eq!(s.materials.len(), 1);
        assert_eq!(s.objects.primitive_count(), 2);
    }

    #[test]
    fn a_models_warnings_are_passed_on_at_their_own_place() {
        let folder = tempfile::tempdir().unwrap();
        std::fs::write(
            folder.path().join("quad.obj"),
            "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let source = format!(
            "{CAMERA}[definitions.quad]\nmesh = 'quad.obj'\n\
             [[objects]]\ninstance = 'quad'\n"
        );
        let loaded =
            crate::scene::parse_scene_with_warnings(&source, &folder.path().join("scene.toml"))
                .unwrap();
        assert_eq!(loaded.scene.objects.primitive_count(), 1);
        let [warning] = &loaded.warnings[..] else {
            panic!("{:?}", loaded.warnings);
        };
        assert_eq!(warning.path, folder.path().join("quad.obj"));
        assert_eq!(warning.line, 1);
        assert!(
            warning.message.contains("missing.mtl"),
            "{}",
            warning.message
        );
    }

    #[test]
    fn a_models_errors_are_reported_at_the_definition_with_their_places() {
        let folder = tempfile::tempdir().unwrap();
        std::fs::write(folder.path().join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
        let source = format!(
            "{CAMERA}[definitions.bad]\nmesh = 'bad.obj'\n\
             [[objects]]\ninstance = 'bad'\n"
        );
        let error =
            crate::scene::parse_scene_with_warnings(&source, &folder.path().join("scene.toml"))
                .unwrap_err()
                .to_string();
        assert!(
            error.contains("error: the model `bad.obj` cannot be read:\n"),
            "{error}"
        );
        assert!(error.contains("bad.obj:2:"), "{error}");
    }

    #[test]
    fn warnings_of_a_library_two_models_share_are_given_once() {
        let folder = tempfile::tempdir().unwrap();
        std::fs::write(folder.path().join("shared.mtl"), "newmtl m\nd -1\n").unwrap();
        for name in ["a.obj", "b.obj"] {
            std::fs::write(
                folder.path().join(name),
                "mtllib shared.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n",
            )
            .unwrap();
        }
        let source = format!(
            "{CAMERA}[definitions.a]\nmesh = 'a.obj'\n[definitions.b]\nmesh = 'b.obj'\n\
             [[objects]]\ninstance = 'a'\n[[objects]]\ninstance = 'b'\n"
        );
        let loaded =
            crate::scene::parse_scene_with_warnings(&source, &folder.path().join("scene.toml"))
                .unwrap();
        let [warning] = &loaded.warnings[..] else {
            panic!("{:?}", loaded.warnings);
        };
        assert_eq!(warning.path, folder.path().join("shared.mtl"));
        assert_eq!(warning.line, 2);
    }
}
