//! Lights: one `[[lights]]` table each, its `type` saying which kind.
//!
//! ```toml
//! [[lights]]
//! type = "point"
//! position = [5, 8, -5]
//! intensity = [1, 1, 0.9]         # a colour or a number; default 1
//! attenuation = [1, 0, 0.01]      # [constant, linear, quadratic]; default [1, 0, 0]
//!
//! [[lights]]
//! type = "directional"
//! direction = [-1, -1, 0]         # the way the light travels
//! intensity = 0.5
//!
//! [[lights]]
//! type = "spot"
//! position = [0, 5, 0]
//! direction = [0, -1, 0]          # the cone's axis
//! angle = 30                      # half-angle of the cone, degrees, in (0, 90]
//! falloff = 4                     # Warn exponent, default 0
//! ```
//!
//! Directions are normalised; a zero direction is an error. Area lights
//! (`rect`, `disk`, `sphere`) are read in `area_light.rs`.

use toml_span::Span;
use toml_span::value::Value;

use super::area_light::{AREA_KINDS, read_area_light};
use super::reader::{Parsed, Reader, all, list};
use crate::shading::Color;
use crate::shading::{Attenuation, Light};

/// The kinds of light, as written in `type`, each with its keys.
const KINDS: &[(&str, &[&str])] = &[
    ("point", &["type", "position", "intensity", "attenuation"]),
    ("directional", &["type", "direction", "intensity"]),
    (
        "spot",
        &[
            "type",
            "position",
            "direction",
            "intensity",
            "attenuation",
            "angle",
            "falloff",
        ],
    ),
    AREA_KINDS[0],
    AREA_KINDS[1],
    AREA_KINDS[2],
];

/// Reads the `[[lights]]` array, if any.
pub(super) fn read_lights(r: &mut Reader<'_>, value: Option<&Value<'_>>) -> Parsed<Vec<Light>> {
    let Some(value) = value else {
        return Ok(Vec::new());
    };
    let lights = r.array(value, "lights", "an array of tables ([[lights]])")?;
    all(lights.iter().map(|light| read_light(r, light)))
}

fn read_light(r: &mut Reader<'_>, value: &Value<'_>) -> Parsed<Light> {
    let mut f = r.table(value, "lights", "light")?;
    let kind = r
        .require(&f, "type", Reader::string)
        .and_then(|(name, span)| find_kind(r, name, span));
    let intensity = r.or_default(&f, "intensity", Color::ONE, Reader::color);
    let (kind, keys) = match kind {
        Ok(kind) => kind,
        Err(reported) => {
            let keys_of_kinds: Vec<&[&str]> = KINDS.iter().map(|(_, keys)| *keys).collect();
            r.check_keys_of_any_kind(&f, &keys_of_kinds, "light types")?;
            return Err(reported);
        }
    };
    f.rename(format!("{kind} light"));
    let keys = r.check_keys(&f, keys);
    let light = match kind {
        "point" => {
            let position = r.require(&f, "position", Reader::vec3);
            let attenuation = r.or_default(&f, "attenuation", Attenuation::NONE, attenuation);
            Light::Point {
                position: position?,
                intensity: intensity?,
                attenuation: attenuation?,
            }
        }
        "rect" | "disk" | "sphere" => {
            let light = read_area_light(r, &f, kind);
            keys?;
            return light;
        }
        "directional" => {
            let direction = r.require(&f, "direction", Reader::direction);
            Light::Directional {
                direction: direction?,
                intensity: intensity?,
            }
        }
        _ => {
            let position = r.require(&f, "position", Reader::vec3);
            let direction = r.require(&f, "direction", Reader::direction);
            let attenuation = r.or_default(&f, "attenuation", Attenuation::NONE, attenuation);
            let angle = r.require(&f, "angle", cone_angle);
            let falloff = r.or_default(&f, "falloff", 0.0, Reader::non_negative);
            Light::Spot {
                position: position?,
                direction: direction?,
                intensity: intensity?,
                cos_cutoff: angle?.to_radians().cos(),
                falloff: falloff?,
                attenuation: attenuation?,
            }
        }
    };
    keys?;
    Ok(light)
}

