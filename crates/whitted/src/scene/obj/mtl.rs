//! MTL material libraries: tobj reads the statements; we check the numbers
//! first (tobj's errors carry no place), read what tobj leaves aside (`Tf`,
//! `Tr`, texture maps), and map each material onto our Whitted material by
//! its `illum`.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use super::maps::{MapSlot, MapStatement, read_map};
use super::text::lines;
use crate::material::Material;
use crate::math::Color;
use crate::scene::{Diagnostic, Severity, push_limited};
use crate::texture::{ImageCache, ImageTexture, Texture};

/// The materials of one library by name, or its errors; with its warnings.
pub(super) struct Library {
    pub(super) materials: HashMap<String, Material>,
    pub(super) diagnostics: Vec<Diagnostic>,
}

/// Statements taking colours (three numbers) and single numbers.
const COLORS: &[&str] = &["Ka", "Kd", "Ks", "Ke", "Tf"];
const NUMBERS: &[&str] = &["Ns", "Ni", "d", "Tr", "illum", "sharpness"];

/// Reads the library text `source`, named `path` in messages; its texture
/// maps are looked for beside it and decoded through `images`.
pub(super) fn read_library(source: &str, path: &Path, images: &mut ImageCache) -> Library {
    let mut diagnostics = check(source, path);
    if diagnostics.iter().any(is_error) {
        return Library {
            materials: HashMap::new(),
            diagnostics,
        };
    }
    let mut materials = HashMap::new();
    match tobj::load_mtl_buf(&mut source.as_bytes()) {
        Ok((parsed, _)) => {
            let extras = extras(source, path.parent().unwrap_or(Path::new("")));
            for m in parsed {
                let extra = extras.get(&m.name).cloned().unwrap_or_default();
                let maps = load_maps(&extra.maps, images, path, source, &mut diagnostics);
                materials.insert(m.name.clone(), whitted_material(&m, &extra, &maps));
            }
        }
        Err(error) => diagnostics.push(Diagnostic::new(
            path,
            source,
            0..0,
            format!("cannot read the material library: {error}"),
        )),
    }
    Library {
        materials,
        diagnostics,
    }
}

fn is_error(d: &Diagnostic) -> bool {
    d.severity == crate::scene::Severity::Error
}

/// Every malformed number, with its place; a warning for the texture maps
/// we do not apply (all but `map_Ka`, `map_Kd` and `map_Ks`).
fn check(source: &str, path: &Path) -> Vec<Diagnostic> {
    let mut diagnostics = Vec::new();
    let mut maps: Option<(Range<usize>, usize)> = None;
    for line in lines(source) {
        let mut words = line.words();
        let Some((keyword, at)) = words.next() else {
            continue;
        };
        let wanted = if COLORS.contains(&keyword) {
            3
        } else if NUMBERS.contains(&keyword) {
            1
        } else {
            let map =
                keyword.starts_with("map_") || ["bump", "disp", "decal", "refl"].contains(&keyword);
            if map && MapSlot::of(keyword).is_none() {
                maps.get_or_insert((at, 0)).1 += 1;
            }
            continue;
        };
        let mut found = 0;
        for (word, span) in words.take(wanted) {
            let ok = if keyword == "illum" {
                word.parse::<u8>().is_ok_and(|i| i <= 10)
            } else {
                word.parse::<f64>().is_ok_and(f64::is_finite)
            };
            if !ok {
                let what = if keyword == "illum" {
                    "an illumination model 0 to 10"
                } else {
                    "a number"
                };
                push_limited(&mut diagnostics, Severity::Error, || {
                    Diagnostic::new(
                        path,
                        source,
                        span,
                        format!("expected {what} after `{keyword}`, found `{word}`"),
                    )
                });
                found = wanted;
                break;
            }
            found += 1;
        }
        if found < wanted {
            let message = format!(
                "`{keyword}` needs {wanted} number{}",
                if wanted == 1 { "" } else { "s" }
            );
            push_limited(&mut diagnostics, Severity::Error, || {
                Diagnostic::new(path, source, at, message)
            });
        }
    }
    if let Some((at, count)) = maps {
        let message = format!(
            "{count} texture map{} in this library not applied: only `map_Ka`, `map_Kd` \
             and `map_Ks` are; bump, normal, dissolve and other maps are ignored",
            if count == 1 { "" } else { "s" }
        );
        diagnostics.push(Diagnostic::warning(path, source, at, message));
    }
    diagnostics
}

