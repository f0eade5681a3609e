//! Whitted/Phong materials.
//!
//! The colour leaving a surface point towards the viewer is
//!
//! ```text
//! I = α (ke + ka·Ia + Σ_lights f_att · S · I_light · (kd (N·L) + ks (R·V)^n))
//!       + α kr · I(reflected) + (α kt + 1 - α) · I(refracted)
//! ```
//!
//! The opacity `α` dissolves the surface: its own light and mirror
//! reflection are weighted by `α`, and what is behind shows through by
//! `1 - α`, on the refracted ray: straight on only when `ior` is 1, bent
//! (or moved onto the mirror ray by total internal reflection) by a glass's
//! index otherwise. An opaque
//! surface (`α` = 1, the default) is the plain Whitted model; a clear one
//! (`α` = 0) is invisible. A shadow ray crossing the surface keeps
//! `α kt + 1 - α` of the light.
//!
//! With `fresnel = true`, the transmission `kt` is split by Schlick's
//! approximation `F`: the refracted ray gets `α kt (1 - F) + 1 - α` and the
//! reflected ray gets `α (kr + kt F)`. Without it, total internal reflection
//! alone moves the refracted weight onto the reflected ray.

use crate::math::DVec2;
use crate::shading::Bump;
use crate::shading::Color;
use crate::shading::Texture;

/// A Whitted/Phong surface description.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// `ka`: how much of the ambient light is returned.
    pub ambient: Texture,
    /// `kd`: Lambertian reflection of direct light.
    pub diffuse: Texture,
    /// `ks`: Phong highlight strength.
    pub specular: Texture,
    /// `n`: Phong exponent (highlight sharpness).
    pub shininess: f64,
    /// `kr`: weight of the mirror-reflected ray.
    pub reflection: Texture,
    /// `kt`: weight of the refracted ray; also how much light a shadow ray
    /// lets through this surface.
    pub transmission: Texture,
    /// `ke`: light the surface emits itself.
    pub emission: Texture,
    /// Index of refraction of the material's inside.
    pub ior: f64,
    /// Split the transmission `kt` by Schlick's Fresnel term `F`: `kt (1 - F)`
    /// to the refracted ray, `kr + kt F` to the reflected one.
    pub fresnel: bool,
    /// A bump or normal map tilting the shading normal `N`, if any.
    pub bump: Option<Bump>,
    /// `α`: how much of the surface is there, per component in [0, 1]; the
    /// rest is dissolved and shows what is behind it.
    pub opacity: Texture,
}

impl Default for Material {
    /// A matte mid-grey.
    fn default() -> Self {
        let grey = Texture::Constant(Color::splat(0.8));
        Self {
            ambient: grey.clone(),
            diffuse: grey,
            specular: Texture::default(),
            shininess: 32.0,
            reflection: Texture::default(),
            transmission: Texture::default(),
            emission: Texture::default(),
            ior: 1.0,
            fresnel: false,
            bump: None,
            opacity: Texture::Constant(Color::ONE),
        }
    }
}

impl Material {
    /// True when shadow rays can pass through this surface: it transmits,
    /// or it may be dissolved somewhere.
    pub fn is_transmissive(&self) -> bool {
        !self.transmission.is_black() || !self.opacity.is_white()
    }

    /// True when shading this material reads the surface's (u, v) or
    /// tangents: a texture that is not one colour, or a bump or normal map.
    pub fn reads_uv(&self) -> bool {
        self.bump.is_some()
            || [
                &self.ambient,
                &self.diffuse,
                &self.specular,
                &self.reflection,
                &self.transmission,
                &self.emission,
                &self.opacity,
            ]
            .into_iter()
            .any(|t| !matches!(t, Texture::Constant(_)))
    }

    /// How much light passes through the surface at `uv` (a shadow ray's
    /// factor): `α kt + 1 - α`.
    pub fn pass_through(&self, uv: DVec2) -> Color {
        let alpha = self.opacity.at(uv);
        alpha * self.transmission.at(uv) + (Color::ONE - alpha)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dissolving_lets_light_through_beside_the_surface_own_transmission() {
        let glass = Material {
            transmission: Color::splat(0.5).into(),
            ..Material::default()
        };
        let uv = DVec2::ZERO;
        assert_eq!(glass.pass_through(uv), Color::splat(0.5));
        let half = Material {
            opacity: Color::splat(0.5).into(),
            ..glass
        };
        assert_eq!(half.pass_through(uv), Color::splat(0.75));
        assert!(half.is_transmissive());
        let opaque = Material::default();
        assert_eq!(opaque.pass_through(uv), Color::ZERO);
        assert!(!opaque.is_transmissive());
        assert!(!opaque.reads_uv());
        let clear = Material {
            opacity: Color::ZERO.into(),
            ..opaque
        };
        assert_eq!(clear.pass_through(uv), Color::ONE);
        assert!(clear.is_transmissive());
    }
}
