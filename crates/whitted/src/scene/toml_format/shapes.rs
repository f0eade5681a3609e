//! The shape kinds of `[[objects]]`: for each, its name, its own keys and
//! one small function that reads them and calls the shape's constructor.
//! Adding a kind is one entry in [`SHAPE_KINDS`] and one function.
//!
//! ```toml
//! shape = "sphere"         # center = [0, 0, 0] (default), radius
//! shape = "plane"          # point, normal
//! shape = "triangle"       # vertices = [[..], [..], [..]]
//! shape = "polygon"        # vertices = [[..], ...], at least 3, in one plane
//! shape = "parallelogram"  # origin, edge_u, edge_v
//! shape = "disk"           # center, normal, radius, inner_radius = 0
//! shape = "cylinder"       # base, top, radius, caps = true
//! shape = "cone"           # base, base_radius, top, top_radius, caps = true
//! shape = "box"            # min, max
//! shape = "torus"          # major, minor (around the y axis, centred at the origin)
//! shape = "quadric"        # a … j = 0, bounds = [[..], [..]] (unless an ellipsoid)
//! shape = "implicit"       # function, bounds = [[..], [..]], max_gradient
//! shape = "bezier_patch"   # points = 4 rows of 4 [x, y, z], row i along u
//! shape = "superellipsoid" # e, n, center = [0, 0, 0], radius = 1
//! shape = "mesh"           # vertices, triangles = [[0, 1, 2], ...] (from 0)
//! ```
//!
//! Disks, cylinders and cones are built in canonical position (standing on
//! the origin along +z) and come with a placement, `Transform::frame` to
//! their `center`/`base` and `normal`/`top - base`; the object's own
//! `transform` steps act after it.
//!
//! A constructor's refusal is reported at the value it names (`radius` ...)
//! or else at the value most to blame (the `normal` of a plane, the
//! `vertices` of a triangle, the stray vertex of a polygon off its plane).
//!
//! Every value is checked on its own, so one wrong value never hides
//! another: radii are range-checked as they are read, with the constructors'
//! own checks and messages, and a disk's placement is built apart from its
//! shape. A check on several values together (a triangle's vertices, a
//! disk's hole against its radius, a cone's two radii) runs when all the
//! values it needs were read; the constructors stay the final authority.

mod implicit;

use toml_span::Span;
use toml_span::value::Value;

use super::reader::{Fields, Parsed, Reader, Reported, all, both, list};
use crate::math::{Aabb, Transform, Vec3, magnitude};
use crate::shape::{
    AxisBox, BezierPatch, Cone, Cylinder, Disk, Parallelogram, Plane, Polygon, Quadric, Shape,
    ShapeError, SmallMesh, Sphere, Superellipsoid, Torus, Triangle, exponent, non_negative,
    positive,
};

/// A shape in its object space and where that space sits before the
/// object's own transform.
pub(super) struct Placed {
    pub(super) shape: Shape,
    pub(super) placement: Transform,
}

impl Placed {
    /// A shape whose constructor already put it in place.
    fn in_place(shape: Shape) -> Self {
        Self {
            shape,
            placement: Transform::IDENTITY,
        }
    }
}

/// Reads the keys of one kind of shape. The span is that of the `shape`
/// value, for errors that concern no key in particular.
type Build = fn(&mut Reader<'_>, &Fields<'_, '_>, Span) -> Parsed<Placed>;

/// One kind of shape in the scene format.
pub(super) struct ShapeKind {
    /// The value of `shape`.
    pub(super) name: &'static str,
    /// Its own keys, besides `shape`, `material` and `transform`.
    pub(super) keys: &'static [&'static str],
    build: Build,
}

