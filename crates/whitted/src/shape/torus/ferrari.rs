//! Ferrari's closed form for the real roots of a quartic, each polished by
//! Newton steps and then checked; the torus's solver. When the check
//! fails, the recursive derivative intervals ([`super::monotone`]) solve
//! the quartic instead.
//!
//! The quartic is made monic and depressed (`x = y − a/4` leaves
//! `y⁴ + p y² + q y + r`), the largest root `m` of the resolvent cubic
//! `m³ + p m² + (p²/4 − r) m − q²/8` is found by Cardano's formula (the
//! trigonometric form when it has three real roots), and with `s = √(2m)`
//! the quartic splits into `y² ∓ s y + p/2 + m ± q/(2s)`, two quadratics
//! solved in closed form. `q = 0` (so `m = 0`) is the biquadratic case.
//!
//! **The check.** The closed form is fast but offers no guarantee: the
//! resolvent's rounding can shift a root, or (near a double root) drop a
//! pair. The roots are trusted only when each is finite, moved less than
//! [`MAX_POLISH_MOVE`] by polishing, leaves a residual within
//! [`RESIDUAL`] of the size of the quartic's terms there, and the number
//! of roots inside the interval has the parity the quartic's signs at the
//! interval's ends demand (opposite signs: odd; equal: even). A dropped
//! simple root changes the parity; a root moved onto its neighbour moves
//! far. Anything else goes to the monotone solver, which cannot miss a root
//! of odd multiplicity.
//!
//! Coefficients are stored lowest degree first: `c[i]` multiplies `xⁱ`.

use super::QuarticSolver;
use super::monotone::Monotone;

/// Newton steps on the original quartic after the closed form.
const POLISH_STEPS: usize = 2;

/// The most polishing may move a root (in the quartic's unit, the bounding
/// sphere's radius) for the closed form to be trusted: the closed form's
/// own error measured on the torus's rays is below 1e-6.
const MAX_POLISH_MOVE: f64 = 1e-4;

/// The largest residual of a trusted root, relative to the sum of the
/// absolute values of the quartic's terms at it (rounding makes some 1e-16).
const RESIDUAL: f64 = 1e-12;

/// Ferrari's method with [`POLISH_STEPS`] Newton steps per root, checked,
/// with [`Monotone`] as the fallback.
pub(super) struct Ferrari;

impl QuarticSolver for Ferrari {
    fn first_root(
        c: &[f64; 5],
        lo: f64,
        hi: f64,
        mut accept: impl FnMut(f64) -> bool,
    ) -> Option<f64> {
        let Some((mut roots, count)) = checked(c, lo, hi, real_roots(c)) else {
            return Monotone::first_root(c, lo, hi, accept);
        };
        let roots = &mut roots[..count];
        roots.sort_unstable_by(f64::total_cmp);
        roots
            .iter()
            .copied()
            .find(|&x| x > lo && x < hi && accept(x))
    }
}

/// The roots `found` of the quartic `c` (unsorted, as an array and a
/// count) polished, or `None` when they fail the check (see the module's
/// documentation) on `(lo, hi)`.
fn checked(c: &[f64; 5], lo: f64, hi: f64, found: ([f64; 4], usize)) -> Option<([f64; 4], usize)> {
    let (mut roots, count) = found;
    let mut inside = 0;
    for x in &mut roots[..count] {
        let polished = polish(c, *x);
        if !((polished - *x).abs() <= MAX_POLISH_MOVE && residual_is_small(c, polished)) {
            return None;
        }
        *x = polished;
        inside += usize::from(*x > lo && *x < hi);
    }
    let (at_lo, at_hi) = (value(c, lo), value(c, hi));
    if at_lo == 0.0 || at_hi == 0.0 || at_lo.is_nan() || at_hi.is_nan() {
        return None;
    }
    let crossings_odd = (at_lo < 0.0) != (at_hi < 0.0);
    (crossings_odd == (inside % 2 == 1)).then_some((roots, count))
}

