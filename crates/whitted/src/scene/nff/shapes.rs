//! The geometry entities `s`, `c` and `p`, built with our shapes'
//! constructors; a constructor's refusal is reported over the entity.
//!
//! ```text
//! s cx cy cz radius                      sphere
//! c bx by bz base_radius                 open cone or cylinder (equal radii)
//!   ax ay az apex_radius
//! p N                                    flat polygon, N >= 3, any shape
//!   x1 y1 z1 ... xN yN zN
//! ```
//!
//! Cones and cylinders stand on `base` along `apex - base`
//! (`Transform::frame`) and have no caps: NFF's are open tubes. A polygon of
//! three vertices is a [`Triangle`], any other a [`Polygon`] (even-odd
//! inside test, so concave outlines such as the SPD gears' are right).
//! Negative radii, which NFF uses for surfaces seen only from inside, are
//! not supported and refused.

use std::ops::Range;

use super::reader::{Parsed, Reader};
use crate::math::{Transform, Vec3, magnitude};
use crate::shape::{Cone, Cylinder, Polygon, Shape, ShapeError, Sphere, Triangle};

/// A shape and where its object space sits in the world.
pub(super) type Placed = (Shape, Transform);

/// The flat shape through `vertices`: a triangle for three, else a polygon.
pub(super) fn flat_shape(vertices: Vec<Vec3>) -> Result<Shape, ShapeError> {
    match vertices[..] {
        [a, b, c] => Triangle::new(a, b, c).map(Shape::Triangle),
        _ => Polygon::new(vertices).map(Shape::Polygon),
    }
}

/// Reports `error` of the shape read from `start` on.
fn refused(r: &mut Reader<'_>, start: usize, error: impl ToString) -> super::reader::Reported {
    let span = r.since(start);
    r.error(span, error.to_string())
}

/// A radius that is not negative, for `what`.
fn radius(r: &mut Reader<'_>, what: &str) -> Parsed<f64> {
    let start = r.next_start();
    let radius = r.number(what)?;
    if radius < 0.0 {
        let span = r.since(start);
        return Err(r.error(
            span,
            format!(
                "{what} is negative ({radius}): surfaces seen only from inside are not supported"
            ),
        ));
    }
    Ok(radius)
}

/// Reads an `s` entity; `at` is the span of its keyword.
pub(super) fn read_sphere(r: &mut Reader<'_>, at: Range<usize>) -> Parsed<Placed> {
    let center = r.vec3("the sphere's centre")?;
    let radius = radius(r, "the sphere's radius")?;
    let sphere = Sphere::new(center, radius).map_err(|e| refused(r, at.start, e))?;
    Ok((Shape::Sphere(sphere), Transform::IDENTITY))
}

/// Reads a `c` entity; `at` is the span of its keyword.
pub(super) fn read_cone(r: &mut Reader<'_>, at: Range<usize>) -> Parsed<Placed> {
    let base = r.vec3("the cone's base")?;
    let base_radius = radius(r, "the cone's base radius")?;
    let apex = r.vec3("the cone's apex")?;
    let apex_radius = radius(r, "the cone's apex radius")?;
    let axis = apex - base;
    if axis == Vec3::ZERO || !axis.is_finite() {
        return Err(refused(
            r,
            at.start,
            "the cone's base and apex are the same point: it has no height",
        ));
    }
    // Measured without squaring: an axis 1e-300 long is refused as such.
    let height = magnitude::norm(axis);
    let shape = if base_radius == apex_radius {
        Cylinder::new(base_radius, height, false).map(Shape::Cylinder)
    } else {
        Cone::new(base_radius, apex_radius, height, false).map(Shape::Cone)
    };
    let shape = shape.map_err(|e| refused(r, at.start, e))?;
    let placement = Transform::frame(base, axis).map_err(|e| refused(r, at.start, e))?;
    Ok((shape, placement))
}

/// Reads the vertex count of a `p` or `pp` entity, `what` naming it: from
/// 3 to 2³² - 1 (vertices are numbered by `u32`).
pub(super) fn vertex_count(r: &mut Reader<'_>, what: &str) -> Parsed<u32> {
    Ok(r.count(&format!("the {what}'s vertex count"), 3, u32::MAX)?
        .0)
}