/// Every kind of shape the format knows.
pub(super) const SHAPE_KINDS: &[ShapeKind] = &[
    ShapeKind {
        name: "sphere",
        keys: &["center", "radius"],
        build: sphere,
    },
    ShapeKind {
        name: "plane",
        keys: &["point", "normal"],
        build: plane,
    },
    ShapeKind {
        name: "triangle",
        keys: &["vertices"],
        build: triangle,
    },
    ShapeKind {
        name: "polygon",
        keys: &["vertices"],
        build: polygon,
    },
    ShapeKind {
        name: "parallelogram",
        keys: &["origin", "edge_u", "edge_v"],
        build: parallelogram,
    },
    ShapeKind {
        name: "disk",
        keys: &["center", "normal", "radius", "inner_radius"],
        build: disk,
    },
    ShapeKind {
        name: "cylinder",
        keys: &["base", "top", "radius", "caps"],
        build: cylinder,
    },
    ShapeKind {
        name: "cone",
        keys: &["base", "base_radius", "top", "top_radius", "caps"],
        build: cone,
    },
    ShapeKind {
        name: "box",
        keys: &["min", "max"],
        build: axis_box,
    },
    ShapeKind {
        name: "torus",
        keys: &["major", "minor"],
        build: torus,
    },
    ShapeKind {
        name: "quadric",
        keys: &["a", "b", "c", "d", "e", "f", "g", "h", "i", "j", "bounds"],
        build: quadric,
    },
    ShapeKind {
        name: "implicit",
        keys: &["function", "bounds", "max_gradient"],
        build: implicit::implicit,
    },
    ShapeKind {
        name: "bezier_patch",
        keys: &["points"],
        build: bezier_patch,
    },
    ShapeKind {
        name: "superellipsoid",
        keys: &["e", "n", "center", "radius"],
        build: superellipsoid,
    },
    ShapeKind {
        name: "mesh",
        keys: &["vertices", "triangles"],
        build: mesh,
    },
];

/// The kind called `name`, written at `span`.
pub(super) fn find(r: &mut Reader<'_>, name: &str, span: Span) -> Parsed<&'static ShapeKind> {
    SHAPE_KINDS
        .iter()
        .find(|kind| kind.name == name)
        .ok_or_else(|| {
            let names: Vec<&str> = SHAPE_KINDS
                .iter()
                .map(|kind| kind.name)
                .chain([super::patches::KIND])
                .collect();
            r.error(
                span,
                format!("unknown shape `{name}`; expected one of: {}", list(&names)),
            )
        })
}

/// Reads an object's shape keys as `kind`.
pub(super) fn build(
    kind: &ShapeKind,
    r: &mut Reader<'_>,
    f: &Fields<'_, '_>,
    kind_span: Span,
) -> Parsed<Placed> {
    (kind.build)(r, f, kind_span)
}

/// Records a constructor's refusal at the value it names (`radius` ...), or
/// else at `fallback`.
fn refused(r: &mut Reader<'_>, f: &Fields<'_, '_>, fallback: Span, error: ShapeError) -> Reported {
    let named = match &error {
        ShapeError::NotPositive { what, .. }
        | ShapeError::Negative { what, .. }
        | ShapeError::NotFinite { what }
        | ShapeError::OutOfRange { what, .. } => f.get(what),
        ShapeError::Degenerate { .. } | ShapeError::NotPlanar { .. } | ShapeError::Memory(_) => {
            None
        }
    };
    let span = named.map_or(fallback, |value| r.span_of(value));
    r.error(span, error.to_string())
}

/// A check a shape's constructor makes on one of its numbers.
type Check = fn(&'static str, f64) -> Result<f64, ShapeError>;

/// The number `key` of `f`, required and accepted by `check`.
fn measure(r: &mut Reader<'_>, f: &Fields<'_, '_>, key: &'static str, check: Check) -> Parsed<f64> {
    r.require(f, key, |r, value, _| checked(r, value, key, check))
}

/// The number `value` of `key`, accepted by `check`; its refusal is
/// reported at the value, in the constructor's words.
fn checked(r: &mut Reader<'_>, value: &Value<'_>, key: &'static str, check: Check) -> Parsed<f64> {
    let number = r.number(value, key)?;
    check(key, number).map_err(|error| {
        let span = r.span_of(value);
        r.error(span, error.to_string())
    })
}

fn sphere(r: &mut Reader<'_>, f: &Fields<'_, '_>, at: Span) -> Parsed<Placed> {
    let center = r.or_default(f, "center", Vec3::ZERO, Reader::vec3);
    let radius = measure(r, f, "radius", positive);
    let sphere = Sphere::new(center?, radius?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Sphere(sphere)))
}

fn plane(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let point = r.require(f, "point", Reader::vec3);
    let normal = r.require(f, "normal", Reader::vec3);
    let at = r.value_span(f, "normal");
    let plane = Plane::new(point?, normal?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Plane(plane)))
}

