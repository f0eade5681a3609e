//! The note after a render when an implicit surface's function grew faster
//! along some ray than its `max_gradient` allows, so that the march may
//! have stepped over parts of the surface (POV-Ray warns the same way).

use std::fmt;

use crate::shape::Shape;
use crate::world::Objects;

/// The implicit surface whose bound was beaten by the widest margin.
#[derive(Clone, Debug, PartialEq)]
pub struct GradientExceeded {
    /// The shape's number among the scene's shapes (from 0), followed by
    /// each definition's shapes in order.
    pub shape: usize,
    /// Its function, as written.
    pub function: String,
    /// The `max_gradient` it was given.
    pub max_gradient: f64,
    /// The largest rate of change seen along a ray.
    pub largest_seen: f64,
    /// How many implicit surfaces had their bound beaten.
    pub surfaces: usize,
}

impl fmt::Display for GradientExceeded {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the implicit surface `{}` grew at up to {:.4e} per unit along a ray, more than \
             its max_gradient = {} allows; parts of it may be missing: raise max_gradient \
             to at least {:.4e}",
            self.function, self.largest_seen, self.max_gradient, self.largest_seen
        )?;
        if self.surfaces > 1 {
            write!(f, " ({} implicit surfaces beat their bound)", self.surfaces)?;
        }
        Ok(())
    }
}

/// Clears what the implicit surfaces of `objects` have seen, before a
/// render.
pub(super) fn forget(objects: &Objects) {
    for p in shapes(objects) {
        if let Shape::Implicit(shape) = &p.shape {
            shape.forget_gradient();
        }
    }
}

/// The scene's shapes, then each definition's (whose implicit surfaces
/// note what every instance's rays saw).
fn shapes(objects: &Objects) -> impl Iterator<Item = &crate::world::Primitive> {
    let defined = objects.definitions.iter().flat_map(|d| &d.primitives);
    objects.primitives.iter().chain(defined)
}

/// The report after a render, if any surface's bound was beaten.
pub(super) fn report(objects: &Objects) -> Option<GradientExceeded> {
    let beaten: Vec<(usize, &crate::shape::Implicit, f64)> = shapes(objects)
        .enumerate()
        .filter_map(|(i, p)| match &p.shape {
            Shape::Implicit(shape) => shape.largest_gradient_seen().map(|seen| (i, shape, seen)),
            _ => None,
        })
        .collect();
    let &(shape, worst, largest_seen) = beaten
        .iter()
        .max_by(|a, b| (a.2 / a.1.max_gradient()).total_cmp(&(b.2 / b.1.max_gradient())))?;
    Some(GradientExceeded {
        shape,
        function: worst.function().text().to_string(),
        max_gradient: worst.max_gradient(),
        largest_seen,
        surfaces: beaten.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Ray, Transform, Vec3};
    use crate::shape::{Expression, Implicit, Sphere};
    use crate::world::MaterialId;

    fn implicit(text: &str, max_gradient: f64) -> Shape {
        let function = Expression::parse(text).unwrap();
        let shape = Implicit::new(function, Vec3::splat(-2.0), Vec3::splat(2.0), max_gradient);
        Shape::Implicit(shape.unwrap())
    }

    #[test]
    fn the_surface_beaten_by_the_widest_margin_is_reported() {
        let mut objects = Objects::default();
        let sphere = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap());
        for shape in [
            sphere,
            implicit("10*(x^2 + y^2 + z^2 - 1)", 1.0),
            implicit("x^2 + y^2 + z^2 - 1", 10.0),
            implicit("4*(x^2 + y^2 + z^2 - 1)", 0.5),
        ] {
            objects.add_primitive(shape, MaterialId(0), Transform::IDENTITY);
        }
        assert_eq!(report(&objects), None);
        let ray = Ray::new(Vec3::new(-5.0, 0.2, 0.1), Vec3::new(1.0, 0.1, 0.0));
        for p in &objects.primitives {
            p.shape.intersect(&ray);
        }
        let note = report(&objects).unwrap();
        assert_eq!((note.shape, note.surfaces), (1, 2), "{note:?}");
        assert_eq!(note.max_gradient, 1.0);
        assert!(note.largest_seen > 1.0);
        let text = note.to_string();
        assert!(
            text.starts_with("the implicit surface `10*(x^2 + y^2 + z^2 - 1)` grew at up to"),
            "{text}"
        );
        assert!(
            text.ends_with("(2 implicit surfaces beat their bound)"),
            "{text}"
        );
        forget(&objects);
        assert_eq!(report(&objects), None);
    }

    #[test]
    fn a_surface_in_a_definition_is_reported_after_the_scenes_own() {
        let mut world = Objects::default();
        let sphere = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0).unwrap());
        world.add_primitive(sphere, MaterialId(0), Transform::IDENTITY);
        let mut definition = Objects::default();
        let steep = implicit("10*(x^2 + y^2 + z^2 - 1)", 1.0);
        definition.add_primitive(steep, MaterialId(0), Transform::IDENTITY);
        let defined = world.add_definition(definition);
        world.add_instance(defined, None, Transform::IDENTITY);
        let ray = Ray::new(Vec3::new(-5.0, 0.2, 0.1), Vec3::new(1.0, 0.1, 0.0));
        crate::world::World::new(&world).intersect(&ray);
        assert_eq!(report(&world).map(|note| note.shape), Some(1));
        forget(&world);
        assert_eq!(report(&world), None);
    }
}
