//! Shapes as solids, for constructive solid geometry: which shapes enclose
//! a volume ([`Shape::solidity`]), whether a point lies inside one
//! ([`Shape::contains`]), and every place a line crosses its surface with
//! whether it goes in or out there ([`Shape::crossings`], Roth's
//! ray-classification lists).
//!
//! Crossings are found by asking the shape for its closest hit again and
//! again, each time from the last one, over the whole line up to the
//! ray's `t_max` (from `-∞`: a bounded solid lies outside there, so the
//! state at any `t` follows from the crossings before it). A convex shape
//! (sphere, box, closed cylinder and cone, ellipsoid) is entered at its
//! first crossing and left at its second; the others say by their normal
//! (an outward normal against the ray is a way in). A line that only
//! grazes a surface may report one crossing where two coincide: a way in
//! that is never followed by a way out is dropped, so a graze never leaves
//! the solid open to infinity.

use smallvec::SmallVec;

use super::{Shape, ShapeHit};
use crate::math::{Ray, Vec3};

/// A list of crossings, kept on the stack while short (no heap allocation
/// per ray for the usual few).
pub type Crossings = SmallVec<[Crossing; 8]>;

/// One place a line crosses a solid's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// The shape's hit there (its `t` is the ray parameter).
    pub hit: ShapeHit,
    /// True when the line goes into the solid there, false when it leaves.
    pub entering: bool,
}

/// Whether a shape encloses a volume, and why not when it does not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solidity {
    /// A closed surface around a bounded volume whose crossings are known.
    Closed,
    /// A surface with no inside; the text says why.
    Open(&'static str),
}

/// The most crossings asked of one shape along one line (a torus has
/// four; an implicit surface, its own).
const MAX_CROSSINGS: usize = 256;

/// Crossings of a shape entered at its first crossing and left at its
/// second.
const CONVEX: u8 = 0;
/// Crossings oriented by the normal.
const BY_NORMAL: u8 = 1;

impl Shape {
    /// Whether the shape is a closed solid, which CSG can combine.
    pub fn solidity(&self) -> Solidity {
        match self {
            Shape::Sphere(_)
            | Shape::AxisBox(_)
            | Shape::Torus(_)
            | Shape::Superellipsoid(_)
            | Shape::Implicit(_)
            | Shape::Csg(_) => Solidity::Closed,
            Shape::Cylinder(c) if c.caps() => Solidity::Closed,
            Shape::Cone(c) if c.caps() => Solidity::Closed,
            Shape::Cylinder(_) | Shape::Cone(_) => {
                Solidity::Open("with `caps = false` its ends are open")
            }
            Shape::Quadric(q) => {
                if q.clip().is_some() {
                    Solidity::Open(
                        "a quadric cut by `bounds` is open where the box cuts it \
                         (make it the intersection of an unbounded quadric with a box, \
                         or of a box with an ellipsoid)",
                    )
                } else if quadric_value(q, far_outside(self)) > 0.0 {
                    Solidity::Closed
                } else {
                    Solidity::Open("this ellipsoid's inside is everything outside it")
                }
            }
            Shape::Plane(_) => Solidity::Open("a plane is a surface with no inside"),
            Shape::Triangle(_) | Shape::Parallelogram(_) | Shape::Polygon(_) | Shape::Disk(_) => {
                Solidity::Open("a flat shape has no inside")
            }
            Shape::BezierPatch(_) => Solidity::Open("a patch is a surface with no inside"),
            Shape::Mesh(m) if m.open_edge().is_none() => Solidity::Closed,
            Shape::Mesh(_) => Solidity::Open(
                "a mesh is closed only when every edge is shared by exactly two \
                 triangles, consistently oriented",
            ),
        }
    }

