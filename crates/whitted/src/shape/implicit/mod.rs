//! An implicit surface: the points where `f(x, y, z) = 0` inside a box, as
//! POV-Ray's isosurface.
//!
//! Scene syntax: `shape = "implicit"`, `function = "..."` (the language of
//! [`expression`]), `bounds = [[x0, y0, z0], [x1, y1, z1]]`,
//! `max_gradient = L`.
//!
//! Inside is where `f < 0`; the normal is the gradient, outward. Only the
//! part of the surface within the box is there: the box's own faces are not
//! a surface (make the box enclose the solid for glass).
//!
//! Intersection: the ray is clipped to the box, then sphere-traced with the
//! Lipschitz bound `L`: from a point where `f` has the value `v`, no root
//! lies closer than `|v| / L`, so the march steps that far (at least
//! [`MIN_STEP`] of the box's diagonal, so that a ray grazing the surface
//! ends) and stops at the first change of sign, which a safeguarded
//! regula falsi (Illinois steps, a bisection whenever two of them have not
//! halved the bracket) then closes to adjacent floating-point numbers, as
//! bisection alone did, in fewer evaluations of `f` where it is smooth
//! (docs/performance-log.md). Where `f` grows faster than `L`
//! between two steps, the largest such rate is kept
//! ([`Implicit::largest_gradient_seen`]) so the render can warn that
//! the bound is too small. A value that is NaN (outside the function's
//! domain) counts as outside, and the march crosses it in steps of
//! [`NAN_STEP`] of the clipped segment.
//!
//! The normal comes from central differences with a step of
//! [`NORMAL_STEP`] times the box's diagonal.
//!
//! (u, v): the point's box-normalised coordinates along the two axes other
//! than the one the normal is most aligned with (y, z where the normal is
//! mostly along x; z, x for y; x, y for z), as a box maps a texture on its
//! faces; [`ShapeHit::part`] is that dominant axis. The tangents are the
//! derivatives of that projection along the surface, so they are
//! perpendicular to the normal.

pub mod expression;

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

pub use expression::{Expression, ExpressionError};

use super::{LocalSurface, ShapeError, ShapeHit, finite, positive};
use crate::math::{Aabb, DVec2, Ray, Vec3, gamma};

/// The smallest march step, as a fraction of the box's diagonal: two roots
/// closer than this (a ray within about this of tangency) may be missed.
pub const MIN_STEP: f64 = 1e-6;

/// The march step through points where the function is NaN, as a fraction
/// of the clipped segment.
pub const NAN_STEP: f64 = 1e-3;

/// The step of the central differences for the normal, as a fraction of the
/// box's diagonal.
pub const NORMAL_STEP: f64 = 1e-7;

/// The error bound on a hit point, as a fraction of the box's diagonal: it
/// covers the bracket's last interval and the function's rounding near
/// the root, so secondary rays start clear of the surface.
const POINT_ERROR: f64 = 1e-10;

/// An implicit surface `f = 0` within a box.
#[derive(Clone, Debug, PartialEq)]
pub struct Implicit {
    data: Arc<Data>,
}

/// What [`Implicit`] keeps behind one pointer, so the enum stays small.
#[derive(Debug)]
struct Data {
    function: Expression,
    bounds: Aabb,
    max_gradient: f64,
    /// The length of the box's diagonal.
    size: f64,
    /// The bits of the largest rate of change seen above `max_gradient`
    /// (0 when none).
    largest_seen: AtomicU64,
}

impl PartialEq for Data {
    fn eq(&self, other: &Self) -> bool {
        self.function == other.function
            && self.bounds == other.bounds
            && self.max_gradient == other.max_gradient
    }
}

/// The sign of a value for root finding: NaN counts as outside.
#[inline]
fn inside(v: f64) -> bool {
    v < 0.0
}

