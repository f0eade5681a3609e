//! Texture lookups averaged over a pixel's footprint (see
//! [`crate::shading::differential`]): images through their mipmap
//! (trilinear), checkers by the closed-form integral of the checkerboard
//! over a box (as pbrt's filtered checkerboard).
//!
//! The checker is averaged over the pixel's own footprint, the
//! parallelogram `uv + X ∂uv/∂x + Y ∂uv/∂y` for X, Y in [−½, ½] (the
//! pixel's square under a box filter, as the supersampled reference sees
//! it): exactly along the pixel axis that crosses more squares (the
//! squares met along that line, found from where u and v cross whole
//! squares), at 1 to 16 evenly spaced lines across the other axis (16 as
//! soon as it crosses a sixteenth of a square, as a 16 × 16 grid of
//! samples would). Where the footprint crosses so many squares that
//! this would cost more than a few hundred steps (near the horizon), the
//! closed-form mean over an axis-aligned box (pbrt's filtered
//! checkerboard) is taken instead: its sides are the footprint's spread,
//! `√(∂u/∂x² + ∂u/∂y²)` in u (the box of the same variance), and both give
//! the checker's mean colour there.

use super::{Checker, Texture};
use crate::math::DVec2;
use crate::shading::Color;
use crate::shading::differential::Footprint;

impl Texture {
    /// The colour averaged over `footprint` around `uv`, or the colour at
    /// `uv` when there is no footprint. A constant is answered where it is
    /// asked (a shaded point asks up to seven times), the others out of
    /// line.
    #[inline(always)]
    pub fn filtered(&self, uv: DVec2, footprint: Option<&Footprint>) -> Color {
        match self {
            Texture::Constant(c) => *c,
            _ => self.filtered_varying(uv, footprint),
        }
    }

    /// [`Self::filtered`] for a texture that is not a constant.
    #[inline(never)]
    fn filtered_varying(&self, uv: DVec2, footprint: Option<&Footprint>) -> Color {
        let Some(footprint) = footprint else {
            return self.at(uv);
        };
        match self {
            Texture::Constant(c) => *c,
            Texture::Checker(checker) => checker.footprint_mean(uv, footprint),
            Texture::Image(image) => image.filtered(uv, footprint),
            Texture::Dissolve(map) => map.value_for_image(map.opacity.filtered(uv, footprint)),
        }
    }
}

impl Checker {
    /// The mean colour over the box around `uv` whose sides are the
    /// footprint's spread in u and in v (see the module's notes).
    pub fn box_filtered(&self, uv: DVec2, footprint: &Footprint) -> Color {
        let (dx, dy) = (footprint.duv_dx, footprint.duv_dy);
        let width = DVec2::new(dx.x.hypot(dy.x), dx.y.hypot(dy.y));
        self.box_mean(uv, width)
    }

    /// The mean colour over the footprint's parallelogram (see the
    /// module's notes).
    pub fn footprint_mean(&self, uv: DVec2, footprint: &Footprint) -> Color {
        let centre = uv / self.size;
        let (mut along, mut across) = (footprint.duv_dx / self.size, footprint.duv_dy / self.size);
        let crossings = |d: DVec2| d.x.abs() + d.y.abs();
        if crossings(across) > crossings(along) {
            std::mem::swap(&mut along, &mut across);
        }
        let lines = (256.0 * crossings(across)).ceil().clamp(1.0, MAX_LINES);
        if !(crossings(along) <= MAX_CROSSINGS && crossings(across) <= MAX_LINES / 4.0) {
            return self.box_filtered(uv, footprint);
        }
        let mut odd = 0.0;
        for i in 0..lines as u32 {
            let offset = (f64::from(i) + 0.5) / lines - 0.5;
            odd += odd_along(centre + offset * across, along);
        }
        let odd = odd / lines;
        self.even * (1.0 - odd) + self.odd * odd
    }

    /// The mean colour over the axis-aligned box of sides `width` centred
    /// on `uv`, in closed form.
    pub fn box_mean(&self, uv: DVec2, width: DVec2) -> Color {
        let s = uv / self.size;
        let half = 0.5 * width / self.size;
        let odd_u = odd_fraction(s.x, half.x);
        let odd_v = odd_fraction(s.y, half.y);
        if !(odd_u.is_finite() && odd_v.is_finite()) {
            return self.at(uv);
        }
        // A point is in an odd square when exactly one of its coordinates
        // is in an odd cell; the two are independent over a box.
        let odd = odd_u + odd_v - 2.0 * odd_u * odd_v;
        self.even * (1.0 - odd) + self.odd * odd
    }
}

/// Most squares crossed along a line of the footprint that
/// [`Checker::footprint_mean`] follows exactly.
const MAX_CROSSINGS: f64 = 64.0;

/// Most lines across the footprint [`Checker::footprint_mean`] follows.
const MAX_LINES: f64 = 16.0;

