//! The primitives: one closed `enum` of shapes, dispatched by `match`.
//!
//! Every shape answers four questions in its own (object) space:
//! - [`Shape::intersect`]: the closest hit in the ray's interval, as a small
//!   [`ShapeHit`] (the parameter `t` and whatever the shape needs to finish
//!   the job later);
//! - [`Shape::occluded`]: is there any hit at all (for shadow rays);
//! - [`Shape::surface`]: for the final hit only, the point with its
//!   floating-point error bound, the unit geometric normal, the texture
//!   coordinates (u, v) from the shape's parametric form and the tangents
//!   `dpdu` and `dpdv` (the derivatives of the point along u and v, both
//!   perpendicular to the normal), which orient bump and normal maps;
//! - [`Shape::bounds`]: the object-space bounding box.
//!
//! Normals point "outward": away from the inside of closed shapes, and along
//! the orientation given by the vertex order or the stated normal for flat
//! ones. Intersection is two-sided; shading turns normals towards the viewer.
//!
//! Degenerate shapes (a zero radius, collinear vertices, a zero-area polygon)
//! are refused by the constructors with a [`ShapeError`]; no test ever
//! produces NaN.

mod axis_box;
mod bezier_patch;
mod cone;
mod csg;
mod cylinder;
mod disk;
pub mod implicit;
mod lanes;
mod outline;
mod parallelogram;
mod plane;
mod polygon;
mod quadratic;
mod quadric;
mod small_mesh;
mod solid;
mod sphere;
#[cfg(target_arch = "x86_64")]
mod sphere_avx;
mod superellipsoid;
mod torus;
mod triangle;
mod triangle_clip;
#[cfg(target_arch = "x86_64")]
mod watertight_avx;

pub use axis_box::AxisBox;
pub use bezier_patch::BezierPatch;
pub use cone::Cone;
pub use csg::{COINCIDENT, Csg, CsgChild, CsgError, CsgOperation, MAX_LEAVES};
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use implicit::{Expression, ExpressionError, Implicit, MIN_STEP, NAN_STEP};
#[cfg(all(test, target_arch = "x86_64"))]
pub(crate) use lanes::AvxLanes;
pub(crate) use lanes::{FourLanes, Hits4, LANES, OneByOne, WideLanes};
pub use parallelogram::Parallelogram;
pub use plane::Plane;
pub(crate) use plane::plane_hit;
pub use polygon::Polygon;
pub use quadric::Quadric;
pub use small_mesh::{OpenEdge, SmallMesh};
pub use solid::{Crossing, Crossings, Solidity};
pub use sphere::Sphere;
pub use superellipsoid::{MAX_EXPONENT, MIN_EXPONENT, Superellipsoid, exponent};
pub use torus::Torus;
pub use triangle::{RayShear, Triangle, watertight};
pub(crate) use triangle_clip::clipped_triangle_bounds;

use crate::math::magnitude::{self, MagnitudeError};
use crate::math::{Aabb, DVec2, Ray, Vec3};

/// A hit found during traversal: kept small, everything else is computed once
/// for the final hit by [`Shape::surface`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    /// The ray parameter of the hit.
    pub t: f64,
    /// Shape-specific data (barycentric coordinates for a triangle, for
    /// instance); meaningful only to the shape that wrote it.
    pub u: f64,
    /// Shape-specific data, like `u`.
    pub v: f64,
    /// Which part of a compound shape was hit (side or cap, box face).
    pub part: u32,
}

impl ShapeHit {
    /// A hit at `t` with no extra data.
    pub fn at(t: f64) -> Self {
        Self {
            t,
            u: 0.0,
            v: 0.0,
            part: 0,
        }
    }
}

/// The surface at a hit, in the shape's object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalSurface {
    /// The hit point, reprojected onto the surface.
    pub point: Vec3,
    /// Absolute bound on the error of `point`, per axis.
    pub point_error: Vec3,
    /// Unit geometric normal, outward.
    pub normal: Vec3,
    /// Texture coordinates from the shape's parametric form.
    pub uv: DVec2,
    /// Derivative of the point along u (a tangent; not normalised, may be
    /// zero at a pole).
    pub dpdu: Vec3,
    /// Derivative of the point along v (a tangent; not normalised, may be
    /// zero where the parametrisation pinches, like the centre of a disk).
    pub dpdv: Vec3,
}

