//! Colour sources for material slots: a constant colour, a procedural
//! checkerboard or an image, over the surface's (u, v) coordinates.
//!
//! Scene syntax: a colour slot takes `[r, g, b]`, a single number (grey),
//! `{ checker = { even = [r, g, b], odd = [r, g, b], size = s } }` where `s`
//! is the side of one square in (u, v) units, or
//! `{ image = "wood.png", wrap = "repeat", scale = [su, sv], offset = [ou, ov] }`.
//! MTL dissolve maps (`map_d`) become a [`DissolveMap`]: an opacity, or the
//! transmission of MTL glass.

mod checker;
mod decode;
mod dissolve;
mod filtered;
mod image;
pub mod mipmap;

pub use self::checker::Checker;
#[cfg(test)]
pub(crate) use self::decode::tests::{png_bytes, rgba_png_bytes};
pub use self::decode::{Decoding, ImageCache, ImageLoadError, decode_image};
pub use self::dissolve::DissolveMap;
pub use self::image::{ImageData, ImageTexture, LARGE_TEXTURE_BYTES, Texels, Wrap};
use crate::math::DVec2;
use crate::shading::Color;

/// The luminance of a linear RGB colour (Rec. 709 weights, which sum to 1:
/// a grey's luminance is its level).
pub fn luminance(c: Color) -> f64 {
    0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b
}

/// What a material slot's colour is at a surface point.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// The same colour everywhere.
    Constant(Color),
    /// Alternating squares in (u, v).
    Checker(Checker),
    /// A PNG or JPEG image, filtered bilinearly.
    Image(ImageTexture),
    /// An MTL dissolve map (`map_d`): an opacity, or what it lets through.
    Dissolve(DissolveMap),
}

impl Default for Texture {
    fn default() -> Self {
        Texture::Constant(Color::ZERO)
    }
}

impl From<Color> for Texture {
    fn from(c: Color) -> Self {
        Texture::Constant(c)
    }
}

impl Texture {
    /// The colour at texture coordinates `uv`.
    #[inline]
    pub fn at(&self, uv: DVec2) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checker(checker) => checker.at(uv),
            Texture::Image(image) => image.at(uv),
            Texture::Dissolve(map) => map.at(uv),
        }
    }

    /// True when the colour is zero everywhere (the slot can be skipped);
    /// may say false for a dissolve map that happens to be clear
    /// everywhere.
    pub fn is_black(&self) -> bool {
        match self {
            Texture::Constant(c) => *c == Color::ZERO,
            Texture::Checker(c) => c.even == Color::ZERO && c.odd == Color::ZERO,
            Texture::Image(image) => image.max_component() == 0.0,
            Texture::Dissolve(map) => map.max_component() == 0.0,
        }
    }

    /// True when the colour is one in every component everywhere (an
    /// opacity that lets nothing through); may say false for an image or a
    /// dissolve map that happens to be opaque everywhere.
    pub fn is_white(&self) -> bool {
        match self {
            Texture::Constant(c) => *c == Color::ONE,
            Texture::Checker(c) => c.even == Color::ONE && c.odd == Color::ONE,
            Texture::Image(_) | Texture::Dissolve(_) => false,
        }
    }

    /// The largest component anywhere, or a bound on it (bounds the slot's
    /// weight).
    pub fn max_component(&self) -> f64 {
        match self {
            Texture::Constant(c) => c.max_element(),
            Texture::Checker(c) => c.even.max_element().max(c.odd.max_element()),
            Texture::Image(image) => image.max_component(),
            Texture::Dissolve(map) => map.max_component(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_alternates_between_neighbouring_squares() {
        let t = Texture::Checker(Checker {
            even: Color::ONE,
            odd: Color::ZERO,
            size: 0.5,
        });
        assert_eq!(t.at(DVec2::new(0.1, 0.1)), Color::ONE);
        assert_eq!(t.at(DVec2::new(0.6, 0.1)), Color::ZERO);
        assert_eq!(t.at(DVec2::new(0.6, 0.6)), Color::ONE);
        assert_eq!(t.at(DVec2::new(-0.1, 0.1)), Color::ZERO);
        assert_eq!(t.at(DVec2::new(-0.1, -0.1)), Color::ONE);
    }

    #[test]
    fn black_and_white_detection_covers_both_squares() {
        assert!(Texture::default().is_black());
        assert!(Texture::Constant(Color::ONE).is_white());
        assert!(!Texture::Constant(Color::new(1.0, 1.0, 0.5)).is_white());
        let t = Texture::Checker(Checker {
            even: Color::ZERO,
            odd: Color::RED,
            size: 1.0,
        });
        assert!(!t.is_black() && !t.is_white());
        assert_eq!(t.max_component(), 1.0);
    }
}