/// True when the quartic `c` at `x` is within [`RESIDUAL`] of the size of
/// its terms there.
fn residual_is_small(c: &[f64; 5], x: f64) -> bool {
    let size = c
        .iter()
        .rev()
        .fold(0.0, |acc, &coefficient| acc * x.abs() + coefficient.abs());
    value(c, x).abs() <= RESIDUAL * size
}

/// The value of the quartic `c` at `x` (Horner).
fn value(c: &[f64; 5], x: f64) -> f64 {
    c.iter()
        .rev()
        .fold(0.0, |acc, &coefficient| acc * x + coefficient)
}

/// The real roots of the quartic `c` (`c[4] ≠ 0`), unsorted, as an array
/// and a count.
fn real_roots(c: &[f64; 5]) -> ([f64; 4], usize) {
    let (a, b, cc, d) = (c[3] / c[4], c[2] / c[4], c[1] / c[4], c[0] / c[4]);
    let shift = -0.25 * a;
    let a2 = a * a;
    let p = b - 0.375 * a2;
    let q = cc - 0.5 * a * b + 0.125 * a2 * a;
    let r = d - 0.25 * a * cc + 0.0625 * a2 * b - 3.0 / 256.0 * a2 * a2;
    let mut roots = [0.0; 4];
    let mut count = 0;
    let mut push = |(found, n): ([f64; 2], usize)| {
        for y in &found[..n] {
            roots[count] = y + shift;
            count += 1;
        }
    };
    let m = if q == 0.0 {
        0.0
    } else {
        largest_cubic_root(p, 0.25 * p * p - r, -0.125 * q * q)
    };
    if m > 0.0 {
        let s = (2.0 * m).sqrt();
        let (half, skew) = (0.5 * p + m, q / (2.0 * s));
        push(monic_quadratic(-s, half + skew));
        push(monic_quadratic(s, half - skew));
    } else {
        // Biquadratic: y² is a root of z² + p z + r.
        let (z, n) = monic_quadratic(p, r);
        for &z in &z[..n] {
            if z >= 0.0 {
                let y = z.sqrt();
                push(([-y, y], 2));
            }
        }
    }
    (roots, count)
}

