//! An independent numeric reference for the quadric's intersection: the
//! polynomial sampled densely along the ray inside the clipping box, sign
//! changes and dips towards zero refined by bisection and golden-section
//! search, in f64. It knows nothing of the quadratic along the ray.

use crate::math::{Aabb, Ray, Vec3};

/// The polynomial `A x² + … + J` written out from the coefficients.
pub(super) fn value(k: &[f64; 10], p: Vec3) -> f64 {
    let (x, y, z) = (p.x, p.y, p.z);
    k[0] * x * x
        + k[1] * y * y
        + k[2] * z * z
        + k[3] * x * y
        + k[4] * x * z
        + k[5] * y * z
        + k[6] * x
        + k[7] * y
        + k[8] * z
        + k[9]
}

/// The first zero of `f(ray.at(t))` in the part of the ray's interval
/// inside `clip` (and within `t_far` when the interval is unbounded),
/// found from `samples` samples.
pub(super) fn first_root(
    k: &[f64; 10],
    ray: &Ray,
    clip: Aabb,
    t_far: f64,
    samples: usize,
) -> Option<f64> {
    let (lo, hi) = slab(ray, clip)?;
    let hi = hi.min(t_far);
    if lo >= hi {
        return None;
    }
    let f = |t: f64| value(k, ray.at(t));
    let ts: Vec<f64> = (0..=samples)
        .map(|i| lo + (hi - lo) * i as f64 / samples as f64)
        .collect();
    let fs: Vec<f64> = ts.iter().map(|&t| f(t)).collect();
    for i in 0..samples {
        if fs[i] == 0.0 && i > 0 {
            return Some(ts[i]);
        }
        if fs[i] * fs[i + 1] < 0.0 {
            return Some(bisect(&f, ts[i], ts[i + 1]));
        }
        // A dip towards zero at sample i + 1 that may cross it between
        // samples i and i + 2 and come back.
        if i + 2 <= samples
            && (fs[i + 1] - fs[i]) * (fs[i + 2] - fs[i + 1]) <= 0.0
            && fs[i + 1] * fs[i + 2] > 0.0
        {
            let sign = fs[i + 1].signum();
            let extreme = golden(&|t| sign * f(t), ts[i], ts[i + 2]);
            if sign * f(extreme) < 0.0 {
                return Some(bisect(&f, ts[i], extreme));
            }
        }
    }
    None
}

/// The parameter interval of the ray inside the box, within its own
/// interval, by the slab method without padding.
fn slab(ray: &Ray, clip: Aabb) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (ray.t_min, ray.t_max);
    for axis in 0..3 {
        let (o, d) = (ray.origin[axis], ray.dir[axis]);
        if d == 0.0 {
            if o < clip.min[axis] || o > clip.max[axis] {
                return None;
            }
            continue;
        }
        let a = (clip.min[axis] - o) / d;
        let b = (clip.max[axis] - o) / d;
        lo = lo.max(a.min(b));
        hi = hi.min(a.max(b));
    }
    (lo <= hi).then_some((lo, hi))
}

/// A zero of `f` between `a` and `b`, where `f` changes sign.
fn bisect(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let fa = f(a);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if f(m) * fa > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Where `f` is smallest between `a` and `b` (one dip), by golden-section
/// search.
fn golden(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let c = b - r * (b - a);
        let d = a + r * (b - a);
        if f(c) < f(d) {
            b = d;
        } else {
            a = c;
        }
        if b - a <= 1e-15 * a.abs().max(b.abs()) {
            break;
        }
    }
    0.5 * (a + b)
}
