//! Geometry basics: vectors, rays, bounding boxes, affine transforms and the
//! floating-point error bounds that keep secondary rays off the surface they
//! leave.
//!
//! All geometry is `f64`. Hit points carry an absolute error bound per axis
//! (`p_error`), derived in the style of pbrt-v4 (Pharr, Jakob and Humphreys,
//! *Physically Based Rendering*, 4th ed., section 6.8): each shape reprojects
//! its hit point onto the surface and bounds what is left of the rounding
//! error, transforms carry that bound into world space, and
//! [`offset_ray_origin`] moves a new ray's origin just past the bound along the
//! surface normal. The offset is relative to the magnitudes involved, so a
//! scene scaled by 1e-3 or 1e4 renders the same picture.

pub mod apart;
pub mod magnitude;
pub mod prefetch;
pub mod random;
pub mod sampling;
#[cfg(all(test, target_arch = "x86_64"))]
pub(crate) mod test_support;

pub use glam::{DAffine3, DMat3, DVec2, DVec3};

/// A point or direction in 3D space.
pub type Vec3 = DVec3;

/// The machine epsilon used by error bounds: half an ulp of 1.0.
pub const MACHINE_EPSILON: f64 = f64::EPSILON * 0.5;

/// Bound on the relative error of `n` successive floating-point operations,
/// `γ(n) = nε / (1 - nε)` (pbrt-v4 eq. 6.20).
pub const fn gamma(n: u32) -> f64 {
    let n_eps = n as f64 * MACHINE_EPSILON;
    n_eps / (1.0 - n_eps)
}

/// A ray `origin + t * dir` for `t` in the open interval `(t_min, t_max)`.
///
/// `dir` need not be unit length: rays are carried into object space
/// unnormalised so that `t` means the same point in both spaces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Where the ray goes (any non-zero length).
    pub dir: Vec3,
    /// Component-wise reciprocal of `dir`, for slab tests.
    pub inv_dir: Vec3,
    /// Hits at or before this parameter are ignored.
    pub t_min: f64,
    /// Hits at or beyond this parameter are ignored.
    pub t_max: f64,
}

impl Ray {
    /// A ray over `(0, ∞)`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self::segment(origin, dir, f64::INFINITY)
    }

    /// A ray over `(0, t_max)`.
    pub fn segment(origin: Vec3, dir: Vec3, t_max: f64) -> Self {
        Self {
            origin,
            dir,
            inv_dir: dir.recip(),
            t_min: 0.0,
            t_max,
        }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + t * self.dir
    }

    /// True when `t` lies inside the ray's open interval.
    pub fn contains(&self, t: f64) -> bool {
        t > self.t_min && t < self.t_max
    }
}

