//! Objects: one `[[objects]]` table each, a shape with a material and a
//! transform.
//!
//! ```toml
//! [[objects]]
//! shape = "sphere"                # the kind; its own keys follow
//! center = [0, 1, 0]
//! radius = 1
//! material = "glass"              # a name from [materials]; default: matte grey
//! transform = [                   # applied in order: the first acts first
//!     { scale = [1, 2, 1] },
//!     { rotate = { axis = [0, 1, 0], angle = 30 } },
//!     { translate = [2, 0, 0] },
//!     { matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]] },
//! ]
//! ```
//!
//! `scale` takes one factor or three; `matrix` is row-major `[R | t]`. A
//! single step may be written without the list: `transform = { scale = 2 }`.

use toml_span::value::Value;

use super::definition::{INSTANCE_KEY, Item, read_placement};
use super::reader::{Fields, Parsed, Reader, all, list};
use super::{csg, patches, shapes};
use crate::math::{Aabb, Transform, TransformError, Vec3, magnitude};
use crate::shape::Shape;

/// An object read from the file.
#[derive(Debug)]
pub(super) struct Object {
    /// The shape in object space.
    pub(super) shape: Shape,
    /// Index of its material in the file's materials; `None` for the default.
    pub(super) material: Option<usize>,
    /// Object to world: the user's steps after the shape's placement.
    pub(super) transform: Transform,
}

/// Keys every object may have, whatever its shape.
const COMMON_KEYS: &[&str] = &["shape", "material", "transform"];

/// Reads the `[[objects]]` array, if any; `materials` are the names defined.
/// Each object comes with the index of the table that defined it.
pub(super) fn read_objects(
    r: &mut Reader<'_>,
    value: Option<&Value<'_>>,
    materials: &[String],
) -> Parsed<Vec<(usize, Item)>> {
    let Some(value) = value else {
        return Ok(Vec::new());
    };
    let objects = r.array(value, "objects", "an array of tables ([[objects]])")?;
    let objects = all(objects
        .iter()
        .map(|object| read_object(r, object, materials)))?;
    let by_table = objects.into_iter().enumerate();
    Ok(by_table
        .flat_map(|(table, objects)| objects.into_iter().map(move |object| (table, object)))
        .collect())
}

/// One object, or one per patch of a `shape = "patches"` file, or an
/// instance of a definition.
pub(super) fn read_object(
    r: &mut Reader<'_>,
    value: &Value<'_>,
    materials: &[String],
) -> Parsed<Vec<Item>> {
    if value.as_table().is_some_and(|t| t.get(csg::KEY).is_some()) {
        return csg::read(r, value, materials).map(|object| vec![Item::Object(object)]);
    }
    let f = r.table(value, "objects", "object")?;
    let is_patches = f.get("shape").and_then(|v| v.as_str()) == Some(patches::KIND);
    let kind = (!is_patches && f.get(INSTANCE_KEY).is_none()).then(|| {
        r.require(&f, "shape", Reader::string)
            .and_then(|(name, span)| Ok((shapes::find(r, name, span)?, span)))
    });
    let material = r.optional(&f, "material", |r, value, key| {
        let (name, span) = r.string(value, key)?;
        materials
            .iter()
            .position(|known| known == name)
            .ok_or_else(|| r.error(span, unknown_material(name, materials)))
    });
    let transform = r.or_default(&f, "transform", Transform::IDENTITY, read_transform);
    if f.get(INSTANCE_KEY).is_some() {
        return read_placement(r, &f, material, transform).map(|item| vec![item]);
    }
    let Some(kind) = kind else {
        let keys = r.check_keys(&f, &[COMMON_KEYS, patches::KEYS].concat());
        let shapes = patches::read(r, &f);
        let (material, transform) = (material?, transform?);
        keys?;
        let shapes = shapes?;
        let bounds = shapes
            .iter()
            .fold(Aabb::EMPTY, |all, shape| all.union(&shape.bounds()));
        check_reach(r, &f, &transform, &bounds)?;
        let object = |shape| Object {
            shape,
            material,
            transform,
        };
        return Ok(shapes.into_iter().map(object).map(Item::Object).collect());
    };
    let (kind, kind_span) = match kind {
        Ok(kind) => kind,
        Err(reported) => {
            let keys_of_kinds: Vec<&[&str]> = std::iter::once(COMMON_KEYS)
                .chain(shapes::SHAPE_KINDS.iter().map(|kind| kind.keys))
                .chain(std::iter::once(patches::KEYS))
                .collect();
            r.check_keys_of_any_kind(&f, &keys_of_kinds, "shapes")?;
            return Err(reported);
        }
    };
    let keys = r.check_keys(&f, &[COMMON_KEYS, kind.keys].concat());
    let placed = shapes::build(kind, r, &f, kind_span);
    keys?;
    let placed = placed?;
    let transform = transform?.then_after(&placed.placement);
    check_reach(r, &f, &transform, &placed.shape.bounds())?;
    Ok(vec![Item::Object(Object {
        shape: placed.shape,
        material: material?,
        transform,
    })])
}