impl Implicit {
    /// The surface `function = 0` within the box `min`..`max`, marched with
    /// the Lipschitz bound `max_gradient`. Refused: a box not above `min` on
    /// every axis, a `max_gradient` not positive, a function without a
    /// variable.
    pub fn new(
        function: Expression,
        min: Vec3,
        max: Vec3,
        max_gradient: f64,
    ) -> Result<Self, ShapeError> {
        let min = finite("bounds", min)?;
        let max = finite("bounds", max)?;
        let max_gradient = positive("max_gradient", max_gradient)?;
        if !min.cmplt(max).all() {
            return Err(ShapeError::Degenerate {
                shape: "implicit surface",
                why: "the bounds' first corner must be below the second on every axis",
            });
        }
        super::not_tiny("the bounds' shortest side", [(max - min).min_element()])?;
        if function.is_constant() {
            return Err(ShapeError::Degenerate {
                shape: "implicit surface",
                why: "the function names none of x, y, z",
            });
        }
        let size = crate::math::magnitude::norm(max - min);
        Ok(Self {
            data: Arc::new(Data {
                function,
                bounds: Aabb::new(min, max),
                max_gradient,
                size,
                largest_seen: AtomicU64::new(0),
            }),
        })
    }

    /// The function.
    pub fn function(&self) -> &Expression {
        &self.data.function
    }

    /// The Lipschitz bound the march trusts.
    pub fn max_gradient(&self) -> f64 {
        self.data.max_gradient
    }

    /// The largest rate of change of the function seen along a ray above
    /// [`Implicit::max_gradient`] since the shape was built or last
    /// [`Implicit::forget_gradient`], if any: parts of the surface may
    /// have been missed there.
    pub fn largest_gradient_seen(&self) -> Option<f64> {
        let seen = f64::from_bits(self.data.largest_seen.load(Ordering::Relaxed));
        (seen > 0.0).then_some(seen)
    }

    /// Clears the record of [`Implicit::largest_gradient_seen`].
    pub fn forget_gradient(&self) {
        self.data.largest_seen.store(0, Ordering::Relaxed);
    }

    /// Records `rate` when it beats the bound and what was seen before.
    fn note_gradient(&self, rate: f64) {
        if rate.is_finite() && rate > self.data.max_gradient {
            // Positive floats order as their bits.
            self.data
                .largest_seen
                .fetch_max(rate.to_bits(), Ordering::Relaxed);
        }
    }

    #[inline]
    fn f(&self, ray: &Ray, t: f64) -> f64 {
        self.data.function.eval(ray.at(t))
    }

