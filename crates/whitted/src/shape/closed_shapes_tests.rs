//! The glass rule for the closed shapes of issue 17: a ray straight through
//! each one enters and leaves it alternately, as the medium stack expects.

use super::testing::assert_crossings_alternate;
use super::{Expression, Implicit, Quadric, Shape, Superellipsoid, Torus};
use crate::math::{Ray, Vec3};

#[test]
fn rays_through_the_middle_of_closed_shapes_alternate_entering_and_leaving() {
    let implicit_sphere = Implicit::new(
        Expression::parse("x^2 + y^2 + z^2 - 1").unwrap(),
        Vec3::splat(-1.5),
        Vec3::splat(1.5),
        6.0,
    )
    .unwrap();
    // x²/4 + y² + 4z² = 1, with no bounds: a bounded quadric.
    let ellipsoid = [0.25, 1.0, 4.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
    // Each shape with how many times a ray through its middle crosses it:
    // the ring torus twice through its tube on either side of the hole, the
    // spindle torus through its apple, its lemon (where the normal points
    // into the lemon, so going in leaves the solid) and out again.
    let shapes = [
        (Shape::Torus(Torus::new(1.0, 0.35).unwrap()), 4),
        (Shape::Torus(Torus::new(0.5, 0.8).unwrap()), 4),
        (
            Shape::Superellipsoid(Superellipsoid::new(Vec3::ZERO, 1.0, 0.7, 0.4).unwrap()),
            2,
        ),
        (
            Shape::Superellipsoid(Superellipsoid::new(Vec3::ZERO, 1.0, 2.5, 2.5).unwrap()),
            2,
        ),
        (Shape::Quadric(Quadric::new(ellipsoid, None).unwrap()), 2),
        (Shape::Implicit(implicit_sphere), 2),
    ];
    // Nearly along x and nearly along z, through points near the centre;
    // not along y, the spindle torus's axis, where apple and lemon meet.
    let rays = [
        (Vec3::new(0.0, 0.01, 0.02), Vec3::new(1.0, 0.1, 0.05)),
        (Vec3::new(0.02, -0.01, 0.0), Vec3::new(-0.05, 0.1, 1.0)),
        (Vec3::new(-0.01, 0.0, 0.01), Vec3::new(-1.0, -0.05, -0.1)),
    ];
    for (shape, expected) in &shapes {
        for &(through, dir) in &rays {
            let ray = Ray::new(through - 10.0 * dir, dir);
            let crossings = assert_crossings_alternate(shape, ray);
            assert_eq!(
                crossings,
                *expected,
                "{}: ray through {through:?} along {dir:?}",
                shape.kind()
            );
        }
    }
}
