//! CSG objects: `csg = "union" | "intersection" | "difference"` and a list
//! of `children`, each an object (a closed solid, or CSG itself) with its
//! own transform and, optionally, material.
//!
//! ```toml
//! [[objects]]
//! csg = "difference"              # the first child minus all the others
//! material = "ivory"              # for every child without its own
//! transform = { translate = [0, 1, 0] }
//! children = [
//!     { shape = "box", min = [-1, -1, -1], max = [1, 1, 1] },
//!     { shape = "sphere", radius = 0.2, center = [0, 0, 1], material = "ink" },
//!     { csg = "union", children = [ ... ] },
//! ]
//! ```
//!
//! A child's transform places it in the CSG object's space; the object's
//! own transform then places the whole in the world.

use toml_span::value::Value;

use super::definition::Item;
use super::object::{Object, read_object, read_transform, unknown_material};
use super::reader::{Parsed, Reader, all, list};
use crate::math::{Transform, magnitude};
use crate::shape::{Csg, CsgChild, CsgError, CsgOperation, Shape, Solidity};

/// The key that makes an object a CSG object.
pub(super) const KEY: &str = "csg";

/// The keys a CSG object may have.
const KEYS: &[&str] = &["csg", "children", "material", "transform"];

/// The operations, by their names in files.
const OPERATIONS: [CsgOperation; 3] = [
    CsgOperation::Union,
    CsgOperation::Intersection,
    CsgOperation::Difference,
];

/// The CSG object `value` (a table with a `csg` key).
pub(super) fn read(r: &mut Reader<'_>, value: &Value<'_>, materials: &[String]) -> Parsed<Object> {
    let mut f = r.table(value, "objects", "CSG object")?;
    let keys = r.check_keys(&f, KEYS);
    let operation = r.require(&f, KEY, |r, value, key| {
        let (name, span) = r.string(value, key)?;
        match OPERATIONS.iter().find(|op| op.name() == name) {
            Some(&op) => Ok(op),
            None => {
                let names: Vec<&str> = OPERATIONS.iter().map(|op| op.name()).collect();
                Err(r.error(
                    span,
                    format!(
                        "unknown CSG operation `{name}`; expected one of: {}",
                        list(&names)
                    ),
                ))
            }
        }
    });
    if let Ok(op) = &operation {
        f.rename(format!("CSG {}", op.name()));
    }
    let material = r.optional(&f, "material", |r, value, key| {
        let (name, span) = r.string(value, key)?;
        materials
            .iter()
            .position(|known| known == name)
            .ok_or_else(|| r.error(span, unknown_material(name, materials)))
    });
    let transform = r.or_default(&f, "transform", Transform::IDENTITY, read_transform);
    let children = r.require(&f, "children", |r, value, key| {
        let items = r.array(value, key, "a list of objects")?;
        let children = all(items.iter().map(|item| read_child(r, item, materials)))?;
        Ok((children, r.span_of(value)))
    });
    keys?;
    let (operation, (children, children_span)) = (operation?, children?);
    let (material, transform) = (material?, transform?);
    let shape = Csg::new(operation, children).map_err(|error| {
        let message = match error {
            CsgError::TooFewChildren { operation, count } => format!(
                "a CSG {} needs at least two children, this one has {count}{}",
                operation.name(),
                if count == 1 {
                    "; write the child as an object of its own"
                } else {
                    ""
                }
            ),
            other => other.to_string(),
        };
        r.error(children_span, message)
    })?;
    let shape = Shape::Csg(shape);
    let world = transform.bounds_to_world(&shape.bounds());
    if world.is_finite() {
        let reach = world.min.abs().max(world.max.abs()).max_element();
        if let Err(error) = magnitude::coordinate(reach) {
            let span = r.value_span(&f, "transform");
            return Err(r.error(
                span,
                format!("the object reaches out of range in the world: {error}"),
            ));
        }
    }
    Ok(Object {
        shape,
        material,
        transform,
    })
}