/// Refuses, at the object's `transform`, an object whose `bounds` carried
/// by `transform` into the world reach beyond ±[`magnitude::MAX_COORDINATE`].
fn check_reach(
    r: &mut Reader<'_>,
    f: &Fields<'_, '_>,
    transform: &Transform,
    bounds: &Aabb,
) -> Parsed<()> {
    let world = transform.bounds_to_world(bounds);
    if world.is_finite() {
        let reach = world.min.abs().max(world.max.abs()).max_element();
        if let Err(error) = magnitude::coordinate(reach) {
            let span = r.value_span(f, "transform");
            return Err(r.error(
                span,
                format!("the object reaches out of range in the world: {error}"),
            ));
        }
    }
    Ok(())
}

pub(super) fn unknown_material(name: &str, materials: &[String]) -> String {
    if materials.is_empty() {
        format!(
            "unknown material `{name}`; no materials are defined (add a [materials.{name}] table)"
        )
    } else {
        format!(
            "unknown material `{name}`; the materials defined are: {}",
            materials.join(", ")
        )
    }
}

/// The kinds of transform step.
const STEPS: &[&str] = &["translate", "rotate", "scale", "matrix"];

/// A list of steps (or one step), composed so the first acts first.
pub(super) fn read_transform(
    r: &mut Reader<'_>,
    value: &Value<'_>,
    key: &str,
) -> Parsed<Transform> {
    let steps = if value.as_table().is_some() {
        std::slice::from_ref(value)
    } else {
        r.array(value, key, "a list of transform steps")?
    };
    let steps = all(steps.iter().map(|step| read_step(r, step)))?;
    Ok(steps
        .iter()
        .fold(Transform::IDENTITY, |so_far, step| step.then_after(&so_far)))
}

/// One step: a table with exactly one of [`STEPS`].
fn read_step(r: &mut Reader<'_>, value: &Value<'_>) -> Parsed<Transform> {
    let f = r.table(value, "transform", "transform step")?;
    let keys = r.check_keys(&f, STEPS);
    let entries = f.entries_in_file_order();
    match entries.as_slice() {
        [] => Err(r.error(
            value.span,
            format!("empty transform step; expected one of: {}", list(STEPS)),
        )),
        [(key, value)] => {
            keys?;
            build_step(r, &key.name, value)
        }
        [(first, _), (second, _), ..] => Err(r.error(
            second.span,
            format!(
                "a transform step has one key, this one also has `{first}`; \
                 write `{second}` as a step of its own"
            ),
        )),
    }
}