/// The fraction of the segment `p + X d`, X in [−½, ½] (in squares), that
/// lies in odd squares (`⌊u⌋ + ⌊v⌋` odd).
fn odd_along(p: DVec2, d: DVec2) -> f64 {
    let mut cuts = [0.0f64; 2 * (MAX_CROSSINGS as usize + 2)];
    let mut count = 0;
    for (start, step) in [(p.x, d.x), (p.y, d.y)] {
        if step == 0.0 {
            continue;
        }
        let (a, b) = (start - 0.5 * step, start + 0.5 * step);
        let (lo, hi) = (a.min(b), a.max(b));
        let mut k = lo.floor() + 1.0;
        while k < hi && count < cuts.len() {
            cuts[count] = (k - start) / step;
            count += 1;
            k += 1.0;
        }
    }
    let cuts = &mut cuts[..count];
    cuts.sort_unstable_by(f64::total_cmp);
    let mut odd = 0.0;
    let mut from = -0.5;
    for &to in cuts.iter().chain([0.5].iter()) {
        if to > from {
            let middle = p + 0.5 * (from + to) * d;
            odd += (to - from) * (middle.x.floor() + middle.y.floor()).rem_euclid(2.0);
            from = to;
        }
    }
    odd
}

/// The fraction of `[s − half, s + half]` where `⌊x⌋` is odd (the point's
/// value of that fraction where `half` is zero).
fn odd_fraction(s: f64, half: f64) -> f64 {
    if half.is_nan() || half <= 0.0 {
        return s.floor().rem_euclid(2.0);
    }
    (odd_integral(s + half) - odd_integral(s - half)) / (2.0 * half)
}

/// `∫₀ˣ [⌊t⌋ odd] dt`: one per period of two, plus the part of the odd
/// cell the last period reaches into.
fn odd_integral(x: f64) -> f64 {
    let periods = (0.5 * x).floor();
    periods + (x - 2.0 * periods - 1.0).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    fn checker() -> Checker {
        Checker {
            even: Color::new(0.9, 0.8, 0.1),
            odd: Color::new(0.1, 0.2, 0.7),
            size: 0.37,
        }
    }

    /// The mean of the checker over the box by the midpoint rule on a fine
    /// grid.
    fn numeric_mean(c: &Checker, uv: DVec2, width: DVec2) -> Color {
        let n = 800;
        let mut sum = Color::ZERO;
        for i in 0..n {
            for j in 0..n {
                let p = uv
                    + width
                        * DVec2::new(
                            (i as f64 + 0.5) / n as f64 - 0.5,
                            (j as f64 + 0.5) / n as f64 - 0.5,
                        );
                sum += c.at(p);
            }
        }
        sum / (n * n) as f64
    }

    #[test]
    fn the_closed_form_matches_numerical_integration_over_random_boxes() {
        let c = checker();
        let mut rng = Rng::new(19);
        for _ in 0..40 {
            let uv = DVec2::new(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0));
            let width = DVec2::new(rng.range(0.0, 2.0), rng.range(0.0, 2.0));
            let got = c.box_mean(uv, width);
            let want = numeric_mean(&c, uv, width);
            assert!(
                (got - want).abs().max_element() < 3e-3,
                "{uv} {width}: {got:?} against {want:?}"
            );
        }
    }

    #[test]
    fn a_point_footprint_gives_the_point_colour_and_a_huge_one_the_mean() {
        let c = checker();
        let mut rng = Rng::new(5);
        for _ in 0..100 {
            let uv = DVec2::new(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0));
            let t = Texture::Checker(c.clone());
            assert_eq!(t.filtered(uv, Some(&Footprint::POINT)), c.at(uv));
            assert_eq!(t.filtered(uv, None), c.at(uv));
        }
        let mean = (c.even + c.odd) * 0.5;
        let far = c.box_mean(DVec2::new(0.1, 0.2), DVec2::new(1e3, 1e3));
        assert!((far - mean).abs().max_element() < 1e-3, "{far:?}");
    }

    /// The mean over the parallelogram by the midpoint rule on a fine grid.
    fn numeric_footprint_mean(c: &Checker, uv: DVec2, f: &Footprint) -> Color {
        let n = 600;
        let mut sum = Color::ZERO;
        for i in 0..n {
            for j in 0..n {
                let x = (i as f64 + 0.5) / n as f64 - 0.5;
                let y = (j as f64 + 0.5) / n as f64 - 0.5;
                sum += c.at(uv + x * f.duv_dx + y * f.duv_dy);
            }
        }
        sum / (n * n) as f64
    }

    #[test]
    fn the_footprint_mean_matches_numerical_integration_over_random_footprints() {
        let c = checker();
        let mut rng = Rng::new(23);
        for _ in 0..40 {
            let uv = DVec2::new(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0));
            let mut d = || DVec2::new(rng.range(-0.8, 0.8), rng.range(-0.8, 0.8));
            let f = Footprint {
                duv_dx: d(),
                duv_dy: d() * 0.3,
            };
            let got = c.footprint_mean(uv, &f);
            let want = numeric_footprint_mean(&c, uv, &f);
            assert!(
                (got - want).abs().max_element() < 0.02,
                "{uv} {f:?}: {got:?} against {want:?}"
            );
        }
    }

    #[test]
    fn the_footprint_box_spreads_by_the_root_sum_of_squares() {
        let c = checker();
        let f = Footprint {
            duv_dx: DVec2::new(0.3, 0.0),
            duv_dy: DVec2::new(0.4, 0.1),
        };
        let uv = DVec2::new(0.2, 0.33);
        assert_eq!(c.box_filtered(uv, &f), c.box_mean(uv, DVec2::new(0.5, 0.1)));
    }
}
