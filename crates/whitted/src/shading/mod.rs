//! How surfaces and lights look: colours, materials (Phong coefficients,
//! mirror and glass, with textures, bump and normal maps), light sources,
//! and the optics of smooth surfaces (reflection, refraction, Fresnel) with
//! the media a refracted ray is inside. Materials can be evaluated for one
//! light and sampled for the ray or photon they scatter ([`scatter`]);
//! lights can be sampled from a point and can emit photons ([`emission`]).

pub mod area_light;
pub mod bump;
mod color;
pub mod differential;
pub mod emission;
pub mod factor;
pub mod light;
pub mod material;
pub mod medium;
pub mod optics;
pub mod scatter;
pub mod tangent_frame;
pub mod texture;

pub use area_light::{AreaLight, Emitter};
pub use bump::{Bump, shading_normal};
pub use color::Color;
pub use differential::{Footprint, RayDifferential, TextureFilter};
pub use emission::EmittedRay;
pub use light::{Attenuation, Light, LightSample, direct_samples};
pub use material::Material;
pub use medium::{Crossing, MediumStack};
pub use scatter::{Lobes, ScatterKind, ScatterSample, Weights, phong};
pub use texture::Texture;