fn triangle(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let [p0, p1, p2] = r.require(f, "vertices", |r, value, key| {
        let points = r.points(value, key)?;
        <[Vec3; 3]>::try_from(points).map_err(|points| {
            r.error(
                value.span,
                format!("expected 3 points for `{key}`, found {}", points.len()),
            )
        })
    })?;
    let at = r.value_span(f, "vertices");
    let triangle = Triangle::new(p0, p1, p2).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Triangle(triangle)))
}

fn polygon(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let vertices = r.require(f, "vertices", Reader::points)?;
    let polygon = Polygon::new(vertices).map_err(|e| {
        let mut at = r.value_span(f, "vertices");
        if let ShapeError::NotPlanar { vertex, .. } = e {
            let off_plane = f
                .get("vertices")
                .and_then(|list| list.as_array())
                .and_then(|list| list.get(vertex));
            at = off_plane.map_or(at, |value| value.span);
        }
        refused(r, f, at, e)
    })?;
    Ok(Placed::in_place(Shape::Polygon(polygon)))
}

/// The most triangles a `mesh` object has: it is tested by brute force.
const MAX_MESH_TRIANGLES: u32 = 65_536;

fn mesh(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let vertices = r.require(f, "vertices", Reader::points);
    let count = vertices.as_ref().map_or(u32::MAX, |v| v.len() as u32);
    let triangles = r.require(f, "triangles", |r, value, key| {
        let items = r.array(value, key, "a list of triangles [[i, j, k], ...]")?;
        if items.len() > MAX_MESH_TRIANGLES as usize {
            return Err(r.error(
                value.span,
                format!(
                    "a mesh object has at most {MAX_MESH_TRIANGLES} triangles, this one has {} \
                     (put big meshes in an OBJ file)",
                    items.len()
                ),
            ));
        }
        all(items.iter().map(|item| {
            let corners = r.array(item, key, "a triangle [i, j, k] of vertex numbers")?;
            if corners.len() != 3 {
                return Err(r.error(
                    item.span,
                    format!("expected 3 vertex numbers, found {}", corners.len()),
                ));
            }
            let last = count.saturating_sub(1);
            let message = |r: &mut Reader<'_>, v: &Value<'_>| {
                let n = v.as_integer().unwrap_or(-1);
                r.error(
                    v.span,
                    format!("no vertex {n}: vertices are numbered from 0 to {last}"),
                )
            };
            let mut t = [0; 3];
            for (slot, v) in t.iter_mut().zip(corners) {
                match v.as_integer() {
                    Some(n) if (0..i64::from(count)).contains(&n) => *slot = n as u32,
                    Some(_) => return Err(message(r, v)),
                    None => return Err(r.wrong_type(v, key, "an integer")),
                }
            }
            Ok(t)
        }))
    });
    let at = r.value_span(f, "triangles");
    let mesh = SmallMesh::new(vertices?, triangles?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Mesh(mesh)))
}

fn parallelogram(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let origin = r.require(f, "origin", Reader::vec3);
    let edge_u = r.require(f, "edge_u", Reader::vec3);
    let edge_v = r.require(f, "edge_v", Reader::vec3);
    let at = r.value_span(f, "edge_v");
    let parallelogram =
        Parallelogram::new(origin?, edge_u?, edge_v?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Parallelogram(parallelogram)))
}

fn disk(r: &mut Reader<'_>, f: &Fields<'_, '_>, at: Span) -> Parsed<Placed> {
    let center = r.require(f, "center", Reader::vec3);
    let normal = r.require(f, "normal", Reader::direction);
    let radius = measure(r, f, "radius", positive);
    let inner_radius = r.or_default(f, "inner_radius", 0.0, |r, value, _| {
        checked(r, value, "inner_radius", non_negative)
    });
    let placement = both(center, normal).and_then(|(center, normal)| frame(r, center, normal, at));
    let too_wide = r.value_span(f, "inner_radius");
    let disk = Disk::new(radius?, inner_radius?).map_err(|e| refused(r, f, too_wide, e))?;
    Ok(Placed {
        shape: Shape::Disk(disk),
        placement: placement?,
    })
}