/// An axis-aligned bounding box. The empty box has `min = +∞`, `max = -∞`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The box that contains nothing; the identity of [`Aabb::union`].
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f64::INFINITY),
        max: Vec3::splat(f64::NEG_INFINITY),
    };

    /// The box that contains everything (for unbounded shapes).
    pub const INFINITE: Self = Self {
        min: Vec3::splat(f64::NEG_INFINITY),
        max: Vec3::splat(f64::INFINITY),
    };

    /// The box spanned by two corners in any order.
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The smallest box around all `points`.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points
            .into_iter()
            .fold(Self::EMPTY, |b, p| b.union_point(p))
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// True when every extent is finite.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// The smallest box around both.
    pub fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The common part of both, or `None` when they do not meet (boxes
    /// that only touch meet in a flat box).
    pub fn intersection(&self, other: &Self) -> Option<Self> {
        let common = Self {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        };
        common.min.cmple(common.max).all().then_some(common)
    }

    /// The smallest box around `self` and `p`.
    pub fn union_point(&self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The box grown by `margin` on every side.
    pub fn expanded(&self, margin: f64) -> Self {
        Self {
            min: self.min - Vec3::splat(margin),
            max: self.max + Vec3::splat(margin),
        }
    }

    /// Width, height and depth.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// The centre point.
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// The surface area (0 for an empty box).
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// The eight corners.
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The parameter interval where `ray` is inside the box, clipped to the
    /// ray's own interval, or `None` if they do not meet (always for the
    /// empty box). Rays parallel to a slab and inside it (or on its faces)
    /// are inside.
    pub fn intersect_ray(&self, ray: &Ray) -> Option<(f64, f64)> {
        // Its planes at ±∞ would put every ray inside every slab.
        if self.is_empty() {
            return None;
        }
        let t0 = (self.min - ray.origin) * ray.inv_dir;
        let t1 = (self.max - ray.origin) * ray.inv_dir;
        let mut near = ray.t_min;
        let mut far = ray.t_max;
        for axis in 0..3 {
            let (a, b) = (t0[axis], t1[axis]);
            // NaN comes from 0 · ∞: a ray lying in a face plane, which
            // counts as inside that slab.
            if a.is_nan() || b.is_nan() {
                continue;
            }
            // Both ends widened by 2γ(3), away from the interval whatever
            // their sign (a ray may start at a negative `t_min`), so
            // rounding never loses a grazing hit (pbrt-v4 section 6.8.2),
            // nor culls a primitive whose hit lies an ulp before the box's
            // computed entry.
            let (low, high) = (a.min(b), a.max(b));
            let (shrink, grow) = (1.0 - 2.0 * gamma(3), 1.0 + 2.0 * gamma(3));
            near = near.max(low * if low < 0.0 { grow } else { shrink });
            far = far.min(high * if high < 0.0 { shrink } else { grow });
        }
        (near <= far).then_some((near, far))
    }
}

/// Errors building a transform.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TransformError {
    /// The matrix has no inverse (a zero scale, or collapsed axes).
    #[error("the transform is singular: it flattens space (a zero scale or dependent axes)")]
    Singular {
        /// The determinant of the linear part.
        determinant: f64,
    },
    /// A scale factor (the length of an axis of the matrix) or the
    /// translation beyond the range of [`magnitude`]: a shape it carries
    /// could not be intersected without overflow or underflow.
    #[error("the transform's {what} is out of range: {error}")]
    OutOfRange {
        /// "scale factor" or "translation".
        what: &'static str,
        /// How it is out of range.
        error: magnitude::MagnitudeError,
    },
    /// A rotation axis of zero length.
    #[error("the rotation axis has zero length")]
    ZeroAxis,
    /// A value that is not a finite number.
    #[error("the transform contains a value that is not a finite number")]
    NotFinite,
}

