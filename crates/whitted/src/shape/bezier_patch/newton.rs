//! The patch seen from a ray, and Newton's iteration for where the ray
//! meets it.
//!
//! The ray is the intersection of two planes through its origin, with unit
//! normals `n1`, `n2` perpendicular to its direction (Kajiya's formulation).
//! Projecting the control points onto (`n1`, `n2`, `d̂`) relative to the
//! origin gives a patch whose first two coordinates are the distances of
//! P(u, v) from the two planes and whose third is the distance along the
//! ray: the ray meets the patch where the first two vanish, a 2×2 system in
//! (u, v), and the third, divided by `|d|`, is then `t`.
//!
//! The frame is made per leaf, of the leaf's own control net: the box of
//! its first two coordinates must hold the origin, or the ray misses the
//! piece (the convex hull property), which turns away most leaves whose
//! 3D box the ray crosses without meeting the surface before any
//! iteration.

use super::bernstein::{ControlNet, basis, evaluate};
use super::hierarchy::Node;
use crate::math::{DVec2, Ray, Vec3, magnitude};

/// Iterations before Newton's method gives up on a leaf.
const MAX_ITERATIONS: u32 = 16;

/// The step in a piece's (s, t) below which the iteration has converged:
/// the step is taken and the iteration ends, as the error left after it
/// is of the order of its square (Newton's convergence is quadratic; a
/// piece is nearly flat, so the constant is small)...
const CONVERGED_STEP: f64 = 1e-7;

/// ...unless the ray grazes the piece: the sine of the angle between the
/// projected tangents below this, where the constant grows and rounding
/// is amplified, the iteration goes on to this step.
const GRAZING: f64 = 0.01;

/// The converged step of a grazing ray.
const GRAZING_STEP: f64 = 1e-14;

/// The largest step in (u, v) of the last Newton step on the patch's own
/// net whose effect on `t` is added (a larger one means the root was not
/// there: it is then left as found).
const POLISH_STEP: f64 = 1e-6;

/// How often a step that leaves the range or fails to reduce the residual
/// is halved before the iteration gives up.
const MAX_HALVINGS: u32 = 8;

/// A root is accepted when the ray passes within this fraction of the
/// projected patch's scale (its size plus its distance from the origin)
/// of the point P(u, v).
const ACCEPTED_RESIDUAL: f64 = 1e-10;

/// How far outside [0, 1] a root's (u, v) may fall and still be accepted
/// (then clamped): rounding at the patch's edges.
const EDGE: f64 = 1e-12;

/// A piece of the patch in the ray's frame: the two plane distances of its
/// control points, one array per plane (the distance along the ray is
/// taken on the patch's own net, at the root).
pub(super) struct RayFrame {
    /// Distances of the control points from the first plane.
    x: [[f64; 4]; 4],
    /// Distances from the second plane.
    y: [[f64; 4]; 4],
    /// The ray's origin and the frame's axes: the planes' unit normals and
    /// the unit direction.
    origin: Vec3,
    axes: [Vec3; 3],
    /// `1 / |d|`, to turn the distance along the ray into `t`.
    inverse_length: f64,
    /// The residual below which a root is accepted.
    tolerance: f64,
    /// Whether the box of the first two coordinates of the control points
    /// (widened by the tolerance) holds the origin.
    faces: bool,
}

/// The two plane distances at (u, v) and their partial derivatives.
struct Plane2 {
    x: f64,
    y: f64,
    xu: f64,
    yu: f64,
    xv: f64,
    yv: f64,
}

/// A root: the ray parameter and the patch parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Root {
    pub(super) t: f64,
    pub(super) u: f64,
    pub(super) v: f64,
}

