//! Image textures: linear RGB texels shared between materials, sampled
//! with bilinear filtering.
//!
//! Texture coordinates follow the OBJ convention: `u` runs left to right and
//! `v` bottom to top, so `v = 0` is the bottom row of the image and `v = 1`
//! its top. Texel `(x, y)` (row `y` counted from the top) has its centre at
//! `u = (x + 0.5) / width`, `v = 1 - (y + 0.5) / height`.

use std::fmt;
use std::sync::{Arc, OnceLock};

use super::mipmap::Mipmap;

use crate::limits::{Charge, Held};

use crate::shading::Color;

use crate::math::DVec2;

/// Textures taking more than this are noted where the scene names them
/// (1 GiB, see [`ImageCache::load_noting`](super::ImageCache::load_noting)).
pub const LARGE_TEXTURE_BYTES: u64 = 1 << 30;

/// Texels as stored: linear RGB values, or the image's own 8-bit or
/// 16-bit samples with the table of the values they stand for (each value
/// then read from the table: the same numbers, in a quarter or half of the
/// memory).
#[derive(Clone, PartialEq)]
pub enum Texels {
    /// Linear RGB values.
    Values(Vec<[f32; 3]>),
    /// 8-bit samples and the value of each.
    Bytes(Vec<[u8; 3]>, Arc<[f32; 256]>),
    /// 16-bit samples and the value of each.
    Words(Vec<[u16; 3]>, Arc<[f32]>),
}

impl Texels {
    /// How many texels.
    pub fn len(&self) -> usize {
        match self {
            Texels::Values(v) => v.len(),
            Texels::Bytes(v, _) => v.len(),
            Texels::Words(v, _) => v.len(),
        }
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Texel `i`'s values.
    #[inline]
    pub fn get(&self, i: usize) -> [f32; 3] {
        match self {
            Texels::Values(v) => v[i],
            Texels::Bytes(v, table) => v[i].map(|s| table[usize::from(s)]),
            Texels::Words(v, table) => v[i].map(|s| table[usize::from(s)]),
        }
    }

    /// The values of texels `at`, the storage looked at once for the four
    /// (a bilinear lookup's).
    #[inline]
    fn four(&self, at: [usize; 4]) -> [[f32; 3]; 4] {
        match self {
            Texels::Values(v) => at.map(|i| v[i]),
            Texels::Bytes(v, table) => at.map(|i| v[i].map(|s| table[usize::from(s)])),
            Texels::Words(v, table) => at.map(|i| v[i].map(|s| table[usize::from(s)])),
        }
    }

    /// Bytes a texel takes.
    pub fn bytes_per_texel(&self) -> usize {
        match self {
            Texels::Values(_) => 12,
            Texels::Bytes(..) => 3,
            Texels::Words(..) => 6,
        }
    }
}

/// Decoded texels in linear RGB, row 0 at the top of the image.
#[derive(Clone)]
pub struct ImageData {
    width: usize,
    height: usize,
    texels: Texels,
    max_component: f64,
    mean: Color,
    /// Its mipmap, built by the first filtered lookup.
    mipmap: OnceLock<Mipmap>,
    /// What it is charged in the memory ledger, texels and mipmap.
    held: Held,
}

impl PartialEq for ImageData {
    /// The same texels (whether the mipmap is built yet does not count).
    fn eq(&self, other: &Self) -> bool {
        (self.width, self.height) == (other.width, other.height) && self.texels == other.texels
    }
}

impl fmt::Debug for ImageData {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "ImageData({}x{})", self.width, self.height)
    }
}

impl ImageData {
    /// An image of `width × height` linear RGB texels, row by row from the
    /// top; `None` when a side is zero or the count does not match.
    pub fn new(width: usize, height: usize, texels: Vec<[f32; 3]>) -> Option<Self> {
        Self::stored(width, height, Texels::Values(texels))
    }

