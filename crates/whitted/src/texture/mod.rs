//! Colour sources for material slots: a constant colour, a procedural
//! checkerboard or an image, over the surface's (u, v) coordinates.
//!
//! Scene syntax: a colour slot takes `[r, g, b]`, a single number (grey),
//! `{ checker = { even = [r, g, b], odd = [r, g, b], size = s } }` where `s`
//! is the side of one square in (u, v) units, or
//! `{ image = "wood.png", wrap = "repeat", scale = [su, sv], offset = [ou, ov] }`.

mod checker;
mod decode;
mod image;

pub use self::checker::Checker;
#[cfg(test)]
pub(crate) use self::decode::tests::png_bytes;
pub use self::decode::{ImageCache, ImageLoadError, decode_image};
pub use self::image::{ImageData, ImageTexture, Wrap};
use crate::math::{Color, DVec2};

/// What a material slot's colour is at a surface point.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// The same colour everywhere.
    Constant(Color),
    /// Alternating squares in (u, v).
    Checker(Checker),
    /// A PNG or JPEG image, filtered bilinearly.
    Image(ImageTexture),
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
        }
    }

    /// True when the colour is zero everywhere (the slot can be skipped).
    pub fn is_black(&self) -> bool {
        match self {
            Texture::Constant(c) => *c == Color::ZERO,
            Texture::Checker(c) => c.even == Color::ZERO && c.odd == Color::ZERO,
            Texture::Image(image) => image.max_component() == 0.0,
        }
    }

    /// The largest component anywhere (bounds the slot's weight).
    pub fn max_component(&self) -> f64 {
        match self {
            Texture::Constant(c) => c.max_element(),
            Texture::Checker(c) => c.even.max_element().max(c.odd.max_element()),
            Texture::Image(image) => image.max_component(),
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
    fn black_detection_covers_both_squares() {
        assert!(Texture::default().is_black());
        let t = Texture::Checker(Checker {
            even: Color::ZERO,
            odd: Color::X,
            size: 1.0,
        });
        assert!(!t.is_black());
        assert_eq!(t.max_component(), 1.0);
    }
}
