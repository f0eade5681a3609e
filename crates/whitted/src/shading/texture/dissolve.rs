//! A dissolve map (MTL `map_d`): the map gives the opacity per texel,
//! scaling the material's dissolve `d`. As a texture it is either that
//! opacity, `d · opacity(u, v)` in all three components (a material's
//! opacity), or what the opacity lets through, tinted by a filter colour,
//! `filter · (1 - d · opacity(u, v))` (the transmission of MTL glass,
//! illum 4).

use super::image::ImageTexture;
use super::luminance;
use crate::math::DVec2;
use crate::shading::Color;

/// A dissolve map, as an opacity or as a transmission.
#[derive(Clone, Debug, PartialEq)]
pub struct DissolveMap {
    /// Opacity per texel: the luminance of the image (decoded as opacity:
    /// its alpha channel when it has one).
    pub opacity: ImageTexture,
    /// The material's constant dissolve `d` in [0, 1], which the map scales.
    pub dissolve: f64,
    /// `None`: the texture is the opacity. `Some(filter)`: it is the light
    /// let through, tinted by `filter`.
    pub filter: Option<Color>,
}

impl DissolveMap {
    /// The opacity at texture coordinates `uv`, in [0, 1].
    pub fn opacity_at(&self, uv: DVec2) -> f64 {
        (self.dissolve * luminance(self.opacity.at(uv))).clamp(0.0, 1.0)
    }

    /// The opacity, or the light let through, at texture coordinates `uv`.
    pub fn at(&self, uv: DVec2) -> Color {
        self.value_for_opacity(self.opacity_at(uv))
    }

    /// The opacity, or the light let through, where the image's colour
    /// (filtered or not) is `image`.
    pub(super) fn value_for_image(&self, image: Color) -> Color {
        self.value_for_opacity((self.dissolve * luminance(image)).clamp(0.0, 1.0))
    }

    /// The texture's value where the opacity is `opacity`.
    fn value_for_opacity(&self, opacity: f64) -> Color {
        match self.filter {
            None => Color::splat(opacity),
            Some(filter) => filter * (1.0 - opacity),
        }
    }

    /// The largest component the texture takes anywhere, or a bound on it.
    pub fn max_component(&self) -> f64 {
        match self.filter {
            None => self.dissolve,
            Some(filter) => filter.max_element(),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::shading::texture::ImageData;

    #[test]
    fn the_map_scales_the_dissolve_per_texel() {
        let data = ImageData::new(2, 1, vec![[1.0; 3], [0.25; 3]]).unwrap();
        let map = DissolveMap {
            opacity: ImageTexture::new(Arc::new(data)),
            dissolve: 1.0,
            filter: None,
        };
        assert_eq!(map.at(DVec2::new(0.25, 0.5)), Color::ONE);
        assert_eq!(map.at(DVec2::new(0.75, 0.5)), Color::splat(0.25));
        let half = DissolveMap {
            dissolve: 0.5,
            ..map
        };
        assert_eq!(half.at(DVec2::new(0.25, 0.5)), Color::splat(0.5));
        assert_eq!(half.at(DVec2::new(0.75, 0.5)), Color::splat(0.125));
    }

    #[test]
    fn as_a_transmission_opaque_texels_block_and_clear_ones_let_the_filter_through() {
        let data = ImageData::new(2, 1, vec![[1.0; 3], [0.25; 3]]).unwrap();
        let map = DissolveMap {
            opacity: ImageTexture::new(Arc::new(data)),
            dissolve: 1.0,
            filter: Some(Color::new(1.0, 0.5, 0.0)),
        };
        assert_eq!(map.at(DVec2::new(0.25, 0.5)), Color::ZERO);
        assert_eq!(map.at(DVec2::new(0.75, 0.5)), Color::new(0.75, 0.375, 0.0));
        assert_eq!(map.max_component(), 1.0);
    }
}
