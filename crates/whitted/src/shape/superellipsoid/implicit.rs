//! The implicit function of the unit superellipsoid, written in the
//! magnitudes `a = |x|`, `b = |y|`, `c = |z|`:
//!
//! `f = s(a, b)^q + c^q - 1` with `s = (a^p + b^p)^(1/p)`, `p = 2/e`,
//! `q = 2/n`,
//!
//! which is POV-Ray's `(|x|^(2/e) + |y|^(2/e))^(e/n) + |z|^(2/n) - 1`
//! (`s^q = (a^p + b^p)^(e/n)`). `s` is computed as
//! `m (1 + (l/m)^p)^(1/p)` with `m = max(a, b)`, `l = min(a, b)`: it lies
//! between `m` and `2^(e/2) m`, so neither it nor its factors overflow or
//! underflow where `a^p` alone would (`0.5^2000` for `e = 0.001`). Only
//! `s^q` and `c^q` may overflow (to `+∞`, far outside, still the right
//! sign) or underflow (to 0, next to the `-1`).
//!
//! `f` is nondecreasing in each of `a`, `b`, `c`, which gives exact
//! bounds of `f` over a stretch of ray from the ranges of the
//! magnitudes ([`Exponents::value`] at the lowest and highest), and
//! bounds of its slope from the ranges of the partial derivatives
//! ([`Exponents::slope_range`]).

/// The exponents of one superellipsoid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Exponents {
    /// `2 / e`, the power within the xy plane.
    pub(super) p: f64,
    /// `2 / n`, the power between the xy plane and z.
    pub(super) q: f64,
}

