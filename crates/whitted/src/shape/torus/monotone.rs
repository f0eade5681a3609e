//! Real roots of low-degree polynomials on an interval, by recursive
//! derivative intervals (Cem Yuksel, "High-Performance Polynomial Root
//! Finding for Graphics", HPG 2022).
//!
//! The roots of a polynomial's derivative cut the interval into pieces on
//! which the polynomial is monotone; each piece whose ends differ in sign
//! holds exactly one root, found by Newton's method kept inside the
//! bracket (bisection when a step would leave it). The derivative's roots
//! are found the same way, one degree down, ending at a quadratic solved in
//! closed form. No step can miss a root of odd multiplicity or return one
//! outside the interval, and no division by a vanishing derivative escapes
//! the bracket, so nothing is NaN.
//!
//! Coefficients are stored lowest degree first: `c[i]` multiplies `xⁱ`.

/// At most this many Newton or bisection steps for one root; Newton inside
/// a bracket converges in far fewer, bisection halves 1e-16 of a unit
/// interval in 53.
const MAX_STEPS: usize = 80;

/// The value and the derivative of the polynomial `c` at `x` (Horner).
fn value_and_slope<const N: usize>(c: &[f64; N], x: f64) -> (f64, f64) {
    let mut value = c[N - 1];
    let mut slope = 0.0;
    for &coefficient in c[..N - 1].iter().rev() {
        slope = slope * x + value;
        value = value * x + coefficient;
    }
    (value, slope)
}

/// The value of the polynomial `c` at `x`.
fn value<const N: usize>(c: &[f64; N], x: f64) -> f64 {
    c.iter()
        .rev()
        .fold(0.0, |acc, &coefficient| acc * x + coefficient)
}

/// The one root of `c` in `(a, b)`, where `c` is monotone and `fa = c(a)`
/// and `c(b)` have opposite signs.
fn bracketed_root<const N: usize>(c: &[f64; N], mut a: f64, mut b: f64, fa: f64) -> f64 {
    let rising = fa < 0.0;
    let mut x = 0.5 * (a + b);
    for _ in 0..MAX_STEPS {
        let (fx, slope) = value_and_slope(c, x);
        if fx == 0.0 {
            return x;
        }
        if (fx < 0.0) == rising {
            a = x;
        } else {
            b = x;
        }
        let newton = x - fx / slope;
        let next = if newton > a && newton < b {
            newton
        } else {
            0.5 * (a + b)
        };
        if (next - x).abs() <= 4.0 * f64::EPSILON * x.abs().max(b - a).max(f64::MIN_POSITIVE)
            || next == a
            || next == b
        {
            return next;
        }
        x = next;
    }
    x
}

/// Calls `found` with each root of `c` in `(lo, hi)` in increasing order,
/// given the points `cuts` (sorted, inside the interval) that split it into
/// pieces where `c` is monotone; stops and returns the first root `found`
/// accepts. A root at a cut (a double root: the ray touches the surface)
/// counts once.
fn roots_between_cuts<const N: usize>(
    c: &[f64; N],
    lo: f64,
    hi: f64,
    cuts: &[f64],
    mut found: impl FnMut(f64) -> bool,
) -> Option<f64> {
    let mut a = lo;
    let mut fa = value(c, lo);
    for b in cuts.iter().copied().chain(std::iter::once(hi)) {
        let fb = value(c, b);
        let root = if fa * fb < 0.0 {
            Some(bracketed_root(c, a, b, fa))
        } else if fb == 0.0 && b < hi && fa != 0.0 {
            Some(b)
        } else {
            None
        };
        if let Some(root) = root
            && found(root)
        {
            return Some(root);
        }
        (a, fa) = (b, fb);
    }
    None
}

/// The roots of the quadratic `c` in `(lo, hi)`, in increasing order, as
/// an array and a count (closed form, without cancellation).
fn quadratic_roots(c: &[f64; 3], lo: f64, hi: f64) -> ([f64; 2], usize) {
    let [c0, c1, c2] = *c;
    let mut roots = [0.0; 2];
    let mut count = 0;
    let mut keep = |x: f64| {
        if x > lo && x < hi {
            roots[count] = x;
            count += 1;
        }
    };
    if c2 == 0.0 {
        if c1 != 0.0 {
            keep(-c0 / c1);
        }
        return (roots, count);
    }
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc < 0.0 || !disc.is_finite() {
        return (roots, count);
    }
    let q = -0.5 * (c1 + disc.sqrt().copysign(c1));
    if q == 0.0 {
        keep(0.0);
        return (roots, count);
    }
    let (x0, x1) = (q / c2, c0 / q);
    keep(x0.min(x1));
    if x1 != x0 {
        keep(x0.max(x1));
    }
    (roots, count)
}

