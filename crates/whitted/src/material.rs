//! Whitted/Phong materials.
//!
//! The colour leaving a surface point towards the viewer is
//!
//! ```text
//! I = ke + ka·Ia + Σ_lights f_att · S · I_light · (kd (N·L) + ks (R·V)^n)
//!       + kr · I(reflected) + kt · I(refracted)
//! ```
//!
//! With `fresnel = true`, the transmission `kt` is split by Schlick's
//! approximation `F`: the refracted ray gets `kt (1 - F)` and the reflected
//! ray gets `kr + kt F`. Without it, total internal reflection alone moves the
//! refracted weight `kt` onto the reflected ray.

use crate::bump::Bump;
use crate::texture::Texture;

/// Index of a material in [`crate::scene::Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);

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
}

impl Default for Material {
    /// A matte mid-grey.
    fn default() -> Self {
        let grey = Texture::Constant(crate::math::Color::splat(0.8));
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
        }
    }
}

impl Material {
    /// True when shadow rays can pass through this surface.
    pub fn is_transmissive(&self) -> bool {
        !self.transmission.is_black()
    }
}
