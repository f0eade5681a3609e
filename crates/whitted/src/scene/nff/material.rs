//! The `f` entity, the lights' default intensity and the ambient light: how
//! NFF's shading numbers become our Whitted/Phong materials.
//!
//! ```text
//! f R G B Kd Ks Shine T ior
//! ```
//!
//! | ours | from NFF |
//! |---|---|
//! | diffuse `kd` | `Kd · (R, G, B)` |
//! | ambient `ka` | `Kd · (R, G, B)`, lit by [`AMBIENT`] |
//! | specular `ks` | `Ks`, white |
//! | shininess `n` | `Shine` |
//! | reflection `kr` | `Ks`, white (Ks weights the mirror ray too) |
//! | transmission `kt` | `T`, white (not tinted by the colour) |
//! | ior | `ior` when `T > 0`; 1 otherwise (opaque files may put 0 there) |

use super::reader::{Parsed, Reader};
use crate::shading::Material;
use crate::shading::{Color, factor};

/// The global ambient light `Ia`, white: small, but present on every
/// surface, as the SPD asks (NFF itself has no ambient term).
pub(super) const AMBIENT: f64 = 0.1;

/// The intensity of each of `count` lights given without a colour:
/// `1 / sqrt(count)`, white, as the SPD's own POV-Ray export does, so that
/// more lights do not wash the picture out.
pub(super) fn default_light_intensity(count: usize) -> Color {
    Color::splat(1.0 / (count.max(1) as f64).sqrt())
}

/// The NFF surface numbers of an `f` entity, as written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Fill {
    /// Surface colour.
    pub(super) color: Color,
    /// Diffuse weight.
    pub(super) kd: f64,
    /// Specular weight: highlight and mirror ray.
    pub(super) ks: f64,
    /// Phong exponent.
    pub(super) shine: f64,
    /// Transmittance.
    pub(super) t: f64,
    /// Index of refraction.
    pub(super) ior: f64,
}

impl Fill {
    /// The Whitted/Phong material meaning the same.
    pub(super) fn material(&self) -> Material {
        let diffuse = self.color * self.kd;
        Material {
            ambient: diffuse.into(),
            diffuse: diffuse.into(),
            specular: Color::splat(self.ks).into(),
            shininess: self.shine,
            reflection: Color::splat(self.ks).into(),
            transmission: Color::splat(self.t).into(),
            emission: Color::ZERO.into(),
            ior: if self.t > 0.0 { self.ior } else { 1.0 },
            fresnel: false,
            bump: None,
            opacity: Color::ONE.into(),
        }
    }
}

/// Reads the numbers of an `f` entity.
pub(super) fn read_fill(r: &mut Reader<'_>) -> Parsed<Fill> {
    let color = r.color("the material's colour")?;
    let kd = weight(r, "Kd")?;
    let ks = weight(r, "Ks")?;
    let shine = weight(r, "Shine")?;
    let t = weight(r, "T")?;
    let ior_start = r.next_start();
    let ior = r.number("the material's index of refraction")?;
    if t > 0.0 && ior <= 0.0 {
        let span = r.since(ior_start);
        return Err(r.error(
            span,
            format!(
                "the index of refraction of a transparent material (T > 0) must be \
                 greater than 0, got {ior}"
            ),
        ));
    }
    if let Err(error) = factor::divisor(ior) {
        let span = r.since(ior_start);
        return Err(r.error(
            span,
            format!("the material's index of refraction is out of range: {error}"),
        ));
    }
    Ok(Fill {
        color,
        kd,
        ks,
        shine,
        t,
        ior,
    })
}

/// A number of the material that must not be negative, named `name`.
fn weight(r: &mut Reader<'_>, name: &str) -> Parsed<f64> {
    let start = r.next_start();
    let value = r.number(&format!("the material's {name}"))?;
    if value < 0.0 {
        let span = r.since(start);
        return Err(r.error(
            span,
            format!("the material's {name} must not be negative, got {value}"),
        ));
    }
    factor::factor(value).map_err(|error| {
        let span = r.since(start);
        r.error(
            span,
            format!("the material's {name} is out of range: {error}"),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn fill(text: &str) -> Parsed<Fill> {
        read_fill(&mut Reader::new(text, Path::new("t.nff")))
    }

    #[test]
    fn nff_numbers_become_whitted_weights() {
        let m = fill("1 0.5 0.25 0.8 0.3 20 0.6 1.5").unwrap().material();
        let diffuse = Color::new(0.8, 0.4, 0.2);
        assert_eq!(m.diffuse, diffuse.into());
        assert_eq!(m.ambient, diffuse.into());
        assert_eq!(m.specular, Color::splat(0.3).into());
        assert_eq!(m.reflection, Color::splat(0.3).into());
        assert_eq!(m.shininess, 20.0);
        assert_eq!(m.transmission, Color::splat(0.6).into());
        assert_eq!(m.ior, 1.5);
        assert!(!m.fresnel && m.emission.is_black());
    }

    #[test]
    fn an_opaque_material_ignores_its_index_of_refraction() {
        let m = fill("1 1 1 1 0 100000 0 0").unwrap().material();
        assert_eq!(m.ior, 1.0);
        assert!(m.reflection.is_black() && !m.is_transmissive());
        assert_eq!(m.shininess, 100000.0);
    }

    #[test]
    fn bad_weights_are_refused() {
        assert!(fill("1 1 1 -0.5 0 1 0 1").is_err());
        assert!(fill("1 1 1 1 0 1 0.5 0").is_err());
        assert!(fill("1 1 1 1 0 1 0.5").is_err());
    }

    #[test]
    fn lights_share_one_over_the_square_root_of_their_number() {
        assert_eq!(default_light_intensity(1), Color::ONE);
        assert_eq!(default_light_intensity(4), Color::splat(0.5));
        assert_eq!(default_light_intensity(0), Color::ONE);
    }
}
