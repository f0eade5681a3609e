//! Roots of quadratics, computed without catastrophic cancellation.

/// The real roots of `a t² + 2 b t + c = 0`, smallest first, given the
/// reduced discriminant `disc = b² - a c` computed by the caller (callers have
/// better-conditioned ways to get it). `None` when there is no real root or
/// `a` is zero.
///
/// Uses `q = -(b + sign(b) √disc)`, `t0 = q / a`, `t1 = c / q` (Numerical
/// Recipes 5.6), so the root near zero keeps full precision.
pub(crate) fn solve(a: f64, b: f64, c: f64, disc: f64) -> Option<(f64, f64)> {
    if disc.is_nan() || disc < 0.0 || a == 0.0 {
        return None;
    }
    let q = -(b + disc.sqrt().copysign(b));
    let (t0, t1) = if q == 0.0 {
        // b = 0 and disc = 0: a double root at c / a = 0 or the ray grazes.
        (0.0, 0.0)
    } else {
        (q / a, c / q)
    };
    if t0 <= t1 {
        Some((t0, t1))
    } else {
        Some((t1, t0))
    }
}

/// The nearest of two sorted roots inside `(t_min, t_max)`.
pub(crate) fn nearest_in(roots: (f64, f64), t_min: f64, t_max: f64) -> Option<f64> {
    [roots.0, roots.1]
        .into_iter()
        .find(|&t| t > t_min && t < t_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_small_root_precise() {
        // t² - 2e8 t + 1 = 0: roots near 2e8 and 5e-9.
        let (a, b, c) = (1.0, -1e8, 1.0);
        let (t0, t1) = solve(a, b, c, b * b - a * c).unwrap();
        assert!((t0 - 5e-9).abs() / 5e-9 < 1e-12);
        assert!((t1 - 2e8).abs() / 2e8 < 1e-12);
    }

    #[test]
    fn no_real_roots_or_zero_leading_term_is_none() {
        assert_eq!(solve(1.0, 0.0, 1.0, -1.0), None);
        assert_eq!(solve(0.0, 1.0, 1.0, 1.0), None);
        assert_eq!(solve(1.0, 0.0, 0.0, f64::NAN), None);
    }

    #[test]
    fn nearest_in_skips_roots_outside_the_interval() {
        assert_eq!(nearest_in((-1.0, 2.0), 0.0, 10.0), Some(2.0));
        assert_eq!(nearest_in((-1.0, 2.0), 0.0, 1.0), None);
        assert_eq!(nearest_in((0.5, 2.0), 0.0, 10.0), Some(0.5));
    }
}
