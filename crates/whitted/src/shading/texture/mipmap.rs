//! A mipmap pyramid of an image (Williams 1983) and trilinear lookups in
//! it chosen by a pixel's footprint.
//!
//! Each level halves the one before, rounding up (`⌈w/2⌉ × ⌈h/2⌉`) down
//! to 1 × 1, so images of any size (not only powers of two) get a full
//! pyramid. A texel of level `l + 1` is the area-weighted mean of the
//! level-`l` texels its square covers (a box filter; an odd side's middle
//! texel is shared half and half), computed in linear RGB in `f64`: every
//! level keeps the image's mean exactly, up to the `f32` rounding of the
//! stored texels.
//!
//! A lookup takes the longer of the footprint's two axes in texels of the
//! full image, `w = max(|∂st/∂x|, |∂st/∂y|)`, picks the fractional level
//! `log2 w` and blends bilinear lookups in the two levels around it
//! (trilinear filtering, isotropic: at grazing angles it blurs along the
//! short axis as much as along the long one).

use super::image::{ImageTexture, Wrap};
use crate::math::DVec2;
use crate::shading::Color;
use crate::shading::differential::Footprint;

/// One level of a pyramid: `width × height` linear RGB texels, row 0 at
/// the top.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// The texels, row by row from the top.
    pub texels: Vec<[f32; 3]>,
}

/// The levels below an image: level 1 (half size) down to 1 × 1; level 0
/// is the image itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mipmap {
    /// Levels 1, 2, …, the last one 1 × 1 (none for a 1 × 1 image).
    pub levels: Vec<MipLevel>,
}

impl Mipmap {
    /// The pyramid of a `width × height` image whose texel `i` (row by
    /// row from the top) is `texel(i)`. The image is read where it is,
    /// not copied, and each level is made a row at a time, so building
    /// takes the levels' memory and a few rows' more.
    pub fn build(width: usize, height: usize, texel: impl Fn(usize) -> [f32; 3]) -> Self {
        let mut levels: Vec<MipLevel> = Vec::new();
        if width > 1 || height > 1 {
            levels.push(halve(width, height, texel));
        }
        while let Some(last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            let next = halve(last.width, last.height, |i| last.texels[i]);
            levels.push(next);
        }
        Self { levels }
    }
}

/// The level of half the size (rounded up) of a `w × h` level whose texel
/// `i` is `texel(i)`, by area-weighted box filtering: rows first, then
/// columns. Each output row sums, in f64, the rows it covers, each summed
/// along the row first.
fn halve(w: usize, h: usize, texel: impl Fn(usize) -> [f32; 3]) -> MipLevel {
    let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
    let wx = box_weights(w, nw);
    let wy = box_weights(h, nh);
    // The horizontal pass of input row `y`: nw texels.
    let horizontal = |y: usize, row: &mut Vec<[f64; 3]>| {
        row.clear();
        row.extend(wx.iter().map(|weights| {
            let mut out = [0.0f64; 3];
            for &(i, weight) in weights {
                let t = texel(y * w + i);
                for c in 0..3 {
                    out[c] += weight * f64::from(t[c]);
                }
            }
            out
        }));
    };
    let mut texels = Vec::with_capacity(nw * nh);
    // The input rows the last output row covered, by number: the next one
    // may share its first row with them.
    let mut rows: Vec<(usize, Vec<[f64; 3]>)> = Vec::new();
    for weights in &wy {
        let mut next = Vec::with_capacity(weights.len());
        for &(j, _) in weights {
            let row = match rows.iter().position(|(k, _)| *k == j) {
                Some(at) => rows.swap_remove(at).1,
                None => {
                    let mut row = Vec::with_capacity(nw);
                    horizontal(j, &mut row);
                    row
                }
            };
            next.push((j, row));
        }
        rows = next;
        for x in 0..nw {
            let mut sum = [0.0f64; 3];
            for ((_, row), &(_, weight)) in rows.iter().zip(weights) {
                let t = row[x];
                for c in 0..3 {
                    sum[c] += weight * t[c];
                }
            }
            texels.push(sum.map(|c| c as f32));
        }
    }
    MipLevel {
        width: nw,
        height: nh,
        texels,
    }
}

/// For each of `m` output texels over `n` input texels (`m = ⌈n/2⌉`), the
/// input texels its interval `[i n/m, (i+1) n/m)` covers and the fraction
/// of it each covers (the weights of one output texel sum to 1).
fn box_weights(n: usize, m: usize) -> Vec<Vec<(usize, f64)>> {
    let scale = n as f64 / m as f64;
    (0..m)
        .map(|i| {
            let (lo, hi) = (i as f64 * scale, (i + 1) as f64 * scale);
            let first = lo.floor() as usize;
            let last = (hi.ceil() as usize).min(n);
            (first..last)
                .map(|k| {
                    let covered = (hi.min(k as f64 + 1.0) - lo.max(k as f64)).max(0.0);
                    (k, covered / scale)
                })
                .filter(|&(_, weight)| weight > 0.0)
                .collect()
        })
        .collect()
}