    /// The part of the ray's interval inside the box, if any.
    fn clip(&self, ray: &Ray) -> Option<(f64, f64)> {
        let b = &self.data.bounds;
        let (mut near, mut far) = (ray.t_min, ray.t_max);
        for axis in 0..3 {
            let (o, d) = (ray.origin[axis], ray.dir[axis]);
            if d == 0.0 {
                if o < b.min[axis] || o > b.max[axis] {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((b.min[axis] - o) / d, (b.max[axis] - o) / d);
            let (t0, t1) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
            near = near.max(t0);
            far = far.min(t1);
        }
        (near <= far && near.is_finite() && far.is_finite()).then_some((near, far))
    }

    /// The first root of `f` along the ray in its open interval and within
    /// the box: sphere tracing to a change of sign, then [`Implicit::refine`].
    fn first_root(&self, ray: &Ray) -> Option<f64> {
        let (start, end) = self.clip(ray)?;
        let speed = crate::math::magnitude::norm(ray.dir);
        if speed == 0.0 || !speed.is_finite() {
            return None;
        }
        let lipschitz = self.data.max_gradient * speed;
        let min_step = MIN_STEP * self.data.size / speed;
        let nan_step = (NAN_STEP * (end - start)).max(min_step);
        let mut t = start;
        let mut v = self.f(ray, t);
        if v == 0.0 && t > ray.t_min {
            return Some(t);
        }
        while t < end {
            let step = if v.is_nan() {
                nan_step
            } else {
                (v.abs() / lipschitz).max(min_step)
            };
            let next = (t + step).min(end);
            if next <= t {
                return None;
            }
            let w = self.f(ray, next);
            self.note_gradient((w - v).abs() / ((next - t) * speed));
            if w == 0.0 {
                return Some(next);
            }
            if v != 0.0 && inside(v) != inside(w) {
                return Some(self.refine(ray, [t, next], [v, w], inside(v)));
            }
            t = next;
            v = w;
        }
        None
    }

    /// Closes the bracket `[a, b]` (where the inside flag changes from
    /// `a_inside`; `fa`, `fb` the values at its ends) to adjacent
    /// numbers; returns the end past the change.
    ///
    /// Each step is the Illinois variant of regula falsi (the secant
    /// through the ends, the value kept at an end that stays twice in a row
    /// halved), and the third step of every three a bisection when the
    /// two before it have not halved the bracket: never slower than
    /// bisection by more than a factor of three, and much faster where
    /// `f` is smooth.
    fn refine(
        &self,
        ray: &Ray,
        [mut a, mut b]: [f64; 2],
        [mut fa, mut fb]: [f64; 2],
        a_inside: bool,
    ) -> f64 {
        let mut kept = None;
        let mut round_width = b - a;
        for step in 0..200 {
            if step % 3 == 0 {
                round_width = b - a;
            }
            let mid = 0.5 * (a + b);
            let secant = a - fa * (b - a) / (fb - fa);
            let stalled = step % 3 == 2 && b - a > 0.5 * round_width;
            let t = if stalled || !(secant > a && secant < b) {
                mid
            } else {
                secant
            };
            if !(mid > a && mid < b && t > a && t < b) {
                break;
            }
            let v = self.f(ray, t);
            if v == 0.0 {
                return t;
            }
            if inside(v) == a_inside {
                (a, fa) = (t, v);
                if kept == Some(true) {
                    fb *= 0.5;
                }
                kept = Some(true);
            } else {
                (b, fb) = (t, v);
                if kept == Some(false) {
                    fa *= 0.5;
                }
                kept = Some(false);
            }
        }
        // The root lies in [a, b]; `b` is in the open interval, as `a` is at
        // least its start.
        b
    }

    /// The gradient at `p`, by central differences.
    fn gradient(&self, p: Vec3) -> Vec3 {
        let h = NORMAL_STEP * self.data.size;
        let f = &self.data.function;
        let mut g = Vec3::ZERO;
        for axis in 0..3 {
            let mut e = Vec3::ZERO;
            e[axis] = h;
            g[axis] = (f.eval(p + e) - f.eval(p - e)) / (2.0 * h);
        }
        g
    }

    /// The unit outward normal at `p`, or `fallback` where the gradient
    /// vanishes or is not finite.
    fn normal(&self, p: Vec3, fallback: Vec3) -> Vec3 {
        let g = self.gradient(p);
        let length = crate::math::magnitude::norm(g);
        if length > 0.0 && length.is_finite() {
            let n = g / length;
            n / n.length()
        } else {
            fallback
        }
    }

    /// The closest hit in the ray's interval; `part` is the axis the normal
    /// is most aligned with.
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let t = self.first_root(ray)?;
        let normal = self.normal(ray.at(t), -ray.dir.normalize_or(Vec3::Z));
        Some(ShapeHit {
            part: dominant_axis(normal) as u32,
            ..ShapeHit::at(t)
        })
    }

    /// True when the ray meets the surface in its interval.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.first_root(ray).is_some()
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> LocalSurface {
        let b = &self.data.bounds;
        let point = ray.at(hit.t).clamp(b.min, b.max);
        let normal = self.normal(point, -ray.dir.normalize_or(Vec3::Z));
        let c = (hit.part as usize).min(2);
        let (a, bb) = ((c + 1) % 3, (c + 2) % 3);
        let extent = b.max - b.min;
        let along = (point - b.min) / extent;
        let tangent = |axis: usize| {
            let mut t = Vec3::ZERO;
            t[axis] = extent[axis];
            if normal[c] != 0.0 {
                t[c] = -extent[axis] * normal[axis] / normal[c];
            }
            t - normal * t.dot(normal)
        };
        LocalSurface {
            point,
            point_error: Vec3::splat(POINT_ERROR * self.data.size) + gamma(4) * point.abs(),
            normal,
            uv: DVec2::new(along[a], along[bb]),
            dpdu: tangent(a),
            dpdv: tangent(bb),
        }
    }

    /// The bounding box given.
    pub fn bounds(&self) -> Aabb {
        self.data.bounds
    }
}

/// The axis along which `n` is largest in magnitude.
fn dominant_axis(n: Vec3) -> usize {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests;
