//! The polynomial of a quadric: its value, its gradient, its restriction to
//! a line, and whether its zero set is bounded.

use crate::math::{Aabb, DMat3, Vec3, gamma, magnitude};

/// `A x² + B y² + C z² + D xy + E xz + F yz + G x + H y + I z + J`, as
/// `pᵀ M p + g·p + J` with the symmetric `M` (`A`, `B`, `C` on the
/// diagonal, `D/2`, `E/2`, `F/2` off it) and `g = (G, H, I)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Form {
    /// The coefficients `A` … `J` as given.
    pub(super) coefficients: [f64; 10],
}

/// The coefficients of `f(o + s d) = a s² + 2 b s + c`.
pub(super) struct AlongLine {
    /// The quadratic coefficient `q(d) = dᵀ M d`.
    pub(super) a: f64,
    /// Half the linear coefficient: `oᵀ M d + g·d / 2`.
    pub(super) b: f64,
    /// The value at the origin, `f(o)`.
    pub(super) c: f64,
}

impl Form {
    /// The symmetric matrix of the quadratic part.
    pub(super) fn matrix(&self) -> DMat3 {
        let [a, b, c, d, e, f, ..] = self.coefficients;
        DMat3::from_cols(
            Vec3::new(a, d / 2.0, e / 2.0),
            Vec3::new(d / 2.0, b, f / 2.0),
            Vec3::new(e / 2.0, f / 2.0, c),
        )
    }

    /// The linear part `g = (G, H, I)`.
    fn linear(&self) -> Vec3 {
        let [.., g, h, i, _] = self.coefficients;
        Vec3::new(g, h, i)
    }

    /// `pᵀ M q`, written out.
    fn bilinear(&self, p: Vec3, q: Vec3) -> f64 {
        let [a, b, c, d, e, f, ..] = self.coefficients;
        a * p.x * q.x
            + b * p.y * q.y
            + c * p.z * q.z
            + 0.5
                * (d * (p.x * q.y + p.y * q.x)
                    + e * (p.x * q.z + p.z * q.x)
                    + f * (p.y * q.z + p.z * q.y))
    }

    /// The polynomial at `p`.
    pub(super) fn value(&self, p: Vec3) -> f64 {
        self.bilinear(p, p) + self.linear().dot(p) + self.coefficients[9]
    }

    /// A bound on the rounding error of [`Form::value`] at `p`: `γ(16)`
    /// times the sum of its terms' magnitudes (a term takes at most three
    /// products and the sums up to ten more roundings; sixteen covers
    /// both, with room for the rounding of `p` itself).
    pub(super) fn value_error(&self, p: Vec3) -> f64 {
        let k = self.coefficients.map(f64::abs);
        let a = p.abs();
        let terms = k[0] * a.x * a.x
            + k[1] * a.y * a.y
            + k[2] * a.z * a.z
            + k[3] * a.x * a.y
            + k[4] * a.x * a.z
            + k[5] * a.y * a.z
            + k[6] * a.x
            + k[7] * a.y
            + k[8] * a.z
            + k[9];
        gamma(16) * terms
    }

    /// The gradient at `p`: `2 M p + g`.
    pub(super) fn gradient(&self, p: Vec3) -> Vec3 {
        let [a, b, c, d, e, f, g, h, i, _] = self.coefficients;
        Vec3::new(
            2.0 * a * p.x + d * p.y + e * p.z + g,
            2.0 * b * p.y + d * p.x + f * p.z + h,
            2.0 * c * p.z + e * p.x + f * p.y + i,
        )
    }

    /// The polynomial along the line `o + s d`.
    pub(super) fn along(&self, o: Vec3, d: Vec3) -> AlongLine {
        AlongLine {
            a: self.bilinear(d, d),
            b: self.bilinear(o, d) + 0.5 * self.linear().dot(d),
            c: self.value(o),
        }
    }

    /// The sign of the quadratic part when it is definite: `1` when `M` is
    /// positive definite, `-1` when negative definite, `0` otherwise, by
    /// Sylvester's criterion on the leading principal minors of `±M`.
    fn definiteness(&self) -> f64 {
        let m = self.matrix();
        for sign in [1.0, -1.0] {
            let s = sign * m;
            let first = s.x_axis.x;
            let second = s.x_axis.x * s.y_axis.y - s.x_axis.y * s.y_axis.x;
            if first > 0.0 && second > 0.0 && s.determinant() > 0.0 {
                return sign;
            }
        }
        0.0
    }