/// An invertible affine transform, kept with its inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    world_from_object: DAffine3,
    object_from_world: DAffine3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The transform that changes nothing.
    pub const IDENTITY: Self = Self {
        world_from_object: DAffine3::IDENTITY,
        object_from_world: DAffine3::IDENTITY,
    };

    /// A transform from its matrix, refused when not finite, when a scale
    /// factor or the translation is out of [`magnitude`]'s range, or when
    /// singular.
    pub fn from_affine(world_from_object: DAffine3) -> Result<Self, TransformError> {
        if !world_from_object.is_finite() {
            return Err(TransformError::NotFinite);
        }
        let m = &world_from_object.matrix3;
        for axis in [m.x_axis, m.y_axis, m.z_axis] {
            magnitude::length(magnitude::norm(axis)).map_err(|error| {
                TransformError::OutOfRange {
                    what: "scale factor",
                    error,
                }
            })?;
        }
        magnitude::point(world_from_object.translation).map_err(|error| {
            TransformError::OutOfRange {
                what: "translation",
                error,
            }
        })?;
        let determinant = m.determinant();
        // How flat the transformed unit cube is: |det| over the product of
        // the column lengths is 1 for orthogonal axes, whatever their scale,
        // and 0 when the axes are dependent. A stretch by 1e6 is fine; axes
        // within 1e-12 radians of a plane are not.
        let volume_ratio =
            determinant.abs() / (m.x_axis.length() * m.y_axis.length() * m.z_axis.length());
        if volume_ratio.is_nan() || volume_ratio <= 1e-12 {
            return Err(TransformError::Singular { determinant });
        }
        let object_from_world = world_from_object.inverse();
        if !object_from_world.is_finite() {
            return Err(TransformError::Singular { determinant });
        }
        Ok(Self {
            world_from_object,
            object_from_world,
        })
    }

    /// A transform from a row-major 3x4 matrix `[R | t]`.
    pub fn from_rows(rows: [[f64; 4]; 3]) -> Result<Self, TransformError> {
        let col = |c: usize| Vec3::new(rows[0][c], rows[1][c], rows[2][c]);
        Self::from_affine(DAffine3::from_cols(col(0), col(1), col(2), col(3)))
    }

    /// Moves points by `offset`.
    pub fn translate(offset: Vec3) -> Result<Self, TransformError> {
        Self::from_affine(DAffine3::from_translation(offset))
    }

    /// Scales about the origin, per axis.
    pub fn scale(factors: Vec3) -> Result<Self, TransformError> {
        Self::from_affine(DAffine3::from_scale(factors))
    }

    /// Rotates by `degrees` about `axis` through the origin (right-handed).
    pub fn rotate(axis: Vec3, degrees: f64) -> Result<Self, TransformError> {
        if !axis.is_finite() || !degrees.is_finite() {
            return Err(TransformError::NotFinite);
        }
        let axis = unit(axis).ok_or(TransformError::ZeroAxis)?;
        Self::from_affine(DAffine3::from_axis_angle(axis, degrees.to_radians()))
    }

    /// The rigid transform (rotation and translation) that puts the origin at
    /// `origin` and the +z axis along `axis`. Used to place canonical disks,
    /// cylinders and cones.
    pub fn frame(origin: Vec3, axis: Vec3) -> Result<Self, TransformError> {
        if !(origin.is_finite() && axis.is_finite()) {
            return Err(TransformError::NotFinite);
        }
        let w = unit(axis).ok_or(TransformError::ZeroAxis)?;
        let (u, v) = w.any_orthonormal_pair();
        Self::from_affine(DAffine3::from_cols(u, v, w, origin))
    }

    /// `self` applied after `first`: `self ∘ first`.
    pub fn then_after(&self, first: &Self) -> Self {
        Self {
            world_from_object: self.world_from_object * first.world_from_object,
            object_from_world: first.object_from_world * self.object_from_world,
        }
    }

    /// The matrix taking object space to world space.
    pub fn world_from_object(&self) -> &DAffine3 {
        &self.world_from_object
    }

    /// The matrix taking world space to object space.
    pub fn object_from_world(&self) -> &DAffine3 {
        &self.object_from_world
    }

    /// True for the identity (no work to do).
    pub fn is_identity(&self) -> bool {
        self.world_from_object == DAffine3::IDENTITY
    }

    /// A world-space ray in object space, with the same `t` parameterisation.
    pub fn ray_to_object(&self, ray: &Ray) -> Ray {
        let dir = self.object_from_world.transform_vector3(ray.dir);
        Ray {
            origin: self.object_from_world.transform_point3(ray.origin),
            dir,
            inv_dir: dir.recip(),
            t_min: ray.t_min,
            t_max: ray.t_max,
        }
    }

    /// An object-space point in world space.
    pub fn point_to_world(&self, p: Vec3) -> Vec3 {
        self.world_from_object.transform_point3(p)
    }

    /// An object-space direction in world space.
    pub fn vector_to_world(&self, v: Vec3) -> Vec3 {
        self.world_from_object.transform_vector3(v)
    }

    /// An object-space normal in world space (by the inverse transpose), not
    /// normalised.
    pub fn normal_to_world(&self, n: Vec3) -> Vec3 {
        self.object_from_world.matrix3.transpose() * n
    }

    /// An object-space point and its error bound in world space: the bound
    /// grows by the rounding of the transform itself (pbrt-v4 eq. 6.30).
    pub fn point_with_error_to_world(&self, p: Vec3, p_error: Vec3) -> (Vec3, Vec3) {
        let m = &self.world_from_object;
        let abs_m = m.matrix3.abs();
        let world = m.transform_point3(p);
        let error = (1.0 + gamma(3)) * (abs_m * p_error)
            + gamma(3) * (abs_m * p.abs() + m.translation.abs());
        (world, error)
    }

    /// The world-space box around an object-space box.
    pub fn bounds_to_world(&self, b: &Aabb) -> Aabb {
        if b.is_empty() || !b.is_finite() {
            return *b;
        }
        Aabb::from_points(b.corners().map(|c| self.point_to_world(c)))
    }
}