/// `Tf`, `Tr` and the texture maps, which tobj keeps as text, by material
/// name.
#[derive(Clone, Debug, Default)]
struct Extra {
    transmission_filter: Option<Color>,
    transparency: Option<f64>,
    maps: Vec<MapStatement>,
}

fn extras(source: &str, folder: &Path) -> HashMap<String, Extra> {
    let mut extras: HashMap<String, Extra> = HashMap::new();
    let mut current = String::new();
    for line in lines(source) {
        let mut words = line.words();
        let Some((keyword, _)) = words.next() else {
            continue;
        };
        let numbers: Vec<f64> = words.filter_map(|(w, _)| w.parse().ok()).collect();
        match (keyword, numbers.as_slice()) {
            ("newmtl", _) => current = line.rest().0.to_string(),
            ("Tf", &[r, g, b, ..]) => {
                extras
                    .entry(current.clone())
                    .or_default()
                    .transmission_filter = Some(Color::new(r, g, b));
            }
            ("Tr", &[tr, ..]) => extras.entry(current.clone()).or_default().transparency = Some(tr),
            _ => {
                if let Some(map) = read_map(line, folder) {
                    extras.entry(current.clone()).or_default().maps.push(map);
                }
            }
        }
    }
    extras
}

/// The textures of a material's maps, by slot.
#[derive(Clone, Debug, Default)]
struct Maps {
    ambient: Option<Texture>,
    diffuse: Option<Texture>,
    specular: Option<Texture>,
}

/// Decodes each map; a file that cannot be read is a warning and its slot
/// keeps its constant colour.
fn load_maps(
    statements: &[MapStatement],
    images: &mut ImageCache,
    path: &Path,
    source: &str,
    diagnostics: &mut Vec<Diagnostic>,
) -> Maps {
    let mut maps = Maps::default();
    for statement in statements {
        let data = match images.load(&statement.file) {
            Ok(data) => data,
            Err(error) => {
                let message = format!(
                    "{error}; `{}` keeps its constant colour",
                    statement.slot.color_name()
                );
                push_limited(diagnostics, Severity::Warning, || {
                    Diagnostic::warning(path, source, statement.span.clone(), message)
                });
                continue;
            }
        };
        let texture = Texture::Image(ImageTexture {
            data,
            wrap: statement.wrap,
            scale: statement.scale,
            offset: statement.offset,
        });
        let slot = match statement.slot {
            MapSlot::Ambient => &mut maps.ambient,
            MapSlot::Diffuse => &mut maps.diffuse,
            MapSlot::Specular => &mut maps.specular,
        };
        *slot = Some(texture);
    }
    maps
}

fn color(c: Option<[f64; 3]>, default: Color) -> Color {
    c.map_or(default, Color::from)
}