/// Reads a `p` entity; `at` is the span of its keyword.
pub(super) fn read_polygon(r: &mut Reader<'_>, at: Range<usize>) -> Parsed<Placed> {
    let count = vertex_count(r, "polygon")?;
    // Not `count` at once: a huge count in a short file must not allocate.
    let mut vertices = Vec::with_capacity(count.min(1024) as usize);
    for i in 1..=count {
        vertices.push(r.vec3(&format!("the polygon's vertex {i}"))?);
    }
    let shape = flat_shape(vertices).map_err(|e| refused(r, at.start, e))?;
    Ok((shape, Transform::IDENTITY))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use std::path::Path;

    /// Reads the entity after its one-letter keyword in `text`.
    fn read(
        text: &str,
        read: fn(&mut Reader<'_>, Range<usize>) -> Parsed<Placed>,
    ) -> Result<Placed, Vec<String>> {
        let mut r = Reader::new(text, Path::new("t.nff"));
        let keyword = r.next_token().unwrap();
        match read(&mut r, keyword.span) {
            Ok(placed) => Ok(placed),
            Err(_) => Err(r
                .into_diagnostics()
                .into_iter()
                .map(|d| d.to_string())
                .collect()),
        }
    }

    #[test]
    fn a_sphere_is_a_centre_and_a_radius() {
        let (shape, placement) = read("s 1 2 3 0.5", read_sphere).unwrap();
        assert_eq!(
            shape,
            Shape::Sphere(Sphere::new(Vec3::new(1.0, 2.0, 3.0), 0.5).unwrap())
        );
        assert!(placement.is_identity());
    }

    #[test]
    fn a_cone_written_over_three_lines_reads_like_one_on_one_line() {
        let spread = read("c\n0 0 0 1\n0 0 2 0.5\n", read_cone).unwrap();
        let single = read("c 0 0 0 1 0 0 2 0.5", read_cone).unwrap();
        assert_eq!(spread, single);
        let (shape, placement) = spread;
        assert_eq!(shape, Shape::Cone(Cone::new(1.0, 0.5, 2.0, false).unwrap()));
        assert!(
            placement
                .point_to_world(Vec3::new(0.0, 0.0, 2.0))
                .abs_diff_eq(2.0 * Vec3::Z, 1e-15)
        );
    }

    #[test]
    fn equal_radii_make_an_open_cylinder_from_base_to_apex() {
        let (shape, placement) = read("c 1 1 1 0.25 1 4 1 0.25", read_cone).unwrap();
        assert_eq!(
            shape,
            Shape::Cylinder(Cylinder::new(0.25, 3.0, false).unwrap())
        );
        let top = placement.point_to_world(Vec3::new(0.0, 0.0, 3.0));
        assert!(top.abs_diff_eq(Vec3::new(1.0, 4.0, 1.0), 1e-14));
        // Open: a ray along the axis passes through.
        let ray = placement.ray_to_object(&Ray::new(Vec3::new(1.0, -5.0, 1.0), Vec3::Y));
        assert_eq!(shape.intersect(&ray), None);
    }

    #[test]
    fn three_vertices_make_a_triangle_and_more_a_polygon() {
        let (shape, _) = read("p 3\n0 0 0\n1 0 0\n0 1 0\n", read_polygon).unwrap();
        assert!(matches!(shape, Shape::Triangle(_)));
        let (shape, _) = read("p 4 0 0 0 1 0 0 1 1 0 0 1 0", read_polygon).unwrap();
        assert!(matches!(shape, Shape::Polygon(_)));
    }

    #[test]
    fn a_concave_polygon_has_its_notch_empty() {
        // A U shape: the notch between the arms is outside.
        let (shape, _) = read(
            "p 8\n0 0 0\n3 0 0\n3 3 0\n2 3 0\n2 1 0\n1 1 0\n1 3 0\n0 3 0\n",
            read_polygon,
        )
        .unwrap();
        let down = |x: f64, y: f64| Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
        assert!(shape.intersect(&down(1.5, 2.0)).is_none());
        assert!(shape.intersect(&down(0.5, 2.0)).is_some());
        assert!(shape.intersect(&down(1.5, 0.5)).is_some());
    }

    #[test]
    fn degenerate_shapes_are_refused_over_the_entity() {
        assert_eq!(
            read("s 0 0 0 0", read_sphere).unwrap_err(),
            [
                "t.nff:1:1: error: radius must be a positive number, got 0\n  |\n1 | s 0 0 0 0\n  | ^^^^^^^^^"
            ]
        );
        assert_eq!(
            read("p 3\n0 0 0\n1 1 1\n2 2 2", read_polygon).unwrap_err(),
            [
                "t.nff:1:1: error: degenerate triangle: its vertices are collinear or coincide\n  |\n1 | p 3\n  | ^^^"
            ]
        );
        assert!(read("c 1 1 1 1 1 1 1 0.5", read_cone).unwrap_err()[0].contains("same point"));
        assert!(
            read("c 0 0 0 0 0 0 1 0", read_cone).unwrap_err()[0]
                .contains("radius must be a positive")
        );
        assert!(read("s 0 0 0 -1", read_sphere).unwrap_err()[0].contains("not supported"));
        assert!(
            read("p 2 0 0 0 1 0 0", read_polygon).unwrap_err()[0].contains("at least 3, got 2")
        );
    }
}
