//! Area lights in `[[lights]]`: `type = "rect"`, `"disk"` or `"sphere"`.
//!
//! ```toml
//! [[lights]]
//! type = "rect"
//! origin = [-1, 4, -1]            # one corner
//! edge_u = [2, 0, 0]              # emits towards edge_u × edge_v
//! edge_v = [0, 0, 2]
//! radiance = [4, 4, 3.6]          # or power = ...; exactly one of them
//! samples = 16                    # shadow rays per shaded point; default 16
//!
//! [[lights]]
//! type = "disk"
//! center = [0, 4, 0]
//! normal = [0, -1, 0]             # the side that emits
//! radius = 1
//! power = 40                      # flux; radiance = power / (π · area)
//!
//! [[lights]]
//! type = "sphere"                 # emits all round
//! center = [0, 4, 0]
//! radius = 0.5
//! radiance = 2
//! ```

use super::reader::{Fields, Parsed, Reader};
use crate::math::Vec3;
use crate::shading::{AreaLight, Color, Emitter, Light};

/// Shadow rays per shaded point when `samples` is not given.
pub(super) const DEFAULT_SAMPLES: u32 = 16;

/// The most `samples` a light may ask for.
const MAX_SAMPLES: u32 = 65_536;

/// The keys every area light has beside those of its shape.
macro_rules! area_keys {
    ($($key:literal),*) => {
        &["type", $($key,)* "radiance", "power", "samples"]
    };
}

/// The kinds of area light and their keys.
pub(super) const AREA_KINDS: &[(&str, &[&str])] = &[
    ("rect", area_keys!("origin", "edge_u", "edge_v")),
    ("disk", area_keys!("center", "normal", "radius")),
    ("sphere", area_keys!("center", "radius")),
];

/// Reads an area light of `kind` (one of [`AREA_KINDS`]) from `f`.
pub(super) fn read_area_light(r: &mut Reader<'_>, f: &Fields<'_, '_>, kind: &str) -> Parsed<Light> {
    let emitter = match kind {
        "rect" => {
            let origin = r.require(f, "origin", Reader::vec3);
            let edge_u = r.require(f, "edge_u", Reader::vec3);
            let edge_v = r.require(f, "edge_v", Reader::vec3);
            Emitter::Rect {
                corner: origin?,
                edge_u: edge_u?,
                edge_v: edge_v?,
            }
        }
        "disk" => {
            let center = r.require(f, "center", Reader::vec3);
            let normal = r.require(f, "normal", Reader::direction);
            let radius = r.require(f, "radius", Reader::positive);
            Emitter::Disk {
                center: center?,
                normal: normal?,
                radius: radius?,
            }
        }
        _ => {
            let center = r.require(f, "center", Reader::vec3);
            let radius = r.require(f, "radius", Reader::positive);
            Emitter::Sphere {
                center: center?,
                radius: radius?,
            }
        }
    };
    let radiance = r.optional(f, "radiance", Reader::color);
    let power = r.optional(f, "power", Reader::color);
    let samples = r.or_default(f, "samples", DEFAULT_SAMPLES, |r, value, key| {
        r.count(value, key, 1, MAX_SAMPLES)
    });
    let radiance = match (radiance?, power?) {
        (Some(radiance), None) => radiance,
        (None, Some(power)) => AreaLight::radiance_for_power(&emitter, power),
        (given, _) => {
            let both = given.is_some();
            let span = if both {
                r.value_span(f, "power")
            } else {
                f.span()
            };
            let message = if both {
                format!("{kind} light: give `radiance` or `power`, not both")
            } else {
                format!("{kind} light: missing `radiance` or `power` (how bright it is)")
            };
            return Err(r.error(span, message));
        }
    };
    let light = AreaLight {
        emitter,
        radiance,
        samples: samples?,
    };
    // Refuse a degenerate shape here, where the message can be placed.
    if let Err(error) = light.glowing_shape() {
        let span = f.span();
        return Err(r.error(span, format!("{kind} light: {error}")));
    }
    if !finite(light.power()) {
        let span = r.value_span(f, "radiance");
        return Err(r.error(span, format!("{kind} light: its power is too large")));
    }
    Ok(Light::Area(light))
}

fn finite(c: Color) -> bool {
    Vec3::new(c.r, c.g, c.b).is_finite()
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::super::tests::{CAMERA, errors, scene};
    use super::*;

    #[test]
    fn each_kind_is_read_with_its_glowing_shape() {
        let s = scene(&format!(
            "{CAMERA}[[lights]]\ntype = 'rect'\norigin = [0, 2, 0]\nedge_u = [1, 0, 0]\n\
             edge_v = [0, 0, 1]\nradiance = [1, 2, 3]\nsamples = 4\n\
             [[lights]]\ntype = 'disk'\ncenter = [0, 3, 0]\nnormal = [0, -2, 0]\nradius = 0.5\n\
             power = 2\n\
             [[lights]]\ntype = 'sphere'\ncenter = [1, 1, 1]\nradius = 0.25\nradiance = 1\n"
        ));
        assert_eq!(s.lights.len(), 3);
        assert_eq!(s.objects.primitives.len(), 3);
        let Light::Area(rect) = &s.lights[0] else {
            panic!("{:?}", s.lights[0]);
        };
        assert_eq!(rect.radiance, Color::new(1.0, 2.0, 3.0));
        assert_eq!(rect.samples, 4);
        let Light::Area(disk) = &s.lights[1] else {
            panic!("{:?}", s.lights[1]);
        };
        assert_eq!(disk.samples, DEFAULT_SAMPLES);
        assert!((disk.power().r - 2.0).abs() < 1e-12);
        assert_eq!(
            disk.emitter,
            Emitter::Disk {
                center: Vec3::new(0.0, 3.0, 0.0),
                normal: -Vec3::Y,
                radius: 0.5
            }
        );
        // The glowing shapes emit π L and nothing else.
        let glow = &s.materials[s.objects.primitives[2].material.0 as usize];
        assert_eq!(glow.emission, Color::splat(PI).into());
        assert!(glow.diffuse.is_black() && glow.ambient.is_black());
    }

    #[test]
    fn brightness_is_radiance_or_power_and_shapes_must_have_an_area() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[lights]]\ntype = 'sphere'\ncenter = [0, 0, 0]\nradius = 1\n\
                 radiance = 1\npower = 2\n\
                 [[lights]]\ntype = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 1, 0]\nradius = 1\n\
                 [[lights]]\ntype = 'rect'\norigin = [0, 0, 0]\nedge_u = [1, 0, 0]\n\
                 edge_v = [2, 0, 0]\nradiance = 1\nsamples = 0\nintensity = 1\n"
            )),
            vec![
                "sphere light: give `radiance` or `power`, not both",
                "disk light: missing `radiance` or `power` (how bright it is)",
                "`samples` must be at least 1, got 0",
                "unknown key `intensity` in rect light; expected one of: \
                 type, origin, edge_u, edge_v, radiance, power, samples",
            ]
        );
        assert_eq!(
            errors(&format!(
                "{CAMERA}[[lights]]\ntype = 'rect'\norigin = [0, 0, 0]\nedge_u = [1, 0, 0]\n\
                 edge_v = [2, 0, 0]\nradiance = 1\n"
            )),
            vec!["rect light: degenerate parallelogram: its edges are parallel or of zero length"]
        );
    }
}
