//! What a scene's colour values mean, and how a value becomes an 8-bit
//! code in a PNG.
//!
//! Our own formats describe light: a colour is linear (twice the value is
//! twice the light), and a PNG gets the sRGB transfer curve. The SPD's NFF
//! files come from renderers that shaded display values as they were and
//! wrote them as they were; their colours are read that way so the
//! pictures look as those renderers (and POV-Ray) show them.
//!
//! Scene syntax: `[render] colours = "linear"` (the default) or
//! `colours = "display"`.

/// The meaning of a scene's colour values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// Values are linear light; an 8-bit code is the value through the sRGB
    /// curve.
    #[default]
    Linear,
    /// Values are what the display shows (sRGB-encoded, as a 1980s
    /// renderer or a colour picker gives them): shaded as they are, and
    /// an 8-bit code is the value scaled to 0–255.
    Display,
}

impl ColorSpace {
    /// Every colour space.
    pub const ALL: [ColorSpace; 2] = [ColorSpace::Linear, ColorSpace::Display];

    /// The name used in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            ColorSpace::Linear => "linear",
            ColorSpace::Display => "display",
        }
    }

    /// The colour space called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The 8-bit code of a value in this colour space (clamped to [0, 1];
    /// NaN becomes 0).
    pub fn encode8(self, value: f32) -> u8 {
        match self {
            ColorSpace::Linear => encode_srgb8(value),
            ColorSpace::Display => encode_display8(value),
        }
    }
}

/// A value in [0, 1] (clamped; NaN becomes 0).
fn unit(value: f32) -> f32 {
    if value.is_nan() {
        0.0
    } else {
        value.clamp(0.0, 1.0)
    }
}

/// A value scaled to 0–255 and rounded to the nearest code.
fn to_code(unit: f32) -> u8 {
    (unit * 255.0 + 0.5) as u8
}

/// A linear value as an 8-bit sRGB code (clamped; NaN becomes 0).
pub fn encode_srgb8(linear: f32) -> u8 {
    let v = unit(linear);
    let encoded = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    to_code(encoded)
}

/// A display value as an 8-bit code, with no transfer curve (clamped; NaN
/// becomes 0).
pub fn encode_display8(display: f32) -> u8 {
    to_code(unit(display))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encoding_matches_known_codes() {
        assert_eq!(encode_srgb8(0.0), 0);
        assert_eq!(encode_srgb8(1.0), 255);
        assert_eq!(encode_srgb8(2.0), 255);
        assert_eq!(encode_srgb8(-1.0), 0);
        assert_eq!(encode_srgb8(f32::NAN), 0);
        assert_eq!(encode_srgb8(0.5), 188);
        assert_eq!(encode_srgb8(0.2159), 128);
    }

    #[test]
    fn display_values_are_scaled_without_a_curve_like_pov_ray_writes_them() {
        // The SPD's background `b 0.078 0.361 0.753`, as POV-Ray 3.7 writes it.
        let codes = [0.078, 0.361, 0.753].map(encode_display8);
        assert_eq!(codes, [20, 92, 192]);
        assert_eq!(encode_display8(0.5), 128);
        assert_eq!(encode_display8(2.0), 255);
        assert_eq!(encode_display8(-1.0), 0);
        assert_eq!(encode_display8(f32::NAN), 0);
    }

    #[test]
    fn each_space_encodes_with_its_own_rule_and_is_found_by_name() {
        assert_eq!(ColorSpace::Linear.encode8(0.5), 188);
        assert_eq!(ColorSpace::Display.encode8(0.5), 128);
        for space in ColorSpace::ALL {
            assert_eq!(ColorSpace::from_name(space.name()), Some(space));
        }
        assert_eq!(ColorSpace::from_name("srgb"), None);
        assert_eq!(ColorSpace::default(), ColorSpace::Linear);
    }
}
