//! Colour sources for material slots: a constant colour or a procedural
//! checkerboard over the surface's (u, v) coordinates.
//!
//! Scene syntax: a colour slot takes `[r, g, b]`, a single number (grey), or
//! `{ checker = { even = [r, g, b], odd = [r, g, b], size = s } }` where `s`
//! is the side of one square in (u, v) units.

use crate::math::{Color, DVec2};

/// What a material slot's colour is at a surface point.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// The same colour everywhere.
    Constant(Color),
    /// Alternating squares in (u, v).
    Checker(Checker),
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

/// A checkerboard in texture space.
#[derive(Clone, Debug, PartialEq)]
pub struct Checker {
    /// Colour of the square containing (0, 0).
    pub even: Color,
    /// Colour of its neighbours.
    pub odd: Color,
    /// Side of one square, in (u, v) units (positive).
    pub size: f64,
}

impl Texture {
    /// The colour at texture coordinates `uv`.
    #[inline]
    pub fn at(&self, uv: DVec2) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checker(checker) => {
                let cell = (uv / checker.size).floor();
                // Cells are summed as floats: exact for any cell index a
                // render can reach (|index| < 2^52).
                if (cell.x + cell.y).rem_euclid(2.0) == 0.0 {
                    checker.even
                } else {
                    checker.odd
                }
            }
        }
    }

    /// True when the colour is zero everywhere (the slot can be skipped).
    pub fn is_black(&self) -> bool {
        match self {
            Texture::Constant(c) => *c == Color::ZERO,
            Texture::Checker(c) => c.even == Color::ZERO && c.odd == Color::ZERO,
        }
    }

    /// The largest component anywhere (bounds the slot's weight).
    pub fn max_component(&self) -> f64 {
        match self {
            Texture::Constant(c) => c.max_element(),
            Texture::Checker(c) => c.even.max_element().max(c.odd.max_element()),
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