/// Our material for an MTL material, by its illumination model (see
/// `docs/obj.md`); a map replaces the constant colour of its slot.
fn whitted_material(m: &tobj::Material, extra: &Extra, maps: &Maps) -> Material {
    let kd = color(m.diffuse, Color::splat(0.8));
    let ke = color(m.emissive, Color::ZERO);
    let kd_map = maps.diffuse.clone().unwrap_or(Texture::Constant(kd));
    let ka = maps
        .ambient
        .clone()
        .unwrap_or(Texture::Constant(color(m.ambient, Color::ZERO)));
    let ks = maps
        .specular
        .clone()
        .unwrap_or(Texture::Constant(color(m.specular, Color::ZERO)));
    let dissolve = m
        .dissolve
        .or(extra.transparency.map(|tr| 1.0 - tr))
        .unwrap_or(1.0)
        .clamp(0.0, 1.0);
    let illum = m.illumination_model.unwrap_or(2);
    let mut material = Material {
        ambient: ka,
        diffuse: kd_map.clone(),
        specular: Color::ZERO.into(),
        shininess: m.shininess.unwrap_or(32.0).max(1.0),
        reflection: Color::ZERO.into(),
        transmission: Color::splat(1.0 - dissolve).into(),
        emission: ke.into(),
        ior: 1.0,
        fresnel: false,
    };
    if illum == 0 {
        material.ambient = Color::ZERO.into();
        material.diffuse = Color::ZERO.into();
        material.emission = match maps.diffuse {
            Some(_) => kd_map,
            None => (kd + ke).into(),
        };
    }
    if illum >= 2 {
        material.specular = ks.clone();
    }
    if (3..=7).contains(&illum) {
        material.reflection = ks;
    }
    if illum == 4 {
        let filter = extra.transmission_filter.unwrap_or(Color::ONE);
        material.transmission = (filter * (1.0 - dissolve)).into();
    }
    if matches!(illum, 6 | 7) {
        let fallback = if dissolve < 1.0 {
            Color::splat(1.0 - dissolve)
        } else {
            Color::ONE
        };
        material.transmission = extra.transmission_filter.unwrap_or(fallback).into();
        material.ior = m.optical_density.filter(|n| *n > 0.0).unwrap_or(1.0);
        material.fresnel = illum == 7;
    }
    material
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Texture;

    fn read(source: &str) -> Library {
        read_library(source, Path::new("m.mtl"), &mut ImageCache::default())
    }

    #[test]
    fn illum_models_map_onto_our_material() {
        let lib = read(
            "newmtl flat\nKd 1 0 0\nillum 0\n\
             newmtl matte\nKa 0.1 0.1 0.1\nKd 0 1 0\nKs 1 1 1\nillum 1\n\
             newmtl mirror\nKs 0.5 0.5 0.5\nNs 200\nillum 3\n\
             newmtl dark glass\nKs 1 1 1\nTf 0.9 0.8 0.7\nNi 1.5\nillum 7\n\
             newmtl half\nTr 0.25\nillum 2\n",
        );
        assert!(lib.diagnostics.is_empty(), "{:?}", lib.diagnostics);
        let m = &lib.materials;
        assert_eq!(
            m["flat"].emission,
            Texture::Constant(Color::new(1.0, 0.0, 0.0))
        );
        assert!(m["flat"].diffuse.is_black());
        assert!(m["matte"].specular.is_black() && m["matte"].reflection.is_black());
        assert_eq!(m["mirror"].reflection, Texture::Constant(Color::splat(0.5)));
        assert_eq!(m["mirror"].shininess, 200.0);
        let glass = &m["dark glass"];
        assert_eq!(
            glass.transmission,
            Texture::Constant(Color::new(0.9, 0.8, 0.7))
        );
        assert!(glass.fresnel && glass.ior == 1.5);
        assert_eq!(
            m["half"].transmission,
            Texture::Constant(Color::splat(0.25))
        );
    }

    #[test]
    fn maps_fill_their_slots_and_one_file_is_shared() {
        let dir = tempfile::tempdir().unwrap();
        let png = crate::texture::png_bytes(1, 1, &[255, 0, 0]);
        std::fs::write(dir.path().join("red.png"), png).unwrap();
        let source = "newmtl shiny\nKs 0.5 0.5 0.5\nillum 3\nmap_Ks -o 0.5 0.25 red.png\n\
                      map_Ka red.png\nnewmtl lamp\nillum 0\nmap_Kd .\\red.png\n";
        let mut images = ImageCache::default();
        let lib = read_library(source, &dir.path().join("m.mtl"), &mut images);
        assert!(lib.diagnostics.is_empty(), "{:?}", lib.diagnostics);
        let shiny = &lib.materials["shiny"];
        let Texture::Image(ks) = &shiny.specular else {
            panic!("{:?}", shiny.specular);
        };
        assert_eq!(ks.offset, crate::math::DVec2::new(0.5, 0.25));
        assert_eq!(shiny.reflection, shiny.specular);
        assert!(matches!(shiny.ambient, Texture::Image(_)));
        let Texture::Image(lamp) = &lib.materials["lamp"].emission else {
            panic!("the lamp's map is not its emission");
        };
        assert!(std::sync::Arc::ptr_eq(&ks.data, &lamp.data));
        assert_eq!(images.len(), 1);
    }

    #[test]
    fn bad_numbers_are_located_and_texture_maps_warned_about() {
        let lib = read("newmtl a\nKd 1 x 0\nmap_d wood.png\nNs\n");
        let text: Vec<String> = lib.diagnostics.iter().map(ToString::to_string).collect();
        assert!(
            text[0].starts_with("m.mtl:2:6: error: expected a number after `Kd`, found `x`"),
            "{}",
            text[0]
        );
        assert!(
            text[1].starts_with("m.mtl:4:1: error: `Ns` needs 1 number"),
            "{}",
            text[1]
        );
        assert!(
            text[2].starts_with("m.mtl:3:1: warning: 1 texture map in this library"),
            "{}",
            text[2]
        );
    }
}