/// Why a shape could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// What the shape keeps (a Bézier patch's hierarchy) does not fit in
    /// the memory budget beside what the run holds.
    #[error(transparent)]
    Memory(#[from] crate::limits::MemoryError),
    /// A length that must be positive was not.
    #[error("{what} must be a positive number, got {value}")]
    NotPositive {
        /// What was wrong ("radius", "height" ...).
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A coordinate or length that is NaN or infinite.
    #[error("{what} must be a finite number")]
    NotFinite {
        /// Which value.
        what: &'static str,
    },
    /// A length that may be zero but was negative.
    #[error("{what} must not be negative, got {value}")]
    Negative {
        /// What was wrong ("inner_radius", "radius0" ...).
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// The shape has no area (collinear vertices, zero edges ...).
    #[error("degenerate {shape}: {why}")]
    Degenerate {
        /// The kind of shape.
        shape: &'static str,
        /// What makes it degenerate.
        why: &'static str,
    },
    /// A coordinate or length outside the range whitted represents
    /// ([`crate::math::magnitude`]): its square or products would overflow
    /// or underflow in the intersection routine.
    #[error("{what} is out of range: {error}")]
    OutOfRange {
        /// Which value.
        what: &'static str,
        /// How it is out of range.
        error: MagnitudeError,
    },
    /// The vertices of a polygon are not in one plane.
    #[error(
        "the polygon is not planar: vertex {vertex} lies {deviation:e} off its plane \
         (the tolerance is {tolerance:e})"
    )]
    NotPlanar {
        /// Which vertex (counting from 0) is off the plane.
        vertex: usize,
        /// Its distance from the plane.
        deviation: f64,
        /// The largest distance allowed.
        tolerance: f64,
    },
}

/// Checks that `value` is a positive length within
/// [`crate::math::magnitude::length`]'s range.
pub(crate) fn positive(what: &'static str, value: f64) -> Result<f64, ShapeError> {
    if !value.is_finite() {
        Err(ShapeError::NotFinite { what })
    } else if value <= 0.0 {
        Err(ShapeError::NotPositive { what, value })
    } else {
        in_range(what, value)
    }
}

/// Checks that `value` is a length, zero or within
/// [`crate::math::magnitude::length`]'s range.
pub(crate) fn non_negative(what: &'static str, value: f64) -> Result<f64, ShapeError> {
    if !value.is_finite() {
        Err(ShapeError::NotFinite { what })
    } else if value < 0.0 {
        Err(ShapeError::Negative { what, value })
    } else {
        in_range(what, value)
    }
}

/// `value` when [`magnitude::length`] accepts it.
fn in_range(what: &'static str, value: f64) -> Result<f64, ShapeError> {
    magnitude::length(value).map_err(|error| ShapeError::OutOfRange { what, error })
}

/// Checks that every component of `v` is finite and within
/// ±[`magnitude::MAX_COORDINATE`].
pub(crate) fn finite(what: &'static str, v: Vec3) -> Result<Vec3, ShapeError> {
    if !v.is_finite() {
        Err(ShapeError::NotFinite { what })
    } else {
        magnitude::point(v).map_err(|error| ShapeError::OutOfRange { what, error })
    }
}

/// Checks that the largest of `lengths` (the edges of a flat shape) is at
/// least [`magnitude::MIN_LENGTH`]: below it, the products of two edges
/// (a normal, an area) underflow.
pub(crate) fn not_tiny(
    what: &'static str,
    lengths: impl IntoIterator<Item = f64>,
) -> Result<(), ShapeError> {
    let longest = lengths.into_iter().fold(0.0, f64::max);
    if longest > 0.0 && longest < magnitude::MIN_LENGTH {
        let error = MagnitudeError::TooSmall { value: longest };
        return Err(ShapeError::OutOfRange { what, error });
    }
    Ok(())
}

/// Every primitive whitted knows.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// An infinite plane.
    Plane(Plane),
    /// A single triangle.
    Triangle(Triangle),
    /// A parallelogram (or rectangle).
    Parallelogram(Parallelogram),
    /// A planar polygon, convex or concave.
    Polygon(Polygon),
    /// A disk or annulus (canonical: z = 0, facing +z).
    Disk(Disk),
    /// A cylinder, open or capped (canonical: along +z from z = 0).
    Cylinder(Cylinder),
    /// A truncated cone, open or capped (canonical: along +z from z = 0).
    Cone(Cone),
    /// A box aligned with the axes.
    AxisBox(AxisBox),
    /// A torus around the y axis (canonical: centred at the origin).
    Torus(Torus),
    /// A quadric surface, clipped to a box unless it is an ellipsoid.
    Quadric(Quadric),
    /// An implicit surface `f(x, y, z) = 0` within a box.
    Implicit(Implicit),
    /// A bicubic Bézier patch.
    BezierPatch(BezierPatch),
    /// POV-Ray's superellipsoid.
    Superellipsoid(Superellipsoid),
    /// A union, intersection or difference of closed solids.
    Csg(Csg),
    /// A small triangle mesh written out in the scene, tested by brute
    /// force.
    Mesh(SmallMesh),
}

const _: () = assert!(std::mem::size_of::<Shape>() <= 80);