    /// True when `p` (in object space) lies inside the solid. Meaningful
    /// for closed shapes only ([`Shape::solidity`]); false for open ones.
    pub fn contains(&self, p: Vec3) -> bool {
        match self {
            Shape::Sphere(s) => (p - s.center()).length_squared() <= s.radius() * s.radius(),
            Shape::AxisBox(b) => p.cmpge(b.min()).all() && p.cmple(b.max()).all(),
            Shape::Cylinder(c) => {
                c.caps()
                    && (0.0..=c.height()).contains(&p.z)
                    && p.x * p.x + p.y * p.y <= c.radius() * c.radius()
            }
            Shape::Cone(c) => {
                let r = c.radius0() + (c.radius1() - c.radius0()) * p.z / c.height();
                c.caps() && (0.0..=c.height()).contains(&p.z) && p.x * p.x + p.y * p.y <= r * r
            }
            Shape::Torus(t) => {
                let (big, small) = (t.major(), t.minor());
                let a = p.length_squared() + big * big - small * small;
                a * a <= 4.0 * big * big * (p.x * p.x + p.z * p.z)
            }
            Shape::Quadric(q) => q.clip().is_none() && quadric_value(q, p) <= 0.0,
            Shape::Superellipsoid(s) => {
                let u = (p - s.center()) / s.radius();
                let (e, n) = (s.e(), s.n());
                let xy = u.x.abs().powf(2.0 / e) + u.y.abs().powf(2.0 / e);
                xy.powf(e / n) + u.z.abs().powf(2.0 / n) <= 1.0
            }
            Shape::Implicit(i) => {
                let b = i.bounds();
                p.cmpge(b.min).all() && p.cmple(b.max).all() && i.function().eval(p) <= 0.0
            }
            Shape::Csg(c) => c.contains(p),
            Shape::Mesh(m) => m.open_edge().is_none() && m.contains(p),
            _ => false,
        }
    }

    /// Appends to `out` every crossing of the shape's surface along the
    /// ray's whole line (its interval is ignored), in order. For closed
    /// shapes only.
    pub fn crossings(&self, ray: &Ray, out: &mut Crossings) {
        let how = match self {
            Shape::Csg(c) => return c.crossings(ray, out),
            Shape::Mesh(m) => return m.crossings(ray, out),
            Shape::Sphere(_) | Shape::AxisBox(_) | Shape::Cylinder(_) | Shape::Cone(_) => CONVEX,
            Shape::Quadric(_) => CONVEX,
            _ => BY_NORMAL,
        };
        let start = out.len();
        let mut line = *ray;
        line.t_min = f64::NEG_INFINITY;
        line.t_max = f64::INFINITY;
        let mut inside = false;
        for _ in 0..MAX_CROSSINGS {
            let Some(hit) = self.intersect(&line) else {
                break;
            };
            if hit.t <= line.t_min {
                break;
            }
            line.t_min = hit.t;
            let entering = if how == CONVEX {
                !inside
            } else {
                let n = self.surface(&line, &hit).normal;
                let along = n.dot(ray.dir);
                if along == 0.0 {
                    continue;
                }
                along < 0.0
            };
            if entering == inside {
                // A second way in (or out) in a row: the same crossing
                // found again by an iterative solver, or a graze.
                continue;
            }
            inside = entering;
            out.push(Crossing { hit, entering });
            if how == CONVEX && !inside {
                break;
            }
        }
        if inside {
            out.pop();
        }
        debug_assert!(out[start..].windows(2).all(|w| w[0].hit.t <= w[1].hit.t));
    }
}

/// A point outside the shape's bounds.
fn far_outside(shape: &Shape) -> Vec3 {
    let b = shape.bounds();
    b.max + b.extent() + Vec3::ONE
}