    /// An image of `width × height` texels stored as `texels` are.
    pub fn stored(width: usize, height: usize, texels: Texels) -> Option<Self> {
        if width == 0 || height == 0 || width.checked_mul(height) != Some(texels.len()) {
            return None;
        }
        let values = (0..texels.len()).map(|i| texels.get(i));
        let max_component = values
            .clone()
            .flatten()
            .fold(0.0f64, |m, c| m.max(f64::from(c)));
        let sum = values.fold(Color::ZERO, |sum, [r, g, b]| {
            sum + Color::new(f64::from(r), f64::from(g), f64::from(b))
        });
        let mean = sum / texels.len() as f64;
        Some(Self {
            width,
            height,
            texels,
            max_component,
            mean,
            mipmap: OnceLock::new(),
            held: Held::default(),
        })
    }

    /// The image, keeping `charge` (what its texels and mipmap are
    /// charged in the memory ledger) until it is dropped.
    pub fn holding(mut self, charge: Charge) -> Self {
        self.held.keep(charge);
        self
    }

    /// Its mipmap pyramid, built once on first use.
    pub fn mipmap(&self) -> &Mipmap {
        self.mipmap
            .get_or_init(|| Mipmap::build(self.width, self.height, |i| self.texels.get(i)))
    }

    /// The mean of all texels.
    pub fn mean(&self) -> Color {
        self.mean
    }

    /// The bytes charged for it in the memory ledger while it is kept
    /// (its texels and mipmap, see [`ImageData::holding`]); 0 for an image
    /// made in code.
    pub fn charged_bytes(&self) -> u64 {
        self.held.bytes()
    }

    /// A note for a texture charged more than `threshold` bytes (`name`
    /// is how the scene names its file), `None` for others.
    pub fn large_texture_note(&self, name: &str, threshold: u64) -> Option<String> {
        let bytes = self.charged_bytes();
        (bytes > threshold).then(|| {
            format!(
                "the image `{name}` takes {} as a texture ({}x{} texels and their mipmap): \
                 a smaller image would take less memory",
                crate::limits::format_bytes(bytes),
                self.width,
                self.height
            )
        })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The values of the texel in column `x`, row `y` from the top (both
    /// in range).
    pub fn texel_values(&self, x: usize, y: usize) -> [f32; 3] {
        self.texels.get(y * self.width + x)
    }

    /// Bytes each texel takes as stored (3 for 8-bit samples, 6 for
    /// 16-bit, 12 for linear values).
    pub fn bytes_per_texel(&self) -> usize {
        self.texels.bytes_per_texel()
    }
}

/// What lies outside `[0, 1]` in (u, v).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    Clamp,
    /// The image tiles the plane, every other copy mirrored.
    Mirror,
}

impl Wrap {
    /// The texel index in `0..n` for any integer index `i`.
    pub(super) fn index(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        let wrapped = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        };
        wrapped as usize
    }
}

/// An image placed on a surface: `(u, v)` maps to image coordinates
/// `(u, v) · scale + offset`.
#[derive(Clone, Debug)]
pub struct ImageTexture {
    /// The shared texels.
    pub data: Arc<ImageData>,
    /// What lies outside the image.
    pub wrap: Wrap,
    /// Multiplies (u, v) (MTL `-s`).
    pub scale: DVec2,
    /// Added to (u, v) after scaling (MTL `-o`).
    pub offset: DVec2,
}

impl PartialEq for ImageTexture {
    /// The same placement of the same shared image (or of equal texels).
    fn eq(&self, other: &Self) -> bool {
        (Arc::ptr_eq(&self.data, &other.data) || self.data == other.data)
            && self.wrap == other.wrap
            && self.scale == other.scale
            && self.offset == other.offset
    }
}

impl ImageTexture {
    /// The whole image once over the unit square, repeated outside it.
    pub fn new(data: Arc<ImageData>) -> Self {
        Self {
            data,
            wrap: Wrap::Repeat,
            scale: DVec2::ONE,
            offset: DVec2::ZERO,
        }
    }

