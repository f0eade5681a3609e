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

use super::bernstein::{ControlNet, evaluate};
use super::hierarchy::Node;
use crate::math::{DVec2, Ray, Vec3, magnitude};

/// Iterations before Newton's method gives up on a leaf.
const MAX_ITERATIONS: u32 = 16;

/// The step in (u, v) below which the iteration has converged.
const CONVERGED_STEP: f64 = 1e-14;

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

/// The patch in the ray's frame.
pub(super) struct RayFrame {
    net: ControlNet,
    /// `1 / |d|`, to turn the distance along the ray into `t`.
    inverse_length: f64,
    /// The residual below which a root is accepted.
    tolerance: f64,
}

/// A root: the ray parameter and the patch parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Root {
    pub(super) t: f64,
    pub(super) u: f64,
    pub(super) v: f64,
}

impl RayFrame {
    /// `net` as seen from `ray`, or `None` for a ray whose direction has no
    /// usable length.
    pub(super) fn new(net: &ControlNet, ray: &Ray) -> Option<Self> {
        let length = magnitude::norm(ray.dir);
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let forward = ray.dir / length;
        let (n1, n2) = forward.any_orthonormal_pair();
        let mut scale: f64 = 0.0;
        let projected = net.map(|row| {
            row.map(|p| {
                let q = p - ray.origin;
                let local = Vec3::new(n1.dot(q), n2.dot(q), forward.dot(q));
                scale = scale.max(local.abs().max_element());
                local
            })
        });
        Some(Self {
            net: projected,
            inverse_length: 1.0 / length,
            tolerance: ACCEPTED_RESIDUAL * scale,
        })
    }

    /// The root Newton's method finds from the centre of `leaf` with `t` in
    /// `(ray.t_min, t_max)`, if any. The iteration may wander one leaf width
    /// beyond the leaf's range; a root anywhere on the patch is accepted (it
    /// is a true intersection, whichever leaf it lies in).
    pub(super) fn solve(&self, leaf: &Node, t_min: f64, t_max: f64) -> Option<Root> {
        let width = [leaf.high[0] - leaf.low[0], leaf.high[1] - leaf.low[1]];
        let low = [leaf.low[0] - width[0], leaf.low[1] - width[1]];
        let high = [leaf.high[0] + width[0], leaf.high[1] + width[1]];
        let inside =
            |u: f64, v: f64| (low[0]..=high[0]).contains(&u) && (low[1]..=high[1]).contains(&v);
        let mut u = 0.5 * (leaf.low[0] + leaf.high[0]);
        let mut v = 0.5 * (leaf.low[1] + leaf.high[1]);
        let mut e = evaluate(&self.net, u, v);
        'iterations: for _ in 0..MAX_ITERATIONS {
            let residual = e.point.truncate().length();
            let det = e.du.x * e.dv.y - e.du.y * e.dv.x;
            if residual == 0.0 || det == 0.0 || !det.is_finite() {
                break;
            }
            let (rx, ry) = (e.point.x, e.point.y);
            let step_u = (rx * e.dv.y - e.dv.x * ry) / det;
            let step_v = (e.du.x * ry - rx * e.du.y) / det;
            if step_u.abs().max(step_v.abs()) <= CONVERGED_STEP {
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
                    let next = evaluate(&self.net, next_u, next_v);
                    if next.point.truncate().length() < residual {
                        (u, v, e) = (next_u, next_v, next);
                        continue 'iterations;
                    }
                }
                fraction *= 0.5;
            }
            break;
        }
        self.root_at(u, v, t_min, t_max)
    }

    /// (u, v) as a root, when the ray passes through P(u, v) within the
    /// tolerance, (u, v) lies on the patch and `t` in the interval.
    fn root_at(&self, u: f64, v: f64, t_min: f64, t_max: f64) -> Option<Root> {
        let on_patch = |x: f64| (-EDGE..=1.0 + EDGE).contains(&x);
        if !on_patch(u) || !on_patch(v) {
            return None;
        }
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        let e = evaluate(&self.net, u, v);
        let residual = DVec2::new(e.point.x, e.point.y).length();
        let t = e.point.z * self.inverse_length;
        (residual <= self.tolerance && t > t_min && t < t_max).then_some(Root { t, u, v })
    }
}