impl RayFrame {
    /// `net` (a leaf's piece) as seen from `ray`, or `None` for a ray whose
    /// direction has no usable length.
    pub(super) fn new(net: &ControlNet, ray: &Ray) -> Option<Self> {
        let length = magnitude::norm(ray.dir);
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let forward = ray.dir / length;
        let (n1, n2) = forward.any_orthonormal_pair();
        let mut frame = Self {
            x: [[0.0; 4]; 4],
            y: [[0.0; 4]; 4],
            origin: ray.origin,
            axes: [n1, n2, forward],
            inverse_length: 1.0 / length,
            tolerance: 0.0,
            faces: false,
        };
        let mut scale: f64 = 0.0;
        let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for (i, row) in net.iter().enumerate() {
            for (j, &p) in row.iter().enumerate() {
                let q = p - ray.origin;
                let local = Vec3::new(n1.dot(q), n2.dot(q), forward.dot(q));
                let far = local.abs().max_element();
                if far > scale {
                    scale = far;
                }
                (frame.x[i][j], frame.y[i][j]) = (local.x, local.y);
                for (k, value) in [local.x, local.y].into_iter().enumerate() {
                    if value < low[k] {
                        low[k] = value;
                    }
                    if value > high[k] {
                        high[k] = value;
                    }
                }
            }
        }
        frame.tolerance = ACCEPTED_RESIDUAL * scale;
        let reach = frame.tolerance;
        frame.faces = low[0] <= reach && low[1] <= reach && high[0] >= -reach && high[1] >= -reach;
        Some(frame)
    }

    /// False when the ray surely misses the piece: the origin lies outside
    /// the box of the projected control points.
    pub(super) fn faces(&self) -> bool {
        self.faces
    }

    /// The plane distances at (u, v) with their derivatives.
    #[inline]
    fn planes(&self, u: f64, v: f64) -> Plane2 {
        let (bu, du) = basis(u);
        let (bv, dv) = basis(v);
        let mut e = Plane2 {
            x: 0.0,
            y: 0.0,
            xu: 0.0,
            yu: 0.0,
            xv: 0.0,
            yv: 0.0,
        };
        for i in 0..4 {
            let (xr, yr) = (&self.x[i], &self.y[i]);
            let x = xr[0] * bv[0] + xr[1] * bv[1] + xr[2] * bv[2] + xr[3] * bv[3];
            let y = yr[0] * bv[0] + yr[1] * bv[1] + yr[2] * bv[2] + yr[3] * bv[3];
            let xs = xr[0] * dv[0] + xr[1] * dv[1] + xr[2] * dv[2] + xr[3] * dv[3];
            let ys = yr[0] * dv[0] + yr[1] * dv[1] + yr[2] * dv[2] + yr[3] * dv[3];
            e.x += bu[i] * x;
            e.y += bu[i] * y;
            e.xu += du[i] * x;
            e.yu += du[i] * y;
            e.xv += bu[i] * xs;
            e.yv += bu[i] * ys;
        }
        e
    }

    /// Where the ray meets the bilinear surface through the piece's four
    /// corners, as (s, t): the piece is nearly flat, so that is close to
    /// the root when the ray meets the piece; the centre when the bilinear
    /// surface is missed or degenerate.
    fn bilinear_seed(&self) -> [f64; 2] {
        let corner = |i: usize, j: usize| [self.x[i][j], self.y[i][j]];
        let cross = |p: [f64; 2], q: [f64; 2]| p[0] * q[1] - p[1] * q[0];
        let (c00, c30, c03, c33) = (corner(0, 0), corner(3, 0), corner(0, 3), corner(3, 3));
        // B(s, t) = a + b s + c t + d s t = 0, the origin.
        let a = c00;
        let b = [c30[0] - c00[0], c30[1] - c00[1]];
        let c = [c03[0] - c00[0], c03[1] - c00[1]];
        let d = [
            c00[0] - c30[0] - c03[0] + c33[0],
            c00[1] - c30[1] - c03[1] + c33[1],
        ];
        // a + b s and c + d s are parallel: a quadratic in s.
        let (q2, q1, q0) = (cross(b, d), cross(a, d) + cross(b, c), cross(a, c));
        let centre = [0.5, 0.5];
        let s = if q2.abs() <= 1e-12 * (q1.abs() + q0.abs()) {
            -q0 / q1
        } else {
            let disc = q1 * q1 - 4.0 * q2 * q0;
            if disc < 0.0 {
                return centre;
            }
            let r = -0.5 * (q1 + disc.sqrt().copysign(q1));
            let (s0, s1) = (r / q2, q0 / r);
            if (s0 - 0.5).abs() <= (s1 - 0.5).abs() {
                s0
            } else {
                s1
            }
        };
        let along = [c[0] + d[0] * s, c[1] + d[1] * s];
        let base = [a[0] + b[0] * s, a[1] + b[1] * s];
        let k = usize::from(along[1].abs() > along[0].abs());
        let t = -base[k] / along[k];
        let near = |x: f64| (-0.5..=1.5).contains(&x);
        if near(s) && near(t) { [s, t] } else { centre }
    }