/// The bilinear lookup at image coordinates `st` in a level of
/// `width × height` `texels` (the same rule as [`ImageTexture::at`]).
fn bilinear(width: usize, height: usize, texels: &[[f32; 3]], wrap: Wrap, st: DVec2) -> Color {
    let x = st.x * width as f64 - 0.5;
    let y = (1.0 - st.y) * height as f64 - 0.5;
    if !(x.is_finite() && y.is_finite()) {
        return Color::ZERO;
    }
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let xs = [x0, x0.saturating_add(1)].map(|i| wrap.index(i, width));
    let ys = [y0, y0.saturating_add(1)].map(|i| wrap.index(i, height));
    let texel = |x: usize, y: usize| {
        let [r, g, b] = texels[y * width + x];
        Color::new(f64::from(r), f64::from(g), f64::from(b))
    };
    let top = texel(xs[0], ys[0]) * (1.0 - fx) + texel(xs[1], ys[0]) * fx;
    let bottom = texel(xs[0], ys[1]) * (1.0 - fx) + texel(xs[1], ys[1]) * fx;
    top * (1.0 - fy) + bottom * fy
}

impl ImageTexture {
    /// The colour averaged over `footprint` around `uv`: trilinear
    /// filtering in the image's mipmap (built on first use).
    pub fn filtered(&self, uv: DVec2, footprint: &Footprint) -> Color {
        let data = &self.data;
        let st = uv * self.scale + self.offset;
        let f = footprint.scaled(self.scale);
        let size = DVec2::new(data.width() as f64, data.height() as f64);
        let width = (f.duv_dx * size).length().max((f.duv_dy * size).length());
        if width.is_nan() || width <= 1.0 {
            return self.at(uv);
        }
        let pyramid = data.mipmap();
        let top = pyramid.levels.len() as f64;
        let level = width.log2().min(top);
        let lower = level.floor();
        let fraction = level - lower;
        let at_level = |l: usize| match l {
            0 => self.at(uv),
            _ => {
                let m = &pyramid.levels[l - 1];
                bilinear(m.width, m.height, &m.texels, self.wrap, st)
            }
        };
        let a = at_level(lower as usize);
        if fraction == 0.0 {
            return a;
        }
        a * (1.0 - fraction) + at_level(lower as usize + 1) * fraction
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::shading::texture::ImageData;
    use std::sync::Arc;

    fn mean(level: &MipLevel) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for t in &level.texels {
            for c in 0..3 {
                sum[c] += f64::from(t[c]);
            }
        }
        sum.map(|s| s / level.texels.len() as f64)
    }

    fn random_image(width: usize, height: usize, seed: u64) -> Vec<[f32; 3]> {
        let mut rng = Rng::new(seed);
        (0..width * height)
            .map(|_| {
                [
                    rng.uniform() as f32,
                    rng.uniform() as f32,
                    rng.uniform() as f32,
                ]
            })
            .collect()
    }

    #[test]
    fn level_sizes_halve_rounding_up_down_to_one_texel() {
        let sizes = |w, h| {
            Mipmap::build(w, h, |_| [0.0; 3])
                .levels
                .iter()
                .map(|l| (l.width, l.height))
                .collect::<Vec<_>>()
        };
        assert_eq!(sizes(8, 4), [(4, 2), (2, 1), (1, 1)]);
        assert_eq!(sizes(5, 3), [(3, 2), (2, 1), (1, 1)]);
        assert_eq!(sizes(7, 1), [(4, 1), (2, 1), (1, 1)]);
        assert!(sizes(1, 1).is_empty());
    }

    #[test]
    fn a_constant_image_stays_constant_on_every_level() {
        let c = [0.25f32, 0.5, 0.75];
        let m = Mipmap::build(13, 6, |_| c);
        for level in &m.levels {
            for t in &level.texels {
                for k in 0..3 {
                    assert!((t[k] - c[k]).abs() < 1e-6, "{t:?}");
                }
            }
        }
    }

    #[test]
    fn every_level_keeps_the_mean_of_the_image() {
        for (w, h) in [(16, 16), (13, 7), (1, 9), (30, 17)] {
            let texels = random_image(w, h, (w * 31 + h) as u64);
            let full = mean(&MipLevel {
                width: w,
                height: h,
                texels: texels.clone(),
            });
            for level in Mipmap::build(w, h, |i| texels[i]).levels {
                let m = mean(&level);
                for c in 0..3 {
                    assert!((m[c] - full[c]).abs() < 1e-6, "{w}x{h}: {m:?} {full:?}");
                }
            }
        }
    }

    #[test]
    fn a_footprint_as_wide_as_the_image_gives_its_mean_and_a_tiny_one_the_bilinear_lookup() {
        let texels = random_image(16, 16, 7);
        let data = ImageData::new(16, 16, texels).unwrap();
        let image_mean = data.mean();
        let t = ImageTexture::new(Arc::new(data));
        let uv = DVec2::new(0.3, 0.6);
        let wide = Footprint {
            duv_dx: DVec2::new(1.0, 0.0),
            duv_dy: DVec2::new(0.0, 1.0),
        };
        let got = t.filtered(uv, &wide);
        assert!((got - image_mean).abs().max_element() < 1e-6, "{got:?}");
        let tiny = Footprint {
            duv_dx: DVec2::new(0.01, 0.0),
            duv_dy: DVec2::new(0.0, 0.01),
        };
        assert_eq!(t.filtered(uv, &tiny), t.at(uv));
        // Between, the result lies between the sharp and the blurred one.
        let mid = Footprint {
            duv_dx: DVec2::new(0.2, 0.0),
            duv_dy: DVec2::ZERO,
        };
        assert!(t.filtered(uv, &mid).is_finite());
    }
}