/// The kind of light called `name`, written at `span`, and its keys.
fn find_kind(
    r: &mut Reader<'_>,
    name: &str,
    span: Span,
) -> Parsed<(&'static str, &'static [&'static str])> {
    KINDS
        .iter()
        .find(|(kind, _)| *kind == name)
        .copied()
        .ok_or_else(|| {
            let names: Vec<&str> = KINDS.iter().map(|(kind, _)| *kind).collect();
            r.error(
                span,
                format!(
                    "unknown light type `{name}`; expected one of: {}",
                    list(&names)
                ),
            )
        })
}

/// `[constant, linear, quadratic]`, none negative, not all zero, each a
/// [`Reader::divisor`] (the light is divided by their sum).
fn attenuation(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Attenuation> {
    let [constant, linear, quadratic] = r.numbers::<3>(value, key, Reader::divisor)?;
    if constant + linear + quadratic == 0.0 {
        return Err(r.error(
            value.span,
            format!("`{key}` needs a positive term; [0, 0, 0] would put the light out"),
        ));
    }
    Ok(Attenuation {
        constant,
        linear,
        quadratic,
    })
}

/// A spot light's half-angle in degrees, in (0, 90].
fn cone_angle(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<f64> {
    let angle = r.number(value, key)?;
    if angle > 0.0 && angle <= 90.0 {
        Ok(angle)
    } else {
        Err(r.error(
            value.span,
            format!("`{key}` must be greater than 0 and at most 90 degrees, got {angle}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, errors, scene};
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn point_lights_are_read_with_defaults() {
        let s = scene(&format!(
            "{CAMERA}[[lights]]\ntype = 'point'\nposition = [1, 2, 3]\n\
             [[lights]]\ntype = 'point'\nposition = [0, 0, 0]\nintensity = 2\n\
             attenuation = [0, 0.5, 1]\n"
        ));
        assert_eq!(
            s.lights,
            [
                Light::Point {
                    position: Vec3::new(1.0, 2.0, 3.0),
                    intensity: Color::ONE,
                    attenuation: Attenuation::NONE,
                },
                Light::Point {
                    position: Vec3::ZERO,
                    intensity: Color::splat(2.0),
                    attenuation: Attenuation {
                        constant: 0.0,
                        linear: 0.5,
                        quadratic: 1.0,
                    },
                },
            ]
        );
    }

    #[test]
    fn directional_lights_have_their_direction_normalised() {
        let s = scene(&format!(
            "{CAMERA}[[lights]]\ntype = 'directional'\ndirection = [0, -3, 0]\n\
             intensity = [1, 0.5, 0]\n"
        ));
        assert_eq!(
            s.lights,
            [Light::Directional {
                direction: -Vec3::Y,
                intensity: Color::new(1.0, 0.5, 0.0),
            }]
        );
    }

    #[test]
    fn spot_lights_store_the_cosine_of_their_angle() {
        let s = scene(&format!(
            "{CAMERA}[[lights]]\ntype = 'spot'\nposition = [0, 5, 0]\ndirection = [0, -2, 0]\n\
             angle = 60\nfalloff = 3\n"
        ));
        let [
            Light::Spot {
                position,
                direction,
                intensity,
                cos_cutoff,
                falloff,
                attenuation,
            },
        ] = s.lights.as_slice()
        else {
            panic!("{:?}", s.lights);
        };
        assert_eq!(
            (*position, *direction),
            (Vec3::new(0.0, 5.0, 0.0), -Vec3::Y)
        );
        assert_eq!(*intensity, Color::ONE);
        assert!((cos_cutoff - 0.5).abs() < 1e-12);
        assert_eq!(*falloff, 3.0);
        assert_eq!(*attenuation, Attenuation::NONE);
    }

    #[test]
    fn every_light_error_is_reported() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[lights]]\nposition = [0, 0, 0]\ncolour = 3\nfoo = 1\n\
                 [[lights]]\ntype = 'sun'\nangle = 10\nintensity = -1\nsize = 2\n\
                 [[lights]]\ntype = 'point'\npositon = [0, 0, 0]\nattenuation = [0, 0, 0]\n\
                 [[lights]]\ntype = 'directional'\ndirection = [0, 0, 0]\nangle = 3\n\
                 [[lights]]\ntype = 'spot'\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n\
                 angle = 95\nfalloff = -1\n"
            )),
            [
                "missing required key `type` in light",
                "unknown key `colour` in light; none of the light types has it; expected one \
                 of: type, position, intensity, attenuation, direction, angle, falloff, origin, \
                 edge_u, edge_v, radiance, power, samples, center, normal, radius",
                "unknown key `foo` in light; none of the light types has it; expected one \
                 of: type, position, intensity, attenuation, direction, angle, falloff, origin, \
                 edge_u, edge_v, radiance, power, samples, center, normal, radius",
                "unknown light type `sun`; expected one of: point, directional, spot, rect, disk, \
                 sphere",
                "`intensity` must not be negative, got -1",
                "unknown key `size` in light; none of the light types has it; expected one \
                 of: type, position, intensity, attenuation, direction, angle, falloff, origin, \
                 edge_u, edge_v, radiance, power, samples, center, normal, radius",
                "missing required key `position` in point light",
                "unknown key `positon` in point light; expected one of: type, position, \
                 intensity, attenuation",
                "`attenuation` needs a positive term; [0, 0, 0] would put the light out",
                "`direction` must not be the zero vector",
                "unknown key `angle` in directional light; expected one of: type, direction, \
                 intensity",
                "`angle` must be greater than 0 and at most 90 degrees, got 95",
                "`falloff` must not be negative, got -1",
            ]
        );
        assert_eq!(
            errors(&format!("{CAMERA}[lights]\ntype = 'point'\n")),
            ["expected an array of tables ([[lights]]) for `lights`, found a table"]
        );
    }
}