/// A closed range of numbers, `lo ≤ hi` (either may be infinite; NaN
/// makes every test on the range fail, which the callers treat as "not
/// proven").
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Range {
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl Range {
    /// The range between `a` and `b`, in either order.
    pub(super) fn between(a: f64, b: f64) -> Self {
        if a <= b {
            Self { lo: a, hi: b }
        } else {
            Self { lo: b, hi: a }
        }
    }

    /// The image of the range under a monotone function `g` (increasing
    /// or decreasing).
    fn map(self, g: impl Fn(f64) -> f64) -> Self {
        Self::between(g(self.lo), g(self.hi))
    }

    /// The range times a constant. A zero constant gives exactly 0 (the
    /// term it scales does not change), even for an infinite range.
    fn scaled(self, k: f64) -> Self {
        if k == 0.0 {
            Self { lo: 0.0, hi: 0.0 }
        } else {
            Self::between(self.lo * k, self.hi * k)
        }
    }

    /// The sum of two ranges.
    fn plus(self, other: Self) -> Self {
        Self {
            lo: self.lo + other.lo,
            hi: self.hi + other.hi,
        }
    }

    /// The product of a range of non-negative numbers (`self`) and any
    /// range.
    fn times(self, other: Self) -> Self {
        let lo = if other.lo >= 0.0 { self.lo } else { self.hi } * other.lo;
        let hi = if other.hi >= 0.0 { self.hi } else { self.lo } * other.hi;
        Self { lo, hi }
    }

    /// True when every number of the range has the same strict sign.
    pub(super) fn excludes_zero(self) -> bool {
        self.lo > 0.0 || self.hi < 0.0
    }
}

/// The magnitudes `|x|`, `|y|`, `|z|` over a stretch of ray along which
/// no coordinate changes sign and `|x| - |y|` keeps its sign: each is an
/// affine function of `t` there, so its range is that of its values at
/// the ends.
#[derive(Clone, Copy, Debug)]
pub(super) struct Stretch {
    /// The larger of `|x|`, `|y|`.
    pub(super) m: Range,
    /// The smaller of `|x|`, `|y|`.
    pub(super) l: Range,
    /// `|z|`.
    pub(super) c: Range,
    /// `l / m`, a ratio of affine functions (monotone): its values at the
    /// ends, or [0, 1] when `m` is 0 at an end.
    pub(super) k: Range,
    /// The rates of change of `m`, `l`, `c` along the ray.
    pub(super) slopes: [f64; 3],
}

impl Exponents {
    /// The exponents for `e` and `n`.
    pub(super) fn new(e: f64, n: f64) -> Self {
        Self {
            p: 2.0 / e,
            q: 2.0 / n,
        }
    }

    /// `s(a, b) = (a^p + b^p)^(1/p)`, computed without overflow or
    /// underflow.
    pub(super) fn planar(&self, a: f64, b: f64) -> f64 {
        let (m, l) = if a >= b { (a, b) } else { (b, a) };
        if m == 0.0 {
            return 0.0;
        }
        m * (1.0 + (l / m).powf(self.p)).powf(1.0 / self.p)
    }

    /// `f` at magnitudes `a`, `b`, `c` (all ≥ 0): negative inside,
    /// positive outside.
    pub(super) fn value(&self, a: f64, b: f64, c: f64) -> f64 {
        self.planar(a, b).powf(self.q) + c.powf(self.q) - 1.0
    }

    /// The range of `f` over a stretch: `f` is nondecreasing in each
    /// magnitude.
    pub(super) fn value_range(&self, s: &Stretch) -> Range {
        Range {
            lo: self.value(s.m.lo, s.l.lo, s.c.lo),
            hi: self.value(s.m.hi, s.l.hi, s.c.hi),
        }
    }

    /// A range holding `df/dt` everywhere on a stretch (up to the positive
    /// factor `q`):
    ///
    /// `df/dt / q = s^(q-1) (∂s/∂m · m' + ∂s/∂l · l') + c^(q-1) c'`,
    ///
    /// with `∂s/∂m = (1 + k^p)^((1-p)/p)` and
    /// `∂s/∂l = (1 + k^(-p))^((1-p)/p)`, each monotone in `k = l/m`, and
    /// `s^(q-1)`, `c^(q-1)` monotone in `s` and `c`. Where a power is
    /// infinite (`k = 0` with `e > 2`, `c = 0` with `n > 2`) the range is
    /// infinite or NaN and proves nothing, as it should.
    pub(super) fn slope_range(&self, s: &Stretch) -> Range {
        let (p, q) = (self.p, self.q);
        let [dm, dl, dc] = s.slopes;
        let to_m = s.k.map(|k| (1.0 + k.powf(p)).powf((1.0 - p) / p));
        let to_l = s.k.map(|k| (1.0 + k.powf(-p)).powf((1.0 - p) / p));
        let inner = to_m.scaled(dm).plus(to_l.scaled(dl));
        let planar = Range {
            lo: self.planar(s.m.lo, s.l.lo),
            hi: self.planar(s.m.hi, s.l.hi),
        };
        let planar_term = planar.map(|v| v.powf(q - 1.0)).times(inner);
        let axial_term = s.c.map(|c| c.powf(q - 1.0)).scaled(dc);
        planar_term.plus(axial_term)
    }

    /// The gradient of `f` with respect to `(a, b, c)`, up to a positive
    /// factor, at a point of the surface; components may be infinite
    /// where the surface has a crease or a point (see the caller).
    pub(super) fn magnitude_gradient(&self, a: f64, b: f64, c: f64) -> [f64; 3] {
        let (p, q) = (self.p, self.q);
        let s = self.planar(a, b);
        let axial = c.powf(q - 1.0);
        if s == 0.0 {
            return [0.0, 0.0, axial];
        }
        let planar = s.powf(q - 1.0);
        [
            planar * (a / s).powf(p - 1.0),
            planar * (b / s).powf(p - 1.0),
            axial,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unit_sphere_and_the_octahedron_are_known_answers() {
        let sphere = Exponents::new(1.0, 1.0);
        assert!((sphere.value(0.6, 0.0, 0.8)).abs() < 1e-15);
        assert!((sphere.value(0.48, 0.36, 0.8)).abs() < 1e-15);
        let octahedron = Exponents::new(2.0, 2.0);
        assert!((octahedron.value(0.2, 0.3, 0.5)).abs() < 1e-15);
        assert!(octahedron.value(0.2, 0.3, 0.4) < 0.0);
    }

    #[test]
    fn tiny_exponents_neither_underflow_nor_overflow() {
        // e = 0.001: a^2000 alone underflows for a = 0.5, which would lose
        // the planar term; s stays 0.5 (to rounding).
        let cubic = Exponents::new(1e-3, 10.0);
        let s = cubic.planar(0.5, 0.49);
        assert!((s - 0.5).abs() < 1e-12, "{s}");
        let value = cubic.value(0.5, 0.49, 0.0);
        assert!((value - (0.5f64.powf(0.2) - 1.0)).abs() < 1e-12);
        let spiky = Exponents::new(10.0, 1e-3);
        assert_eq!(spiky.value(0.9, 0.9, 0.0), f64::INFINITY);
        assert!(!spiky.value(0.1, 0.1, 0.0).is_nan());
    }

    #[test]
    fn slope_ranges_hold_the_slope() {
        let exponents = Exponents::new(0.7, 2.5);
        // x = 0.3 + 0.1 t, y = 0.1 + 0.05 t, z = 0.5 - 0.2 t on t in [0, 1].
        let at = |t: f64| [0.3 + 0.1 * t, 0.1 + 0.05 * t, 0.5 - 0.2 * t];
        let [x0, y0, z0] = at(0.0);
        let [x1, y1, z1] = at(1.0);
        let stretch = Stretch {
            m: Range::between(x0, x1),
            l: Range::between(y0, y1),
            c: Range::between(z0, z1),
            k: Range::between(y0 / x0, y1 / x1),
            slopes: [0.1, 0.05, -0.2],
        };
        let range = exponents.slope_range(&stretch);
        let f = |t: f64| {
            let [x, y, z] = at(t);
            exponents.value(x, y, z)
        };
        for i in 0..=100 {
            let t = f64::from(i) / 100.0;
            let h = 1e-6;
            let slope = (f(t + h) - f(t - h)) / (2.0 * h) / exponents.q;
            assert!(
                range.lo - 1e-6 <= slope && slope <= range.hi + 1e-6,
                "{slope} {range:?}"
            );
        }
        let values = exponents.value_range(&stretch);
        assert!(values.lo <= f(0.5) && f(0.5) <= values.hi);
    }
}