    /// The root Newton's method finds from the bilinear seed in `leaf` (whose
    /// piece the frame holds) with `t` in `(ray.t_min, t_max)`, if any. The
    /// iteration runs in the piece's own (s, t) and may wander one leaf
    /// width beyond it; a root anywhere on the patch is accepted (it is a
    /// true intersection, whichever leaf it lies in), and reported in the
    /// patch's (u, v).
    pub(super) fn solve(
        &self,
        leaf: &Node,
        net: &ControlNet,
        t_min: f64,
        t_max: f64,
    ) -> Option<Root> {
        let inside = |u: f64, v: f64| (-1.0..=2.0).contains(&u) && (-1.0..=2.0).contains(&v);
        let [mut u, mut v] = self.bilinear_seed();
        let mut e = self.planes(u, v);
        'iterations: for _ in 0..MAX_ITERATIONS {
            let residual = e.x * e.x + e.y * e.y;
            let det = e.xu * e.yv - e.yu * e.xv;
            if residual == 0.0 || det == 0.0 || !det.is_finite() {
                break;
            }
            let step_u = (e.x * e.yv - e.xv * e.y) / det;
            let step_v = (e.xu * e.y - e.x * e.yu) / det;
            let tangents = (e.xu * e.xu + e.yu * e.yu) * (e.xv * e.xv + e.yv * e.yv);
            let converged = if det * det > GRAZING * GRAZING * tangents {
                CONVERGED_STEP
            } else {
                GRAZING_STEP
            };
            if step_u.abs().max(step_v.abs()) <= converged {
                u -= step_u;
                v -= step_v;
                break;
            }
            // Damped: the full step unless it leaves the range or fails
            // to shrink the residual, then halves of it.
            let mut fraction = 1.0;
            for _ in 0..MAX_HALVINGS {
                let (next_u, next_v) = (u - fraction * step_u, v - fraction * step_v);
                if inside(next_u, next_v) {
                    let next = self.planes(next_u, next_v);
                    if next.x * next.x + next.y * next.y < residual {
                        (u, v, e) = (next_u, next_v, next);
                        continue 'iterations;
                    }
                }
                fraction *= 0.5;
            }
            break;
        }
        self.root_at(leaf, net, [u, v], t_min, t_max)
    }

    /// The piece's (s, t) as a root of the whole patch `net`, when the
    /// point lies on the patch, the ray passes through it within the
    /// tolerance and `t` is in the interval. The point is evaluated on the
    /// patch's own net, and one more Newton step taken there to first
    /// order: the pieces' nets, made by repeated halving, are the patch
    /// only to rounding, which a grazing ray would magnify in `t`.
    fn root_at(
        &self,
        leaf: &Node,
        net: &ControlNet,
        [s, t]: [f64; 2],
        t_min: f64,
        t_max: f64,
    ) -> Option<Root> {
        let width = [leaf.high[0] - leaf.low[0], leaf.high[1] - leaf.low[1]];
        let (u, v) = (leaf.low[0] + s * width[0], leaf.low[1] + t * width[1]);
        let on_patch = |x: f64| (-EDGE..=1.0 + EDGE).contains(&x);
        if !on_patch(u) || !on_patch(v) {
            return None;
        }
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        let e = evaluate(net, u, v);
        let [n1, n2, forward] = self.axes;
        let q = e.point - self.origin;
        let (x, y, mut z) = (n1.dot(q), n2.dot(q), forward.dot(q));
        if DVec2::new(x, y).length() > self.tolerance {
            return None;
        }
        let (xu, yu, xv, yv) = (n1.dot(e.du), n2.dot(e.du), n1.dot(e.dv), n2.dot(e.dv));
        let det = xu * yv - yu * xv;
        if det != 0.0 && det.is_finite() {
            let next_u = (u - (x * yv - xv * y) / det).clamp(0.0, 1.0);
            let next_v = (v - (xu * y - x * yu) / det).clamp(0.0, 1.0);
            if (next_u - u).abs().max((next_v - v).abs()) <= POLISH_STEP {
                z += forward.dot(e.du) * (next_u - u) + forward.dot(e.dv) * (next_v - v);
            }
        }
        let distance = z * self.inverse_length;
        (distance > t_min && distance < t_max).then_some(Root { t: distance, u, v })
    }
}