macro_rules! dispatch {
    ($self:expr, $s:ident => $body:expr) => {
        match $self {
            Shape::Sphere($s) => $body,
            Shape::Plane($s) => $body,
            Shape::Triangle($s) => $body,
            Shape::Parallelogram($s) => $body,
            Shape::Polygon($s) => $body,
            Shape::Disk($s) => $body,
            Shape::Cylinder($s) => $body,
            Shape::Cone($s) => $body,
            Shape::AxisBox($s) => $body,
            Shape::Torus($s) => $body,
            Shape::Quadric($s) => $body,
            Shape::Implicit($s) => $body,
            Shape::BezierPatch($s) => $body,
            Shape::Superellipsoid($s) => $body,
            Shape::Csg($s) => $body,
            Shape::Mesh($s) => $body,
        }
    };
}

impl Shape {
    /// True when the parameter this shape reports for a ray comes from a
    /// closed formula, the same whatever interval the ray is tested with
    /// as long as it lies in it; false for the shapes found by an
    /// iterative search of the interval (torus, implicit surface, Bézier
    /// patch, superellipsoid) and for CSG. A packet walk, which tests
    /// primitives with other intervals than a single ray's walk does,
    /// gives that walk's answers only for these (see the world's packets).
    pub fn closed_form(&self) -> bool {
        match self {
            Shape::Sphere(_)
            | Shape::Plane(_)
            | Shape::Triangle(_)
            | Shape::Parallelogram(_)
            | Shape::Polygon(_)
            | Shape::Disk(_)
            | Shape::Cylinder(_)
            | Shape::Cone(_)
            | Shape::AxisBox(_)
            | Shape::Quadric(_)
            | Shape::Mesh(_) => true,
            Shape::Torus(_)
            | Shape::Implicit(_)
            | Shape::BezierPatch(_)
            | Shape::Superellipsoid(_)
            | Shape::Csg(_) => false,
        }
    }

    /// True when the shape lies in one plane (plane, triangle,
    /// parallelogram, polygon, disk), whatever its transform: a line
    /// crosses it once at most, so a ray's closest hit is its only one.
    pub fn is_flat(&self) -> bool {
        matches!(
            self,
            Shape::Plane(_)
                | Shape::Triangle(_)
                | Shape::Parallelogram(_)
                | Shape::Polygon(_)
                | Shape::Disk(_)
        )
    }

    /// The closest hit with `t` in the ray's open interval.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        dispatch!(self, s => s.intersect(ray))
    }

    /// True when the ray meets the shape anywhere in its open interval.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        dispatch!(self, s => s.occluded(ray))
    }

    /// The surface at a hit this shape returned for `ray`.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        dispatch!(self, s => s.surface(ray, hit))
    }

    /// The surface at a hit for a material that reads no (u, v): the same
    /// point, error bound and normal as [`Shape::surface`], with (u, v) and
    /// the tangents left zero where skipping them saves work (spheres and
    /// quadrics, whose (u, v) take an `atan2` and an `acos`), computed
    /// otherwise.
    pub fn surface_geometry(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        match self {
            Shape::Sphere(s) => s.surface_geometry(ray, hit),
            Shape::Cylinder(s) => s.surface_geometry(ray, hit),
            Shape::Cone(s) => s.surface_geometry(ray, hit),
            Shape::Quadric(s) => s.surface_geometry(ray, hit),
            _ => self.surface(ray, hit),
        }
    }

    /// The object-space bounds ([`Aabb::INFINITE`] for the plane).
    pub fn bounds(&self) -> Aabb {
        dispatch!(self, s => s.bounds())
    }

    /// The name used in scene files and messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Sphere(_) => "sphere",
            Shape::Plane(_) => "plane",
            Shape::Triangle(_) => "triangle",
            Shape::Parallelogram(_) => "parallelogram",
            Shape::Polygon(_) => "polygon",
            Shape::Disk(_) => "disk",
            Shape::Cylinder(_) => "cylinder",
            Shape::Cone(_) => "cone",
            Shape::AxisBox(_) => "box",
            Shape::Torus(_) => "torus",
            Shape::Quadric(_) => "quadric",
            Shape::Implicit(_) => "implicit",
            Shape::BezierPatch(_) => "bezier_patch",
            Shape::Superellipsoid(_) => "superellipsoid",
            Shape::Csg(_) => "csg",
            Shape::Mesh(_) => "mesh",
        }
    }

    /// The material of the part of the shape a hit is on, where that part
    /// has its own (a CSG child's); `None` for the shape's material.
    pub fn material(&self, hit: &ShapeHit) -> Option<u32> {
        match self {
            Shape::Csg(c) => c.material(hit),
            _ => None,
        }
    }

    /// The material that fills the solid, where it is not the shape's
    /// material (a CSG object's, [`Csg::medium`]).
    pub fn medium(&self) -> Option<u32> {
        match self {
            Shape::Csg(c) => c.medium(),
            _ => None,
        }
    }
}

#[cfg(test)]
mod closed_shapes_tests;
#[cfg(test)]
pub(crate) mod testing;