fn build_step(r: &mut Reader<'_>, key: &str, value: &Value<'_>) -> Parsed<Transform> {
    let built = match key {
        "translate" => Transform::translate(r.vec3(value, key)?),
        "scale" => {
            let factors = if value.as_array().is_some() {
                r.vec3(value, key)?
            } else if value.as_integer().is_some() || value.as_float().is_some() {
                Vec3::splat(r.number(value, key)?)
            } else {
                return Err(r.wrong_type(value, key, "a number or [x, y, z]"));
            };
            Transform::scale(factors)
        }
        "rotate" => {
            let f = r.table(value, key, "`rotate`")?;
            let keys = r.check_keys(&f, &["axis", "angle"]);
            let axis = r.require(&f, "axis", Reader::vec3);
            let angle = r.require(&f, "angle", Reader::number);
            keys?;
            let rotation = Transform::rotate(axis?, angle?);
            if rotation == Err(TransformError::ZeroAxis) {
                let span = r.value_span(&f, "axis");
                return Err(r.error(span, "the rotation axis has zero length"));
            }
            rotation
        }
        _ => {
            let rows = r.array(value, key, "3 rows of 4 numbers")?;
            if rows.len() != 3 {
                return Err(r.error(
                    value.span,
                    format!(
                        "expected 3 rows of 4 numbers for `{key}`, found {} rows",
                        rows.len()
                    ),
                ));
            }
            let rows = all(rows
                .iter()
                .map(|row| r.numbers::<4>(row, key, Reader::number)))?;
            Transform::from_rows([rows[0], rows[1], rows[2]])
        }
    };
    built.map_err(|error| r.error(value.span, error.to_string()))
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, errors, scene};
    use super::shapes::SHAPE_KINDS;
    use crate::math::{Transform, Vec3};
    use crate::render::Scene;
    use crate::shading::Material;
    use crate::world::MaterialId;
    use crate::world::TransformId;

    /// The world transform of the only object in `steps`.
    fn transform(steps: &str) -> Transform {
        let s = scene(&format!(
            "{CAMERA}[[objects]]\nshape = 'sphere'\nradius = 1\ntransform = {steps}\n"
        ));
        world_from_object(&s, 0)
    }

    fn world_from_object(s: &Scene, index: usize) -> Transform {
        s.objects.primitives[index]
            .transform
            .map_or(Transform::IDENTITY, |TransformId(i)| {
                s.objects.transforms[i as usize]
            })
    }

    fn close(t: &Transform, p: Vec3, expected: Vec3) {
        let got = t.point_to_world(p);
        assert!((got - expected).length() < 1e-12, "{got} != {expected}");
    }

    #[test]
    fn each_step_kind_is_read() {
        let t = transform("[{ translate = [1, 2, 3] }]");
        close(&t, Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        let t = transform("{ scale = 2 }");
        close(&t, Vec3::ONE, Vec3::splat(2.0));
        let t = transform("[{ scale = [1, 2, 3] }]");
        close(&t, Vec3::ONE, Vec3::new(1.0, 2.0, 3.0));
        let t = transform("[{ rotate = { axis = [0, 0, 2], angle = 90 } }]");
        close(&t, Vec3::X, Vec3::Y);
        let t = transform("[{ matrix = [[0, -1, 0, 5], [1, 0, 0, 6], [0, 0, 1, 7]] }]");
        close(&t, Vec3::X, Vec3::new(5.0, 7.0, 7.0));
        let t = transform("[]");
        assert!(t.is_identity());
    }

    #[test]
    fn the_first_step_listed_acts_first() {
        let t = transform("[{ scale = 2 }, { translate = [1, 0, 0] }]");
        close(&t, Vec3::X, Vec3::new(3.0, 0.0, 0.0));
        let t = transform("[{ translate = [1, 0, 0] }, { scale = 2 }]");
        close(&t, Vec3::X, Vec3::new(4.0, 0.0, 0.0));
        let t =
            transform("[{ translate = [1, 0, 0] }, { rotate = { axis = [0, 0, 1], angle = 90 } }]");
        close(&t, Vec3::ZERO, Vec3::Y);
    }

    #[test]
    fn objects_get_their_material_or_a_shared_default() {
        let s = scene(&format!(
            "{CAMERA}[materials.red]\ndiffuse = [1, 0, 0]\n[materials.blue]\ndiffuse = [0, 0, 1]\n\
             [[objects]]\nshape = 'sphere'\nradius = 1\nmaterial = 'blue'\n\
             [[objects]]\nshape = 'sphere'\nradius = 1\n\
             [[objects]]\nshape = 'sphere'\nradius = 1\n"
        ));
        let ids: Vec<MaterialId> = s.objects.primitives.iter().map(|p| p.material).collect();
        assert_eq!(ids, [MaterialId(1), MaterialId(2), MaterialId(2)]);
        assert_eq!(s.materials.len(), 3);
        assert_eq!(s.materials[2], Material::default());
        assert!(s.objects.primitives.iter().all(|p| p.transform.is_none()));
    }

    #[test]
    fn every_object_error_is_reported() {
        let kinds: Vec<&str> = SHAPE_KINDS.iter().map(|kind| kind.name).collect();
        let kinds = format!("{}, patches", kinds.join(", "));
        let keys_of_any_shape = "shape, material, transform, center, radius, point, normal, \
                                 vertices, origin, edge_u, edge_v, inner_radius, base, top, \
                                 caps, base_radius, top_radius, min, max, major, minor, \
                                 a, b, c, d, e, f, g, h, i, j, bounds, function, max_gradient, \
                                 points, n, file";
        assert_eq!(
            errors(&format!(
                "{CAMERA}[materials.glass]\n\
                 [[objects]]\nradius = 1\nmaterial = 'glas'\ncolour = 3\n\
                 [[objects]]\nshape = 'blob'\nsize = 3\ntop = [0, 1, 0]\n\
                 [[objects]]\nshape = 'sphere'\nradiuss = 1\ntransform = [{{ scale = 0 }}]\n"
            )),
            [
                "missing required key `shape` in object",
                "unknown material `glas`; the materials defined are: glass",
                &format!(
                    "unknown key `colour` in object; none of the shapes has it; \
                     expected one of: {keys_of_any_shape}"
                ),
                &format!("unknown shape `blob`; expected one of: {kinds}"),
                &format!(
                    "unknown key `size` in object; none of the shapes has it; \
                     expected one of: {keys_of_any_shape}"
                ),
                "missing required key `radius` in object",
                "unknown key `radiuss` in object; expected one of: shape, material, transform, \
                 center, radius",
                "the transform is singular: it flattens space (a zero scale or dependent axes)",
            ]
        );
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'sphere'\nradius = 1\nmaterial = 'x'\n"
            )),
            ["unknown material `x`; no materials are defined (add a [materials.x] table)"]
        );
    }

    #[test]
    fn every_transform_error_is_reported() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'sphere'\nradius = 1\ntransform = [\n\
                 {{}},\n\
                 {{ move = [1, 0, 0] }},\n\
                 {{ scale = 2, translate = [1, 0, 0] }},\n\
                 {{ scale = 'big' }},\n\
                 {{ rotate = {{ axis = [0, 0, 0], angle = 30 }} }},\n\
                 {{ rotate = {{ angle = 30, turns = 1 }} }},\n\
                 {{ matrix = [[1, 0, 0, 0], [0, 1, 0, 0]] }},\n\
                 {{ matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 1, 0, 0]] }},\n\
                 3,\n]\n"
            )),
            [
                "empty transform step; expected one of: translate, rotate, scale, matrix",
                "unknown key `move` in transform step; expected one of: translate, rotate, \
                 scale, matrix",
                "a transform step has one key, this one also has `scale`; write `translate` \
                 as a step of its own",
                "expected a number or [x, y, z] for `scale`, found a string",
                "the rotation axis has zero length",
                "missing required key `axis` in `rotate`",
                "unknown key `turns` in `rotate`; expected one of: axis, angle",
                "expected 3 rows of 4 numbers for `matrix`, found 2 rows",
                "the transform is singular: it flattens space (a zero scale or dependent axes)",
                "expected a table for `transform`, found an integer",
            ]
        );
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'sphere'\nradius = 1\ntransform = 'none'\n"
            )),
            ["expected a list of transform steps for `transform`, found a string"]
        );
    }
}
