//! The transmission of a dissolve map (MTL `map_d`): the map gives the
//! opacity per texel, scaling the material's dissolve `d`, and what is not
//! opaque lets light through, tinted by a filter colour:
//! `filter · (1 - d · opacity(u, v))`.

use super::image::ImageTexture;
use super::luminance;
use crate::math::{Color, DVec2};

/// A dissolve map, as a transmission.
#[derive(Clone, Debug, PartialEq)]
pub struct DissolveMap {
    /// Opacity per texel: the luminance of the image (decoded as opacity:
    /// its alpha channel when it has one).
    pub opacity: ImageTexture,
    /// The material's constant dissolve `d` in [0, 1], which the map scales.
    pub dissolve: f64,
    /// The colour of the light let through (white, or MTL `Tf`).
    pub filter: Color,
}

impl DissolveMap {
    /// The transmission at texture coordinates `uv`.
    pub fn at(&self, uv: DVec2) -> Color {
        let opacity = (self.dissolve * luminance(self.opacity.at(uv))).clamp(0.0, 1.0);
        self.filter * (1.0 - opacity)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::texture::ImageData;

    #[test]
    fn opaque_texels_block_and_clear_ones_let_the_filter_through() {
        let data = ImageData::new(2, 1, vec![[1.0; 3], [0.25; 3]]).unwrap();
        let map = DissolveMap {
            opacity: ImageTexture::new(Arc::new(data)),
            dissolve: 1.0,
            filter: Color::new(1.0, 0.5, 0.0),
        };
        assert_eq!(map.at(DVec2::new(0.25, 0.5)), Color::ZERO);
        assert_eq!(map.at(DVec2::new(0.75, 0.5)), Color::new(0.75, 0.375, 0.0));
        let half = DissolveMap {
            dissolve: 0.5,
            ..map
        };
        assert_eq!(half.at(DVec2::new(0.25, 0.5)), Color::new(0.5, 0.25, 0.0));
    }
}