fn cylinder(r: &mut Reader<'_>, f: &Fields<'_, '_>, at: Span) -> Parsed<Placed> {
    let axis = axis(r, f);
    let radius = measure(r, f, "radius", positive);
    let caps = r.or_default(f, "caps", true, Reader::boolean);
    let (base, axis) = axis?;
    let placement = frame(r, base, axis, at);
    let cylinder =
        Cylinder::new(radius?, axis.length(), caps?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed {
        shape: Shape::Cylinder(cylinder),
        placement: placement?,
    })
}

fn cone(r: &mut Reader<'_>, f: &Fields<'_, '_>, at: Span) -> Parsed<Placed> {
    let axis = axis(r, f);
    let base_radius = measure(r, f, "base_radius", non_negative);
    let top_radius = measure(r, f, "top_radius", non_negative);
    let caps = r.or_default(f, "caps", true, Reader::boolean);
    let (base, axis) = axis?;
    let placement = frame(r, base, axis, at);
    let pointless = r.value_span(f, "top_radius");
    let cone = Cone::new(base_radius?, top_radius?, axis.length(), caps?)
        .map_err(|e| refused(r, f, pointless, e))?;
    Ok(Placed {
        shape: Shape::Cone(cone),
        placement: placement?,
    })
}

fn axis_box(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let min = r.require(f, "min", Reader::vec3);
    let max = r.require(f, "max", Reader::vec3);
    let at = r.value_span(f, "max");
    let axis_box = AxisBox::new(min?, max?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::AxisBox(axis_box)))
}

fn torus(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let major = measure(r, f, "major", non_negative);
    let minor = measure(r, f, "minor", positive);
    let (major, minor) = (major?, minor?);
    let thin = if minor < major * Torus::MIN_RATIO {
        "minor"
    } else {
        "major"
    };
    let at = r.value_span(f, thin);
    let torus = Torus::new(major, minor).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Torus(torus)))
}

fn quadric(r: &mut Reader<'_>, f: &Fields<'_, '_>, at: Span) -> Parsed<Placed> {
    let read = Quadric::COEFFICIENTS.map(|key| r.or_default(f, key, 0.0, Reader::coordinate));
    let clip = r.optional(f, "bounds", clipping_box);
    let mut coefficients = [0.0; 10];
    for (coefficient, value) in coefficients.iter_mut().zip(read) {
        *coefficient = value?;
    }
    let quadric = Quadric::new(coefficients, clip?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Quadric(quadric)))
}

/// A quadric's `bounds`: two corners, the first below the second on every
/// axis.
fn clipping_box(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Aabb> {
    let points = r.points(value, key)?;
    let Ok([min, max]) = <[Vec3; 2]>::try_from(points) else {
        return Err(r.error(
            value.span,
            format!("expected 2 points for `{key}`: [[x0, y0, z0], [x1, y1, z1]]"),
        ));
    };
    if !min.cmplt(max).all() {
        return Err(r.error(
            value.span,
            format!("the first corner of `{key}` must be below the second on every axis"),
        ));
    }
    Ok(Aabb { min, max })
}

fn bezier_patch(r: &mut Reader<'_>, f: &Fields<'_, '_>, _: Span) -> Parsed<Placed> {
    let net = r.require(f, "points", |r, value, key| {
        let rows = r.array(value, key, "4 rows of 4 points [[[x, y, z], ...], ...]")?;
        let rows = super::reader::all(rows.iter().map(|row| {
            let points = r.points(row, key)?;
            <[Vec3; 4]>::try_from(points).map_err(|points| {
                let found = points.len();
                r.error(
                    row.span,
                    format!("expected 4 points in each row of `{key}`, found {found}"),
                )
            })
        }))?;
        <[[Vec3; 4]; 4]>::try_from(rows).map_err(|rows| {
            let found = rows.len();
            r.error(
                value.span,
                format!("expected 4 rows of 4 points for `{key}`, found {found} rows"),
            )
        })
    })?;
    let at = r.value_span(f, "points");
    let patch = BezierPatch::new(net).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::BezierPatch(patch)))
}