/// The quadric's polynomial at `p`.
fn quadric_value(q: &super::Quadric, p: Vec3) -> f64 {
    let (x, y, z) = (p.x, p.y, p.z);
    let [a, b, c, d, e, f, g, h, i, j] = q.coefficients();
    a * x * x
        + b * y * y
        + c * z * z
        + d * x * y
        + e * x * z
        + f * y * z
        + g * x
        + h * y
        + i * z
        + j
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::shape::testing::random_line_through;
    use crate::shape::{
        AxisBox, Cone, Cylinder, Disk, Expression, Implicit, Plane, Quadric, Sphere,
        Superellipsoid, Torus,
    };

    /// Every closed shape whitted has, in a few forms.
    pub(crate) fn closed_shapes() -> Vec<Shape> {
        let implicit = |f: &str, b: f64| {
            let e = Expression::parse(f).unwrap();
            Shape::Implicit(Implicit::new(e, Vec3::splat(-b), Vec3::splat(b), 8.0).unwrap())
        };
        vec![
            Shape::Sphere(Sphere::new(Vec3::new(0.2, -0.1, 0.3), 0.9).unwrap()),
            Shape::AxisBox(AxisBox::new(Vec3::new(-1.0, -0.5, -0.2), Vec3::ONE).unwrap()),
            Shape::Cylinder(Cylinder::new(0.7, 1.5, true).unwrap()),
            Shape::Cone(Cone::new(0.8, 0.3, 1.2, true).unwrap()),
            Shape::Cone(Cone::new(0.0, 0.9, 1.0, true).unwrap()),
            Shape::Torus(Torus::new(1.0, 0.35).unwrap()),
            Shape::Torus(Torus::new(0.5, 0.8).unwrap()),
            Shape::Quadric(
                Quadric::new([0.25, 1.0, 4.0, 0.3, 0.0, 0.0, 0.1, 0.0, 0.0, -1.0], None).unwrap(),
            ),
            Shape::Superellipsoid(Superellipsoid::new(Vec3::ZERO, 1.0, 0.3, 0.6).unwrap()),
            Shape::Superellipsoid(Superellipsoid::new(Vec3::ZERO, 1.0, 2.5, 2.5).unwrap()),
            implicit("x^2 + y^2 + z^2 - 1", 1.5),
            implicit("x^4 + y^4 + z^4 - 1", 1.5),
        ]
    }

    #[test]
    fn open_shapes_say_why_and_closed_ones_are_closed() {
        for shape in closed_shapes() {
            assert_eq!(shape.solidity(), Solidity::Closed, "{}", shape.kind());
        }
        let open = [
            Shape::Plane(Plane::new(Vec3::ZERO, Vec3::Y).unwrap()),
            Shape::Disk(Disk::new(1.0, 0.0).unwrap()),
            Shape::Cylinder(Cylinder::new(1.0, 1.0, false).unwrap()),
            Shape::Cone(Cone::new(1.0, 0.5, 1.0, false).unwrap()),
            Shape::Quadric(
                Quadric::new(
                    [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
                    Some(crate::math::Aabb::new(Vec3::splat(-2.0), Vec3::splat(2.0))),
                )
                .unwrap(),
            ),
            // A negative definite quadric: the bubble, everything outside.
            Shape::Quadric(
                Quadric::new([-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], None).unwrap(),
            ),
        ];
        for shape in open {
            assert!(
                matches!(shape.solidity(), Solidity::Open(why) if !why.is_empty()),
                "{}",
                shape.kind()
            );
            assert!(!shape.contains(Vec3::ZERO) || shape.kind() != "quadric");
        }
    }

    /// Inside or not at `t` by the crossings: inside when the last crossing
    /// before `t` goes in.
    fn inside_by_crossings(crossings: &[Crossing], t: f64) -> bool {
        crossings
            .iter()
            .take_while(|c| c.hit.t < t)
            .last()
            .is_some_and(|c| c.entering)
    }

    #[test]
    fn crossings_agree_with_point_membership_along_random_lines() {
        let mut rng = Rng::new(21);
        for shape in closed_shapes() {
            let bounds = shape.bounds();
            let mut crossed = 0;
            for _ in 0..300 {
                let (ray, start) = random_line_through(&mut rng, &bounds);
                let mut crossings = Crossings::new();
                shape.crossings(&ray, &mut crossings);
                assert!(
                    crossings.len().is_multiple_of(2),
                    "{}: {crossings:?}",
                    shape.kind()
                );
                crossed += usize::from(!crossings.is_empty());
                let step = 4.0 / 400.0;
                let near = 1e-7 * bounds.extent().length() / ray.dir.length();
                for k in 0..400 {
                    let t = start + f64::from(k) * step - 0.5;
                    if crossings.iter().any(|c| (c.hit.t - t).abs() < near) {
                        continue;
                    }
                    assert_eq!(
                        shape.contains(ray.at(t)),
                        inside_by_crossings(&crossings, t),
                        "{}: t = {t} along {ray:?}: {crossings:?}",
                        shape.kind()
                    );
                }
            }
            assert!(crossed > 100, "{}: {crossed}", shape.kind());
        }
    }
}