/// The origin for a ray leaving the surface point `p` (with absolute error
/// bound `p_error`) in direction `w`, moved along the geometric normal `n`
/// just past the error bound on the side `w` points to, then rounded away
/// from `p` so it cannot fall back inside the bound (pbrt-v4
/// `OffsetRayOrigin`).
///
/// The bound is doubled to also cover the rounding of the next ray's trip into
/// object space.
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    offset_to_side(p, p_error, n, w.dot(n) < 0.0)
}

/// [`offset_ray_origin`] for any direction on the side of `n` that `below`
/// says (true: against `n`), which is all the direction decides.
fn offset_to_side(p: Vec3, p_error: Vec3, n: Vec3, below: bool) -> Vec3 {
    let d = 2.0 * n.abs().dot(p_error);
    let mut offset = d * n;
    if below {
        offset = -offset;
    }
    let po = p + offset;
    Vec3::new(
        round_away(po.x, offset.x),
        round_away(po.y, offset.y),
        round_away(po.z, offset.z),
    )
}

/// The origins of the rays leaving one surface point, one per side of its
/// geometric normal, each computed by [`offset_ray_origin`] the first time
/// a ray leaves on that side: a point lit by several lights, or that
/// reflects and refracts, pays for each side once, with the same origins
/// to the bit.
#[derive(Clone, Copy, Debug)]
pub struct RayOrigins {
    p: Vec3,
    p_error: Vec3,
    n: Vec3,
    /// Above (along `n`) and below.
    sides: [Option<Vec3>; 2],
}

impl RayOrigins {
    /// The origins for point `p` with absolute error bound `p_error` and
    /// geometric normal `n`, none computed yet.
    #[inline]
    pub fn new(p: Vec3, p_error: Vec3, n: Vec3) -> Self {
        Self {
            p,
            p_error,
            n,
            sides: [None; 2],
        }
    }

    /// The origin of a ray leaving in direction `w`:
    /// `offset_ray_origin(p, p_error, n, w)`.
    #[inline]
    pub fn towards(&mut self, w: Vec3) -> Vec3 {
        let below = w.dot(self.n) < 0.0;
        let (p, p_error, n) = (self.p, self.p_error, self.n);
        *self.sides[usize::from(below)].get_or_insert_with(|| offset_to_side(p, p_error, n, below))
    }
}

/// Moves `value` one ulp further in the direction of `offset`'s sign.
fn round_away(value: f64, offset: f64) -> f64 {
    if offset > 0.0 {
        value.next_up()
    } else if offset < 0.0 {
        value.next_down()
    } else {
        value
    }
}