    /// What the zero set is, as far as bounds go.
    pub(super) fn extent(&self) -> Extent {
        let sign = self.definiteness();
        if sign == 0.0 {
            return Extent::Unbounded;
        }
        // f(p) = (p - c)ᵀ M (p - c) + k with c = -M⁻¹ g / 2 and
        // k = J + g·c / 2; the surface is (p - c)ᵀ M (p - c) = -k, whose
        // half-width along axis i is √(-k (M⁻¹)ᵢᵢ).
        let inverse = self.matrix().inverse();
        let center = -0.5 * (inverse * self.linear());
        let k = self.coefficients[9] + 0.5 * self.linear().dot(center);
        if sign * k >= 0.0 {
            return Extent::Empty;
        }
        let diagonal = Vec3::new(inverse.x_axis.x, inverse.y_axis.y, inverse.z_axis.z);
        let half = (-k * diagonal).max(Vec3::ZERO).sqrt();
        // Rounding in M⁻¹ grows with its condition: 1e-6 of the half-widths
        // covers ellipsoids up to about 1e9 times longer than wide.
        let margin = 1e-6 * half + 1e-15 * center.abs();
        let (min, max) = (center - half - margin, center + half + margin);
        match (magnitude::point(min), magnitude::point(max)) {
            (Ok(min), Ok(max)) if min.is_finite() && max.is_finite() => {
                Extent::Ellipsoid(Aabb::new(min, max))
            }
            _ => Extent::Unbounded,
        }
    }
}

/// The kind of zero set, as far as bounds go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Extent {
    /// An ellipsoid (the quadratic part is definite), inside this box.
    Ellipsoid(Aabb),
    /// Definite, but no real point or a single one: nothing to see.
    Empty,
    /// Anything else (or an ellipsoid too large to bound).
    Unbounded,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn form(coefficients: [f64; 10]) -> Form {
        Form { coefficients }
    }

    #[test]
    fn value_and_gradient_follow_the_coefficients() {
        let f = form([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0]);
        let p = Vec3::new(1.0, -2.0, 0.5);
        // A x², B y², C z², D xy, E xz, F yz, G x, H y, I z, J.
        let terms = [1.0, 8.0, 0.75, -8.0, 2.5, -6.0, 7.0, -16.0, 4.5, 10.0];
        let expected: f64 = terms.iter().sum();
        assert_eq!(f.value(p), expected);
        let h = 1e-6;
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let numeric = (f.value(p + h * axis) - f.value(p - h * axis)) / (2.0 * h);
            assert!((numeric - f.gradient(p).dot(axis)).abs() < 1e-6);
        }
        let o = Vec3::new(0.3, 0.1, -2.0);
        let d = Vec3::new(1.0, 0.5, 0.25);
        let line = f.along(o, d);
        for s in [-1.0, 0.5, 3.0] {
            let direct = f.value(o + s * d);
            let poly = line.a * s * s + 2.0 * line.b * s + line.c;
            assert!((direct - poly).abs() < 1e-12 * direct.abs().max(1.0));
        }
    }

    #[test]
    fn ellipsoids_are_bounded_and_everything_else_is_not() {
        // (x - 1)² / 4 + y² + (z + 2)² / 9 = 1.
        let ellipsoid = form([
            0.25,
            1.0,
            1.0 / 9.0,
            0.0,
            0.0,
            0.0,
            -0.5,
            0.0,
            4.0 / 9.0,
            0.25 + 4.0 / 9.0 - 1.0,
        ]);
        let Extent::Ellipsoid(b) = ellipsoid.extent() else {
            panic!("{:?}", ellipsoid.extent());
        };
        assert!(
            (b.min - Vec3::new(-1.0, -1.0, -5.0)).length() < 1e-5,
            "{b:?}"
        );
        assert!((b.max - Vec3::new(3.0, 1.0, 1.0)).length() < 1e-5, "{b:?}");
        assert!(b.min.cmple(Vec3::new(-1.0, -1.0, -5.0)).all());
        assert!(b.max.cmpge(Vec3::new(3.0, 1.0, 1.0)).all());
        // Negative definite: the same sphere seen inside out.
        let inside_out = form([-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert!(matches!(inside_out.extent(), Extent::Ellipsoid(_)));
        let empty = form([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(empty.extent(), Extent::Empty);
        let point = form([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(point.extent(), Extent::Empty);
        for unbounded in [
            [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
            [1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
            [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [1.0, 1.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        ] {
            assert_eq!(form(unbounded).extent(), Extent::Unbounded, "{unbounded:?}");
        }
    }
}