fn superellipsoid(r: &mut Reader<'_>, f: &Fields<'_, '_>, at: Span) -> Parsed<Placed> {
    let e = measure(r, f, "e", exponent);
    let n = measure(r, f, "n", exponent);
    let center = r.or_default(f, "center", Vec3::ZERO, Reader::vec3);
    let radius = r.or_default(f, "radius", 1.0, |r, value, _| {
        checked(r, value, "radius", positive)
    });
    let shape = Superellipsoid::new(center?, radius?, e?, n?).map_err(|e| refused(r, f, at, e))?;
    Ok(Placed::in_place(Shape::Superellipsoid(shape)))
}

/// `base` and `top - base` of a cylinder or cone; an error at `top` when the
/// two points coincide or the height between them is out of range.
fn axis(r: &mut Reader<'_>, f: &Fields<'_, '_>) -> Parsed<(Vec3, Vec3)> {
    let base = r.require(f, "base", Reader::vec3);
    let top = r.require(f, "top", Reader::vec3);
    let (base, top) = (base?, top?);
    let axis = top - base;
    if axis == Vec3::ZERO {
        let span = r.value_span(f, "top");
        return Err(r.error(
            span,
            "`top` must differ from `base`: the shape has no height",
        ));
    }
    let height = magnitude::norm(axis);
    if let Err(error) = magnitude::length(height) {
        let span = r.value_span(f, "top");
        return Err(r.error(
            span,
            format!("the height from `base` to `top` is out of range: {error}"),
        ));
    }
    Ok((base, axis))
}