/// The real roots of `x² + b x + c` (closed form, without cancellation).
fn monic_quadratic(b: f64, c: f64) -> ([f64; 2], usize) {
    let disc = b * b - 4.0 * c;
    if disc.is_nan() || disc < 0.0 {
        return ([0.0; 2], 0);
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    if q == 0.0 {
        return ([0.0; 2], 1);
    }
    ([q, c / q], 2)
}

/// The largest real root of `x³ + a x² + b x + c` (Cardano).
fn largest_cubic_root(a: f64, b: f64, c: f64) -> f64 {
    // x = z − a/3: z³ + P z + Q.
    let p = b - a * a / 3.0;
    let q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
    let disc = 0.25 * q * q + p * p * p / 27.0;
    let z = if p == 0.0 {
        (-q).cbrt()
    } else if disc > 0.0 {
        let w = (-0.5 * q - disc.sqrt().copysign(q)).cbrt();
        w - p / (3.0 * w)
    } else {
        let third = (-p / 3.0).sqrt();
        let cos = (-0.5 * q / (third * third * third)).clamp(-1.0, 1.0);
        2.0 * third * (cos.acos() / 3.0).cos()
    };
    z - a / 3.0
}

/// `x` after [`POLISH_STEPS`] Newton steps on the quartic `c`, each taken
/// only when it gives a finite point.
fn polish(c: &[f64; 5], mut x: f64) -> f64 {
    for _ in 0..POLISH_STEPS {
        let mut value = c[4];
        let mut slope = 0.0;
        for &coefficient in c[..4].iter().rev() {
            slope = slope * x + value;
            value = value * x + coefficient;
        }
        let next = x - value / slope;
        if !next.is_finite() {
            break;
        }
        x = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted_roots(c: &[f64; 5]) -> Vec<f64> {
        let mut roots = Vec::new();
        Ferrari::first_root(c, -10.0, 10.0, |x| {
            roots.push(x);
            false
        });
        roots
    }

    #[test]
    fn four_separate_roots_are_found_in_order() {
        // (x + 0.7)(x + 0.2)(x − 0.3)(x − 0.9)
        let c = [0.0378, 0.075, -0.67, -0.3, 1.0];
        let roots = sorted_roots(&c);
        assert_eq!(roots.len(), 4, "{roots:?}");
        for (x, want) in roots.iter().zip([-0.7, -0.2, 0.3, 0.9]) {
            assert!((x - want).abs() < 1e-14, "{x} != {want}");
        }
    }

    #[test]
    fn a_biquadratic_and_a_rootless_quartic() {
        // (x² − 1)(x² − 4) and (x² + 1)(x² + 0.01).
        assert_eq!(
            sorted_roots(&[4.0, 0.0, -5.0, 0.0, 1.0]),
            [-2.0, -1.0, 1.0, 2.0]
        );
        assert!(sorted_roots(&[0.01, 0.0, 1.01, 0.0, 1.0]).is_empty());
    }

    #[test]
    fn a_dropped_or_misplaced_root_fails_the_check() {
        // (x + 0.7)(x + 0.2)(x − 0.3)(x − 0.9)
        let c = [0.0378, 0.075, -0.67, -0.3, 1.0];
        let all = ([-0.7, -0.2, 0.3, 0.9], 4);
        let (polished, count) = checked(&c, -1.0, 1.0, all).expect("the true roots pass");
        assert_eq!(count, 4);
        assert!((polished[2] - 0.3).abs() < 1e-15);
        // One root left out: three inside, but the ends have equal signs.
        assert_eq!(checked(&c, -1.0, 1.0, ([-0.7, -0.2, 0.9, 0.0], 3)), None);
        // A root 0.05 off: Newton's steps move it too far.
        assert_eq!(checked(&c, -1.0, 1.0, ([-0.7, -0.2, 0.35, 0.9], 4)), None);
        // A NaN, and an end of the interval on a root.
        assert_eq!(
            checked(&c, -1.0, 1.0, ([-0.7, f64::NAN, 0.3, 0.9], 4)),
            None
        );
        assert_eq!(checked(&c, -1.0, 0.3, all), None);
        // The interval holds two of the roots: the parity is still right.
        assert!(checked(&c, -0.5, 0.5, all).is_some());
    }

    #[test]
    fn when_the_check_fails_the_monotone_solver_answers() {
        // A double root at 0.5 (a tangent ray) between two simple ones:
        // whatever path is taken, the roots come in order, the touching
        // one at most once.
        let c = [-0.0675, 0.12, 0.58, -1.6, 1.0]; // (x − 0.5)²(x + 0.3)(x − 0.9)
        let roots = sorted_roots(&c);
        assert!(roots.windows(2).all(|pair| pair[0] <= pair[1]), "{roots:?}");
        assert!((roots[0] + 0.3).abs() < 1e-14, "{roots:?}");
        assert!((roots[roots.len() - 1] - 0.9).abs() < 1e-14, "{roots:?}");
        assert!(
            roots[1..roots.len() - 1]
                .iter()
                .all(|x| (x - 0.5).abs() < 1e-7),
            "{roots:?}"
        );
    }

    #[test]
    fn the_resolvent_cubic_root_is_the_largest() {
        // (x − 1)(x − 2)(x − 3) and x³ − 8 (one real root).
        assert!((largest_cubic_root(-6.0, 11.0, -6.0) - 3.0).abs() < 1e-14);
        assert!((largest_cubic_root(0.0, 0.0, -8.0) - 2.0).abs() < 1e-15);
    }
}