/// `v` scaled to unit length, or `None` when it is zero or not finite.
///
/// Divides by the largest absolute component first, so that vectors whose
/// squared length would underflow or overflow (`[1e-200, 0, 0]`,
/// `[1e200, 0, 0]`) still normalise: only a true zero vector is refused.
pub fn unit(v: Vec3) -> Option<Vec3> {
    let largest = v.abs().max_element();
    if !(largest.is_finite() && largest > 0.0) {
        return None;
    }
    (v / largest).try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-12
    }

    #[test]
    fn transform_round_trips_points_and_keeps_normals_perpendicular() {
        let t = Transform::translate(Vec3::new(1.0, 2.0, 3.0))
            .unwrap()
            .then_after(&Transform::rotate(Vec3::new(1.0, 1.0, 0.0), 37.0).unwrap())
            .then_after(&Transform::scale(Vec3::new(2.0, 0.5, 3.0)).unwrap());
        let p = Vec3::new(0.3, -0.7, 1.1);
        let back = t.object_from_world().transform_point3(t.point_to_world(p));
        assert!(close(p, back));
        let tangent = Vec3::new(1.0, 1.0, 0.0);
        let normal = Vec3::new(1.0, -1.0, 0.0);
        let dot = t.vector_to_world(tangent).dot(t.normal_to_world(normal));
        assert!(dot.abs() < 1e-12);
    }

    #[test]
    fn strong_but_invertible_stretches_are_accepted() {
        let t = Transform::scale(Vec3::new(1e6, 1.0, 1e-6)).unwrap();
        let p = Vec3::new(2e-6, 3.0, 4e6);
        let back = t.object_from_world().transform_point3(t.point_to_world(p));
        assert!(((back - p) / p).abs().max_element() < 1e-12);
        let shear = Transform::from_rows([
            [1.0, 1e-9, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ]);
        assert!(shear.is_ok());
        let flat = Transform::from_rows([
            [1.0, 1.0, 0.0, 0.0],
            [1.0, 1.0 + 1e-15, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ]);
        assert!(matches!(flat, Err(TransformError::Singular { .. })));
    }

    #[test]
    fn singular_transforms_are_refused() {
        assert!(matches!(
            Transform::scale(Vec3::new(1.0, 0.0, 1.0)),
            Err(TransformError::Singular { .. })
        ));
        assert_eq!(
            Transform::rotate(Vec3::ZERO, 10.0),
            Err(TransformError::ZeroAxis)
        );
        assert_eq!(
            Transform::translate(Vec3::new(f64::NAN, 0.0, 0.0)),
            Err(TransformError::NotFinite)
        );
    }

    #[test]
    fn scales_and_translations_out_of_range_are_refused_as_such() {
        let too_large = magnitude::MagnitudeError::TooLarge { value: 1e103 };
        assert_eq!(
            Transform::scale(Vec3::splat(1e103)),
            Err(TransformError::OutOfRange {
                what: "scale factor",
                error: too_large,
            })
        );
        assert_eq!(
            Transform::scale(Vec3::new(1.0, 1e-300, 1.0)),
            Err(TransformError::OutOfRange {
                what: "scale factor",
                error: magnitude::MagnitudeError::TooSmall { value: 1e-300 },
            })
        );
        assert!(matches!(
            Transform::translate(Vec3::new(0.0, 0.0, 1e31)),
            Err(TransformError::OutOfRange {
                what: "translation",
                ..
            })
        ));
        assert!(Transform::scale(Vec3::new(1e30, 1e-30, -1.0)).is_ok());
    }

    #[test]
    fn unit_normalises_tiny_and_huge_vectors_and_refuses_only_zero() {
        for scale in [1e-300, 1e-200, 1e-160, 1.0, 1e160, 1e200, 1e300] {
            let v = unit(Vec3::new(3.0, -4.0, 0.0) * scale).unwrap();
            assert!(close(v, Vec3::new(0.6, -0.8, 0.0)), "{scale:e}: {v}");
        }
        assert_eq!(
            unit(Vec3::new(f64::MIN_POSITIVE / 4.0, 0.0, 0.0)),
            Some(Vec3::X)
        );
        assert_eq!(unit(Vec3::new(0.0, -f64::MAX, 0.0)), Some(-Vec3::Y));
        assert_eq!(unit(Vec3::ZERO), None);
        assert_eq!(unit(Vec3::new(f64::INFINITY, 0.0, 0.0)), None);
        assert_eq!(unit(Vec3::new(f64::NAN, 1.0, 0.0)), None);
    }

    #[test]
    fn rotations_and_frames_accept_tiny_and_huge_axes() {
        for axis in [Vec3::new(0.0, 0.0, 1e-200), Vec3::new(0.0, 0.0, 1e200)] {
            let r = Transform::rotate(axis, 90.0).unwrap();
            assert!(close(r.vector_to_world(Vec3::X), Vec3::Y));
            let f = Transform::frame(Vec3::ZERO, Vec3::new(axis.z, 0.0, 0.0)).unwrap();
            assert!(close(f.vector_to_world(Vec3::Z), Vec3::X));
        }
    }

    #[test]
    fn frame_puts_z_along_the_axis_without_scaling() {
        let origin = Vec3::new(1.0, 2.0, 3.0);
        let t = Transform::frame(origin, Vec3::new(3.0, -4.0, 0.0)).unwrap();
        assert!(close(t.point_to_world(Vec3::ZERO), origin));
        assert!(close(t.vector_to_world(Vec3::Z), Vec3::new(0.6, -0.8, 0.0)));
        assert!((t.vector_to_world(Vec3::X).length() - 1.0).abs() < 1e-12);
        assert_eq!(
            Transform::frame(origin, Vec3::ZERO),
            Err(TransformError::ZeroAxis)
        );
    }

    #[test]
    fn offset_origin_lands_on_the_side_of_the_new_direction() {
        let p = Vec3::new(1e4, 0.0, 3.0);
        let err = Vec3::splat(1e-9);
        let up = offset_ray_origin(p, err, Vec3::Y, Vec3::new(0.0, 1.0, 1.0));
        let down = offset_ray_origin(p, err, Vec3::Y, Vec3::new(0.0, -1.0, 1.0));
        assert!(up.y > 0.0 && down.y < 0.0);
    }

    #[test]
    fn kept_origins_are_offset_ray_origin_for_every_direction() {
        let mut rng = random::Rng::new(5);
        for _ in 0..2000 {
            let p = 1e3 * rng.unit_vector() * rng.uniform();
            let err = Vec3::splat(1e-12 * (1.0 + 1e6 * rng.uniform())) * p.abs().max_element();
            let n = rng.unit_vector();
            let mut origins = RayOrigins::new(p, err, n);
            for _ in 0..4 {
                let w = match rng.uniform() {
                    u if u < 0.1 => n.any_orthonormal_vector(),
                    _ => rng.unit_vector(),
                };
                let want = offset_ray_origin(p, err, n, w);
                assert_eq!(origins.towards(w), want, "{p:?} {n:?} {w:?}");
            }
        }
    }

    #[test]
    fn box_slab_test_handles_axis_parallel_rays() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let inside = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        let (near, far) = b.intersect_ray(&inside).unwrap();
        assert!(near <= 1.0 && 1.0 - near < 1e-14);
        assert!(far >= 2.0 && far - 2.0 < 1e-14);
        let outside = Ray::new(Vec3::new(1.5, 0.5, -1.0), Vec3::Z);
        assert_eq!(b.intersect_ray(&outside), None);
        let on_face = Ray::new(Vec3::new(0.0, 0.5, -1.0), Vec3::Z);
        assert!(b.intersect_ray(&on_face).is_some());
    }

    #[test]
    fn box_slab_test_widens_negative_parameters_outward_too() {
        // The box lies behind the origin, at t in [-3, -2], and the ray's
        // interval starts at -10: both ends must be widened away from it.
        let b = Aabb::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(-2.0, 1.0, 1.0));
        let mut ray = Ray::new(Vec3::new(0.0, 0.5, 0.5), Vec3::X);
        ray.t_min = -10.0;
        let (near, far) = b.intersect_ray(&ray).unwrap();
        assert!(near <= -3.0 && near > -3.0 - 1e-14, "{near}");
        assert!((-2.0..-2.0 + 1e-14).contains(&far), "{far}");
        // A ray ending exactly where the box starts still meets it.
        ray.t_max = -3.0;
        assert!(b.intersect_ray(&ray).is_some());
    }

    #[test]
    fn no_ray_meets_the_empty_box() {
        for dir in [
            Vec3::X,
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(0.0, 0.0, -1.0),
        ] {
            assert_eq!(Aabb::EMPTY.intersect_ray(&Ray::new(Vec3::ZERO, dir)), None);
        }
    }
}