/// The rigid placement of a canonical shape standing on `origin` along
/// `axis`.
fn frame(r: &mut Reader<'_>, origin: Vec3, axis: Vec3, at: Span) -> Parsed<Transform> {
    Transform::frame(origin, axis).map_err(|e| r.error(at, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, errors, scene};
    use super::*;

    /// The shape of the only object in `keys`.
    fn shape(keys: &str) -> Shape {
        placed(keys).0
    }

    /// The shape of the only object in `keys`, and its object-to-world
    /// transform.
    fn placed(keys: &str) -> (Shape, Transform) {
        let mut s = scene(&format!("{CAMERA}[[objects]]\n{keys}\n"));
        assert_eq!(s.objects.primitives.len(), 1);
        let primitive = s.objects.primitives.remove(0);
        let transform = primitive.transform.map_or(Transform::IDENTITY, |id| {
            s.objects.transforms[id.0 as usize]
        });
        (primitive.shape, transform)
    }

    fn close(a: Vec3, b: Vec3) {
        assert!((a - b).length() < 1e-12, "{a} != {b}");
    }

    #[test]
    fn spheres_are_read_with_a_default_center() {
        assert_eq!(
            shape("shape = 'sphere'\nradius = 2"),
            Shape::Sphere(Sphere::new(Vec3::ZERO, 2.0).unwrap())
        );
        assert_eq!(
            shape("shape = 'sphere'\ncenter = [1, 2, 3]\nradius = 0.5"),
            Shape::Sphere(Sphere::new(Vec3::new(1.0, 2.0, 3.0), 0.5).unwrap())
        );
    }

    #[test]
    fn planes_are_read() {
        assert_eq!(
            shape("shape = 'plane'\npoint = [0, -1, 0]\nnormal = [0, 2, 0]"),
            Shape::Plane(Plane::new(-Vec3::Y, Vec3::Y).unwrap())
        );
    }

    #[test]
    fn triangles_are_read() {
        let [a, b, c] = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(
            shape("shape = 'triangle'\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]"),
            Shape::Triangle(Triangle::new(a, b, c).unwrap())
        );
    }

    #[test]
    fn polygons_are_read() {
        let square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]];
        let points = square.map(|[x, y, z]| Vec3::new(x.into(), y.into(), z.into()));
        assert_eq!(
            shape(&format!("shape = 'polygon'\nvertices = {square:?}")),
            Shape::Polygon(Polygon::new(points.to_vec()).unwrap())
        );
    }

    #[test]
    fn parallelograms_are_read() {
        assert_eq!(
            shape(
                "shape = 'parallelogram'\norigin = [1, 0, 0]\nedge_u = [0, 0, 2]\nedge_v = [3, 0, 0]"
            ),
            Shape::Parallelogram(
                Parallelogram::new(Vec3::X, Vec3::new(0.0, 0.0, 2.0), Vec3::new(3.0, 0.0, 0.0))
                    .unwrap()
            )
        );
    }

    #[test]
    fn disks_are_placed_at_their_center_facing_their_normal() {
        let (disk, t) = placed(
            "shape = 'disk'\ncenter = [1, 2, 3]\nnormal = [0, 2, 0]\nradius = 2\n\
             inner_radius = 0.5",
        );
        assert_eq!(disk, Shape::Disk(Disk::new(2.0, 0.5).unwrap()));
        close(t.point_to_world(Vec3::ZERO), Vec3::new(1.0, 2.0, 3.0));
        close(t.vector_to_world(Vec3::Z), Vec3::Y);
        let plain = shape("shape = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 0, 1]\nradius = 1");
        assert_eq!(plain, Shape::Disk(Disk::new(1.0, 0.0).unwrap()));
    }

    #[test]
    fn cylinders_stand_on_their_base_and_reach_their_top() {
        let (cylinder, t) =
            placed("shape = 'cylinder'\nbase = [0, 1, 0]\ntop = [0, 1, 3]\nradius = 0.5");
        assert_eq!(
            cylinder,
            Shape::Cylinder(Cylinder::new(0.5, 3.0, true).unwrap())
        );
        close(t.point_to_world(Vec3::ZERO), Vec3::Y);
        close(
            t.point_to_world(Vec3::new(0.0, 0.0, 3.0)),
            Vec3::new(0.0, 1.0, 3.0),
        );
        let open = shape(
            "shape = 'cylinder'\nbase = [0, 0, 0]\ntop = [1, 0, 0]\nradius = 1\ncaps = false",
        );
        assert_eq!(
            open,
            Shape::Cylinder(Cylinder::new(1.0, 1.0, false).unwrap())
        );
    }

    #[test]
    fn cones_stand_on_their_base_and_reach_their_top() {
        let (cone, t) = placed(
            "shape = 'cone'\nbase = [1, 0, 0]\nbase_radius = 1\ntop = [1, 2, 0]\n\
             top_radius = 0\ncaps = false",
        );
        assert_eq!(cone, Shape::Cone(Cone::new(1.0, 0.0, 2.0, false).unwrap()));
        close(t.point_to_world(Vec3::ZERO), Vec3::X);
        close(
            t.point_to_world(Vec3::new(0.0, 0.0, 2.0)),
            Vec3::new(1.0, 2.0, 0.0),
        );
        let closed = shape(
            "shape = 'cone'\nbase = [0, 0, 0]\nbase_radius = 1\ntop = [0, 0, 1]\ntop_radius = 0.5",
        );
        assert_eq!(closed, Shape::Cone(Cone::new(1.0, 0.5, 1.0, true).unwrap()));
    }

    #[test]
    fn boxes_are_read() {
        assert_eq!(
            shape("shape = 'box'\nmin = [-1, 0, -2]\nmax = [1, 3, 2]"),
            Shape::AxisBox(
                AxisBox::new(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(1.0, 3.0, 2.0)).unwrap()
            )
        );
    }

    #[test]
    fn the_objects_own_steps_act_after_the_placement() {
        let (_, t) = placed(
            "shape = 'cylinder'\nbase = [0, 0, 0]\ntop = [0, 2, 0]\nradius = 1\n\
             transform = [{ scale = 2 }, { translate = [5, 0, 0] }]",
        );
        close(
            t.point_to_world(Vec3::new(0.0, 0.0, 2.0)),
            Vec3::new(5.0, 4.0, 0.0),
        );
    }

    #[test]
    fn refused_round_shapes_are_reported_at_the_culprit() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 0, 0]\n\
                 radius = 1\n\
                 [[objects]]\nshape = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 1, 0]\n\
                 radius = 1\ninner_radius = 1\n\
                 [[objects]]\nshape = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 1, 0]\n\
                 radius = 1\ninner_radius = -1\n\
                 [[objects]]\nshape = 'cylinder'\nbase = [0, 1, 0]\ntop = [0, 1, 0]\n\
                 radius = 1\n\
                 [[objects]]\nshape = 'cylinder'\nbase = [0, 0, 0]\ntop = [0, 1, 0]\n\
                 radius = 0\n\
                 [[objects]]\nshape = 'cylinder'\nbase = [0, 0, 0]\ntop = [0, 1, 0]\n\
                 radius = 1\ncaps = 'yes'\n\
                 [[objects]]\nshape = 'cone'\nbase = [0, 0, 0]\nbase_radius = -1\n\
                 top = [0, 1, 0]\ntop_radius = 1\n\
                 [[objects]]\nshape = 'cone'\nbase = [0, 0, 0]\nbase_radius = 0\n\
                 top = [0, 1, 0]\ntop_radius = 0\n\
                 [[objects]]\nshape = 'box'\nmin = [0, 0, 0]\nmax = [1, 0, 1]\n"
            )),
            [
                "`normal` must not be the zero vector",
                "degenerate disk: the inner radius is not smaller than the radius",
                "inner_radius must not be negative, got -1",
                "`top` must differ from `base`: the shape has no height",
                "radius must be a positive number, got 0",
                "expected `true` or `false` for `caps`, found a string",
                "base_radius must not be negative, got -1",
                "degenerate cone: both radii are zero",
                "degenerate box: min must be below max on every axis",
            ]
        );
    }

    #[test]
    fn refused_flat_shapes_are_reported_at_their_defining_values() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'plane'\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\n\
                 [[objects]]\nshape = 'triangle'\nvertices = [[0, 0, 0], [1, 1, 1], [2, 2, 2]]\n\
                 [[objects]]\nshape = 'triangle'\nvertices = [[0, 0, 0], [1, 1, 1]]\n\
                 [[objects]]\nshape = 'triangle'\nvertices = [[0, 0, 0], 1, [0, 0]]\n\
                 [[objects]]\nshape = 'polygon'\nvertices = [[0, 0, 0], [1, 0, 0]]\n\
                 [[objects]]\nshape = 'parallelogram'\norigin = [0, 0, 0]\n\
                 edge_u = [1, 0, 0]\nedge_v = [2, 0, 0]\n"
            )),
            [
                "degenerate plane: the normal has zero length",
                "degenerate triangle: its vertices are collinear or coincide",
                "expected 3 points for `vertices`, found 2",
                "expected an array of 3 numbers for `vertices`, found an integer",
                "expected 3 numbers for `vertices`, found 2",
                "degenerate polygon: it needs at least three vertices",
                "degenerate parallelogram: its edges are parallel or of zero length",
            ]
        );
    }

    #[test]
    fn a_polygon_off_its_plane_is_reported_at_the_stray_vertex() {
        let source = format!(
            "{CAMERA}[[objects]]\nshape = 'polygon'\n\
             vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 1.5, 1]]\n"
        );
        let Err(crate::scene::SceneError::Invalid { diagnostics }) =
            crate::scene::parse_scene(&source, std::path::Path::new("t.toml"))
        else {
            panic!("the polygon was accepted");
        };
        let [d] = diagnostics.as_slice() else {
            panic!("{diagnostics:?}");
        };
        assert!(d.message.starts_with("the polygon is not planar: vertex "));
        let vertex: usize = d.message["the polygon is not planar: vertex ".len()..]
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let starts = [13, 24, 35, 46, 57];
        assert_eq!(d.column, starts[vertex], "{d}");
    }

    #[test]
    fn one_bad_value_never_hides_another() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'sphere'\ncenter = [0, 1]\nradius = -1\n\
                 [[objects]]\nshape = 'disk'\ncenter = 'here'\nnormal = [0, 1, 0]\n\
                 radius = -1\ninner_radius = -0.5\n\
                 [[objects]]\nshape = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 0, 0]\n\
                 radius = 1\ninner_radius = 2\n\
                 [[objects]]\nshape = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 1, 0]\n\
                 radius = 'big'\ninner_radius = -1\n\
                 [[objects]]\nshape = 'cylinder'\nbase = [0, 1, 0]\ntop = [0, 1, 0]\n\
                 radius = 0\n"
            )),
            [
                "expected 3 numbers for `center`, found 2",
                "radius must be a positive number, got -1",
                "expected an array of 3 numbers for `center`, found a string",
                "radius must be a positive number, got -1",
                "inner_radius must not be negative, got -0.5",
                "`normal` must not be the zero vector",
                "degenerate disk: the inner radius is not smaller than the radius",
                "expected a number for `radius`, found a string",
                "inner_radius must not be negative, got -1",
                "`top` must differ from `base`: the shape has no height",
                "radius must be a positive number, got 0",
            ]
        );
    }

    #[test]
    fn quadrics_are_read_with_zero_coefficients_by_default() {
        let sphere = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert_eq!(
            shape("shape = 'quadric'\na = 1\nb = 1\nc = 1\nj = -1"),
            Shape::Quadric(Quadric::new(sphere, None).unwrap())
        );
        let clip = Aabb::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(
            shape("shape = 'quadric'\na = 1\nb = 1\nj = -1\nbounds = [[-1, -1, 0], [1, 1, 2]]"),
            Shape::Quadric(
                Quadric::new(
                    [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
                    Some(clip)
                )
                .unwrap()
            )
        );
    }

    #[test]
    fn refused_quadrics_are_reported_at_the_culprit() {
        let source = format!(
            "{CAMERA}[[objects]]\nshape = 'quadric'\nj = 1\n\
             [[objects]]\nshape = 'quadric'\na = 1\nb = 1\nj = -1\n\
             [[objects]]\nshape = 'quadric'\na = 1\nb = 1\nc = 1\nj = 1\n\
             [[objects]]\nshape = 'quadric'\na = 1\nb = 1\nj = -1\nbounds = [[0, 0, 0], [1, 0, 1]]\n\
             [[objects]]\nshape = 'quadric'\na = 1\nb = 1\nj = -1\nbounds = [[0, 0, 0]]\n\
             [[objects]]\nshape = 'quadric'\na = 1\nb = 1\nj = -1\nbounds = [[0, 0, 0], [1, 1, 1e31]]\n\
             [[objects]]\nshape = 'quadric'\na = 1\nb = 1\nj = -1e40\nc = 'x'\n\
             [[objects]]\nshape = 'quadric'\na = 1\nb = 1\nc = 1\nj = -1\nbounds = [[2, 2, 2], [3, 3, 3]]\n"
        );
        assert_eq!(
            errors(&source),
            [
                "degenerate quadric: all of a to i are zero: the polynomial is a constant",
                "degenerate quadric: it is unbounded (not an ellipsoid): give `bounds` to clip it",
                "degenerate quadric: it is an ellipsoid with no real points (or a single one)",
                "the first corner of `bounds` must be below the second on every axis",
                "expected 2 points for `bounds`: [[x0, y0, z0], [x1, y1, z1]]",
                "`bounds` is out of range: 1e31 is too large: at most 1e30 in magnitude is allowed",
                "`j` is out of range: -1e40 is too large: at most 1e30 in magnitude is allowed",
                "expected a number for `c`, found a string",
                "degenerate quadric: the bounds do not meet the ellipsoid",
            ]
        );
        let Err(crate::scene::SceneError::Invalid { diagnostics }) =
            crate::scene::parse_scene(&source, std::path::Path::new("t.toml"))
        else {
            panic!("the quadrics were accepted");
        };
        let lines: Vec<&str> = diagnostics.iter().map(|d| d.source_line.as_str()).collect();
        assert_eq!(lines[0], "shape = 'quadric'");
        assert_eq!(lines[3], "bounds = [[0, 0, 0], [1, 0, 1]]");
        assert_eq!(lines[6], "j = -1e40");
    }

    #[test]
    fn superellipsoids_are_read_and_bad_exponents_located() {
        assert_eq!(
            shape("shape = 'superellipsoid'\ne = 0.5\nn = 2"),
            Shape::Superellipsoid(Superellipsoid::new(Vec3::ZERO, 1.0, 0.5, 2.0).unwrap())
        );
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'superellipsoid'\ne = 0\nn = 20\nradius = -1\n"
            )),
            [
                "e must be a positive number, got 0",
                "degenerate superellipsoid: the exponents e and n must lie between 0.001 and 10",
                "radius must be a positive number, got -1",
            ]
        );
    }

    #[test]
    fn a_refused_sphere_is_reported_at_its_radius() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[objects]]\nshape = 'sphere'\nradius = -1\n"
            )),
            ["radius must be a positive number, got -1"]
        );
    }
}