    /// The bilinearly filtered colour at texture coordinates `uv`.
    pub fn at(&self, uv: DVec2) -> Color {
        let st = uv * self.scale + self.offset;
        let data = &self.data;
        let x = st.x * data.width as f64 - 0.5;
        let y = (1.0 - st.y) * data.height as f64 - 0.5;
        if !(x.is_finite() && y.is_finite()) {
            return Color::ZERO;
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // Saturating float-to-int casts: coordinates beyond ±2^63 texels
        // land on the edge, which no render reaches.
        let (x0, y0) = (x0 as i64, y0 as i64);
        let xs = [x0, x0.saturating_add(1)].map(|i| self.wrap.index(i, data.width));
        let ys = [y0, y0.saturating_add(1)].map(|i| self.wrap.index(i, data.height));
        let w = data.width;
        let [a, b, c, d] = data
            .texels
            .four([
                ys[0] * w + xs[0],
                ys[0] * w + xs[1],
                ys[1] * w + xs[0],
                ys[1] * w + xs[1],
            ])
            .map(|[r, g, b]| Color::new(f64::from(r), f64::from(g), f64::from(b)));
        let top = a * (1.0 - fx) + b * fx;
        let bottom = c * (1.0 - fx) + d * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The largest component of any texel.
    pub fn max_component(&self) -> f64 {
        self.data.max_component
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Row 0 (top): red, green; row 1 (bottom): blue, white.
    fn two_by_two(wrap: Wrap) -> ImageTexture {
        let texels = vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        let data = ImageData::new(2, 2, texels).unwrap();
        ImageTexture {
            wrap,
            ..ImageTexture::new(Arc::new(data))
        }
    }

    fn close(a: Color, b: Color) -> bool {
        (a - b).abs().max_element() < 1e-12
    }

    #[test]
    fn texel_centres_give_the_texels_with_v_zero_at_the_bottom() {
        let t = two_by_two(Wrap::Repeat);
        assert!(close(t.at(DVec2::new(0.25, 0.75)), Color::RED));
        assert!(close(t.at(DVec2::new(0.75, 0.75)), Color::GREEN));
        assert!(close(t.at(DVec2::new(0.25, 0.25)), Color::BLUE));
        assert!(close(t.at(DVec2::new(0.75, 0.25)), Color::ONE));
    }

    #[test]
    fn halfway_between_texels_gives_their_mean() {
        let t = two_by_two(Wrap::Clamp);
        assert!(close(
            t.at(DVec2::new(0.5, 0.75)),
            Color::new(0.5, 0.5, 0.0)
        ));
        assert!(close(
            t.at(DVec2::new(0.25, 0.5)),
            Color::new(0.5, 0.0, 0.5)
        ));
        assert!(close(t.at(DVec2::new(0.5, 0.5)), Color::new(0.5, 0.5, 0.5)));
    }

    #[test]
    fn repeat_tiles_and_blends_across_the_edge() {
        let t = two_by_two(Wrap::Repeat);
        assert!(close(t.at(DVec2::new(1.25, -0.75)), Color::BLUE));
        // At u = 0 the left and right columns of the top row meet.
        assert!(close(
            t.at(DVec2::new(0.0, 0.75)),
            Color::new(0.5, 0.5, 0.0)
        ));
    }

    #[test]
    fn clamp_extends_the_edge_texels() {
        let t = two_by_two(Wrap::Clamp);
        assert!(close(t.at(DVec2::new(0.0, 0.75)), Color::RED));
        assert!(close(t.at(DVec2::new(-3.0, 0.75)), Color::RED));
        assert!(close(t.at(DVec2::new(7.0, -2.0)), Color::ONE));
    }

    #[test]
    fn mirror_reflects_every_other_copy() {
        let t = two_by_two(Wrap::Mirror);
        // Just right of u = 1 is the mirrored copy: green first.
        assert!(close(t.at(DVec2::new(1.25, 0.75)), Color::GREEN));
        assert!(close(t.at(DVec2::new(1.75, 0.75)), Color::RED));
        assert!(close(t.at(DVec2::new(2.25, 0.75)), Color::RED));
        assert!(close(t.at(DVec2::new(1.0, 0.75)), Color::GREEN));
    }

    #[test]
    fn scale_and_offset_move_the_image() {
        let t = ImageTexture {
            scale: DVec2::splat(2.0),
            offset: DVec2::new(0.5, 0.0),
            ..two_by_two(Wrap::Repeat)
        };
        // (0.125, 0.375) · 2 + (0.5, 0) = (0.75, 0.75): green.
        assert!(close(t.at(DVec2::new(0.125, 0.375)), Color::GREEN));
    }

    #[test]
    fn mismatched_sizes_are_refused() {
        assert!(ImageData::new(2, 2, vec![[0.0; 3]; 3]).is_none());
        assert!(ImageData::new(0, 0, Vec::new()).is_none());
    }
}