/// One child: an object that must be a closed solid.
fn read_child(r: &mut Reader<'_>, value: &Value<'_>, materials: &[String]) -> Parsed<CsgChild> {
    let items = read_object(r, value, materials)?;
    let objects = items
        .into_iter()
        .map(|item| match item {
            Item::Object(object) => Ok(object),
            Item::Instance(_) => Err(r.error(
                value.span,
                "an instance cannot be a CSG child yet: place the shapes themselves as children"
                    .to_string(),
            )),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let [object] = <[Object; 1]>::try_from(objects).map_err(|objects| {
        r.error(
            value.span,
            format!(
                "a patches file makes {} open patches, not one closed solid; \
                 it cannot be a CSG child",
                objects.len()
            ),
        )
    })?;
    if let Solidity::Open(why) = object.shape.solidity() {
        let kind = object.shape.kind();
        return Err(r.error(
            value.span,
            format!(
                "a {kind} cannot be a CSG child, which must be a closed solid: {why}; \
                 closed solids are spheres, boxes, cylinders and cones with caps, tori, \
                 quadrics without bounds that are ellipsoids, superellipsoids, implicit \
                 surfaces and CSG objects"
            ),
        ));
    }
    Ok(CsgChild {
        transform: (!object.transform.is_identity()).then_some(object.transform),
        shape: object.shape,
        material: object.material.map(|index| index as u32),
    })
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, errors, scene};
    use crate::math::{Ray, Vec3};
    use crate::shape::Shape;
    use crate::world::{MaterialId, World};

    #[test]
    fn a_csg_object_is_read_with_its_children_materials_and_transforms() {
        // A box minus a sphere moved to its top face, nested in a union
        // with a sphere standing to the side; the whole moved up by 1.
        let s = scene(&format!(
            "{CAMERA}[materials.ivory]\n[materials.ink]\n\
             [[objects]]\ncsg = 'union'\nmaterial = 'ivory'\n\
             transform = {{ translate = [0, 1, 0] }}\nchildren = [\n\
               {{ csg = 'difference', children = [\n\
                 {{ shape = 'box', min = [-1, -1, -1], max = [1, 1, 1] }},\n\
                 {{ shape = 'sphere', radius = 0.5, material = 'ink', \
                    transform = {{ translate = [0, 1, 0] }} }},\n\
               ] }},\n\
               {{ shape = 'sphere', center = [3, 0, 0], radius = 0.5 }},\n\
             ]\n"
        ));
        let [p] = s.objects.primitives.as_slice() else {
            panic!("one object")
        };
        assert!(matches!(&p.shape, Shape::Csg(c) if c.leaf_count() == 3));
        assert_eq!(p.material, MaterialId(0));
        let world = World::new(&s.objects);
        let down = |x: f64| Ray::new(Vec3::new(x, 5.0, 0.0), -Vec3::Y);
        // Into the pocket: the sphere's lower half, 0.5 below the top face
        // at y = 2, in the child's own material.
        let hit = world.intersect(&down(0.0)).unwrap();
        let surface = world.surface(&down(0.0), &hit);
        assert!((surface.point.y - 1.5).abs() < 1e-12, "{}", surface.point);
        assert!(surface.normal.y > 0.99);
        assert_eq!(surface.material, MaterialId(1));
        let hit = world.intersect(&down(0.9)).unwrap();
        assert!((hit.t() - 3.0).abs() < 1e-12);
        assert_eq!(world.surface(&down(0.9), &hit).material, MaterialId(0));
        let hit = world.intersect(&down(3.0)).unwrap();
        assert!((hit.t() - 3.5).abs() < 1e-12);
    }

    #[test]
    fn open_children_lone_children_and_unknown_operations_are_refused() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\ncsg = 'difference'\nchildren = [\n\
                 {{ shape = 'sphere', radius = 1 }},\n\
                 {{ shape = 'disk', center = [0, 0, 0], normal = [0, 1, 0], radius = 1 }},\n]\n\
                 [[objects]]\ncsg = 'union'\nchildren = [{{ shape = 'sphere', radius = 1 }}]\n\
                 [[objects]]\ncsg = 'merge'\nchildren = 3\n"
            )),
            [
                "a disk cannot be a CSG child, which must be a closed solid: a flat shape has \
                 no inside; closed solids are spheres, boxes, cylinders and cones with caps, \
                 tori, quadrics without bounds that are ellipsoids, superellipsoids, implicit \
                 surfaces and CSG objects",
                "a CSG union needs at least two children, this one has 1; write the child as \
                 an object of its own",
                "unknown CSG operation `merge`; expected one of: union, intersection, difference",
                "expected a list of objects for `children`, found an integer",
            ]
        );
    }
}
