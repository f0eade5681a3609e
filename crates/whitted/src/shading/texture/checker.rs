//! A procedural checkerboard over (u, v).

use crate::shading::Color;

use crate::math::DVec2;

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

impl Checker {
    /// The colour of the square holding `uv`.
    #[inline]
    pub fn at(&self, uv: DVec2) -> Color {
        let cell = (uv / self.size).floor();
        // Cells are summed as floats: exact for any cell index a render can
        // reach (|index| < 2^52).
        if (cell.x + cell.y).rem_euclid(2.0) == 0.0 {
            self.even
        } else {
            self.odd
        }
    }
}
