//! Bicubic Bézier nets: evaluation with first derivatives, and subdivision
//! by de Casteljau's construction.

use crate::math::Vec3;

/// A bicubic control net: `net[i][j]` is point (i, j), i along u.
pub(crate) type ControlNet = [[Vec3; 4]; 4];

/// A point of a patch and its partial derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Evaluated {
    /// P(u, v).
    pub(crate) point: Vec3,
    /// ∂P/∂u.
    pub(crate) du: Vec3,
    /// ∂P/∂v.
    pub(crate) dv: Vec3,
}

/// The cubic Bernstein polynomials at `t` and their derivatives.
#[inline]
pub(super) fn basis(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * (s - 2.0 * t),
            3.0 * t * (2.0 * s - t),
            3.0 * t * t,
        ],
    )
}

/// The patch of `net` at (u, v), with ∂P/∂u and ∂P/∂v.
pub(crate) fn evaluate(net: &ControlNet, u: f64, v: f64) -> Evaluated {
    let (bu, du) = basis(u);
    let (bv, dv) = basis(v);
    let mut e = Evaluated {
        point: Vec3::ZERO,
        du: Vec3::ZERO,
        dv: Vec3::ZERO,
    };
    for (i, row) in net.iter().enumerate() {
        let along_v: Vec3 = row.iter().zip(bv).map(|(&p, b)| b * p).sum();
        let slope_v: Vec3 = row.iter().zip(dv).map(|(&p, b)| b * p).sum();
        e.point += bu[i] * along_v;
        e.du += du[i] * along_v;
        e.dv += bu[i] * slope_v;
    }
    e
}

/// The two halves of the cubic with control points `c`, split at 1/2.
fn halve(c: [Vec3; 4]) -> ([Vec3; 4], [Vec3; 4]) {
    let m01 = 0.5 * (c[0] + c[1]);
    let m12 = 0.5 * (c[1] + c[2]);
    let m23 = 0.5 * (c[2] + c[3]);
    let a = 0.5 * (m01 + m12);
    let b = 0.5 * (m12 + m23);
    let mid = 0.5 * (a + b);
    ([c[0], m01, a, mid], [mid, b, m23, c[3]])
}

/// The four quarters of a patch, split at u = 1/2 and v = 1/2: in the order
/// (low u, low v), (low u, high v), (high u, low v), (high u, high v).
pub(crate) fn quarters(net: &ControlNet) -> [ControlNet; 4] {
    let mut low_u = [[Vec3::ZERO; 4]; 4];
    let mut high_u = [[Vec3::ZERO; 4]; 4];
    for j in 0..4 {
        let (a, b) = halve([net[0][j], net[1][j], net[2][j], net[3][j]]);
        for i in 0..4 {
            low_u[i][j] = a[i];
            high_u[i][j] = b[i];
        }
    }
    let split_v = |half: &ControlNet| {
        let mut low = [[Vec3::ZERO; 4]; 4];
        let mut high = [[Vec3::ZERO; 4]; 4];
        for i in 0..4 {
            (low[i], high[i]) = halve(half[i]);
        }
        (low, high)
    };
    let (a, b) = split_v(&low_u);
    let (c, d) = split_v(&high_u);
    [a, b, c, d]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    fn random_net(rng: &mut Rng) -> ControlNet {
        std::array::from_fn(|_| std::array::from_fn(|_| rng.point_in(-Vec3::ONE, Vec3::ONE)))
    }

    #[test]
    fn corners_are_interpolated_and_derivatives_match_differences() {
        let mut rng = Rng::new(5);
        let net = random_net(&mut rng);
        assert_eq!(evaluate(&net, 0.0, 0.0).point, net[0][0]);
        assert!((evaluate(&net, 1.0, 1.0).point - net[3][3]).length() < 1e-15);
        let e = evaluate(&net, 0.0, 0.0);
        assert!((e.du - 3.0 * (net[1][0] - net[0][0])).length() < 1e-14);
        assert!((e.dv - 3.0 * (net[0][1] - net[0][0])).length() < 1e-14);
        for _ in 0..100 {
            let (u, v) = (rng.uniform(), rng.uniform());
            let h = 1e-6;
            let e = evaluate(&net, u, v);
            let du = (evaluate(&net, u + h, v).point - evaluate(&net, u - h, v).point) / (2.0 * h);
            let dv = (evaluate(&net, u, v + h).point - evaluate(&net, u, v - h).point) / (2.0 * h);
            assert!((e.du - du).length() < 1e-8 && (e.dv - dv).length() < 1e-8);
        }
    }

    #[test]
    fn quarters_are_the_same_surface_over_their_parameter_ranges() {
        let mut rng = Rng::new(7);
        let net = random_net(&mut rng);
        let parts = quarters(&net);
        for (k, part) in parts.iter().enumerate() {
            let (u0, v0) = (0.5 * (k / 2) as f64, 0.5 * (k % 2) as f64);
            for _ in 0..50 {
                let (s, t) = (rng.uniform(), rng.uniform());
                let whole = evaluate(&net, u0 + 0.5 * s, v0 + 0.5 * t).point;
                assert!((evaluate(part, s, t).point - whole).length() < 1e-14);
            }
        }
    }
}