/// The roots of the cubic `c` in `(lo, hi)`, in increasing order, as an
/// array and a count.
fn cubic_roots(c: &[f64; 4], lo: f64, hi: f64) -> ([f64; 3], usize) {
    let slope = [c[1], 2.0 * c[2], 3.0 * c[3]];
    let (cuts, cut_count) = quadratic_roots(&slope, lo, hi);
    let mut roots = [0.0; 3];
    let mut count = 0;
    roots_between_cuts(c, lo, hi, &cuts[..cut_count], |x| {
        roots[count] = x;
        count += 1;
        false
    });
    (roots, count)
}

/// The torus's solver: [`first_quartic_root`].
pub(super) struct Monotone;

impl super::QuarticSolver for Monotone {
    fn first_root(c: &[f64; 5], lo: f64, hi: f64, accept: impl FnMut(f64) -> bool) -> Option<f64> {
        first_quartic_root(c, lo, hi, accept)
    }
}

/// The first root of the quartic `c` in `(lo, hi)` that `accept` takes,
/// trying the roots in increasing order.
pub(super) fn first_quartic_root(
    c: &[f64; 5],
    lo: f64,
    hi: f64,
    accept: impl FnMut(f64) -> bool,
) -> Option<f64> {
    let slope = [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4]];
    let (cuts, cut_count) = cubic_roots(&slope, lo, hi);
    roots_between_cuts(c, lo, hi, &cuts[..cut_count], accept)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The monic quartic with the given roots.
    fn with_roots(r: [f64; 4]) -> [f64; 5] {
        let mut c = [1.0, 0.0, 0.0, 0.0, 0.0];
        for (degree, root) in r.into_iter().enumerate() {
            for i in (0..=degree + 1).rev() {
                let lower = if i > 0 { c[i - 1] } else { 0.0 };
                c[i] = lower - root * if i <= degree { c[i] } else { 0.0 };
            }
        }
        c
    }

    fn all_roots(c: &[f64; 5], lo: f64, hi: f64) -> Vec<f64> {
        let mut roots = Vec::new();
        first_quartic_root(c, lo, hi, |x| {
            roots.push(x);
            false
        });
        roots
    }

    #[test]
    fn four_separate_roots_are_found_in_order() {
        let c = with_roots([-0.7, -0.2, 0.3, 0.9]);
        let roots = all_roots(&c, -1.0, 1.0);
        assert_eq!(roots.len(), 4, "{roots:?}");
        for (x, want) in roots.iter().zip([-0.7, -0.2, 0.3, 0.9]) {
            assert!((x - want).abs() < 1e-15, "{x} != {want}");
        }
    }

    #[test]
    fn only_roots_inside_the_open_interval_are_reported() {
        let c = with_roots([-0.7, -0.2, 0.3, 0.9]);
        let roots = all_roots(&c, -0.2, 0.5);
        assert_eq!(roots.len(), 1, "{roots:?}");
        assert!((roots[0] - 0.3).abs() < 1e-15);
    }

    #[test]
    fn a_double_root_is_reported_at_most_once_and_close_roots_are_told_apart() {
        let c = with_roots([0.25, 0.25, 0.5, 0.5 + 1e-7]);
        let roots = all_roots(&c, -1.0, 1.0);
        let [.., a, b] = roots[..] else {
            panic!("{roots:?}")
        };
        assert!(roots.len() == 2 || (roots.len() == 3 && (roots[0] - 0.25).abs() < 1e-7));
        // Two roots 1e-7 apart beside a double root: conditioned to about 1e-9.
        assert!(
            (a - 0.5).abs() < 1e-8 && (b - 0.5 - 1e-7).abs() < 1e-8,
            "{roots:?}"
        );
    }

    #[test]
    fn a_quartic_without_real_roots_has_none() {
        // (x² + 1)(x² + 0.01)
        assert!(all_roots(&[0.01, 0.0, 1.01, 0.0, 1.0], -10.0, 10.0).is_empty());
    }

    #[test]
    fn accept_skips_roots_until_it_agrees() {
        let c = with_roots([-0.7, -0.2, 0.3, 0.9]);
        let third = first_quartic_root(&c, -1.0, 1.0, |x| x > 0.0);
        assert!((third.unwrap() - 0.3).abs() < 1e-15);
    }
}
