//! MTL material libraries: tobj reads the statements; we check the numbers
//! first (tobj's errors carry no place), read what tobj leaves aside (`Tf`,
//! `Tr`, texture maps), and map each material onto our Whitted material by
//! its `illum`.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use super::maps::{Channel, MapSlot, MapStatement, read_map};
use super::text::lines;
use crate::scene::{Diagnostic, Severity, push_limited, without_bom};
use crate::shading::Bump;
use crate::shading::Color;
use crate::shading::Material;
use crate::shading::Texture;
use crate::shading::factor::{self, FactorError};
use crate::shading::texture::{Decoding, DissolveMap, ImageCache, ImageData, ImageTexture};

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
    let source = without_bom(source);
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

/// Why the number `word` of a colour statement (`Kd`, `Ke` ...) or of `Ni`
/// is out of range for radiance, if it is: a colour component beyond
/// [`factor::MAX_FACTOR`] in magnitude, an index of refraction outside
/// [`factor::divisor`]'s range.
fn out_of_range(keyword: &str, word: &str) -> Option<FactorError> {
    let value = word.parse::<f64>().ok()?;
    if COLORS.contains(&keyword) {
        factor::factor(value).err()
    } else if keyword == "Ni" {
        factor::divisor(value).err()
    } else {
        None
    }
}

/// Why a number of `keyword` that is taken clamped (the dissolve `d` and
/// transparency `Tr` to 0 to 1, the exponent `Ns` to at least 1) is out of
/// its range, and what it is taken as; `None` within it. A negative `Ns`
/// only: 0 to 1 is the MTL's own range, read as 1.
fn clamped(keyword: &str, value: f64) -> Option<String> {
    let taken = match keyword {
        "d" | "Tr" if !(0.0..=1.0).contains(&value) => value.clamp(0.0, 1.0),
        "Ns" if value < 0.0 => 1.0,
        _ => return None,
    };
    let meaning = match (keyword, taken) {
        ("d", 0.0) | ("Tr", 1.0) => ": the surface is invisible",
        _ => "",
    };
    Some(format!(
        "`{keyword}` {value} is out of range ({}); taken as {taken}{meaning}",
        if keyword == "Ns" {
            "0 or more"
        } else {
            "0 to 1"
        }
    ))
}

fn is_error(d: &Diagnostic) -> bool {
    d.severity == crate::scene::Severity::Error
}

/// Every malformed number, with its place; a warning for the texture maps
/// we do not apply (all but those [`MapSlot::of`] knows).
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
            let problem = if COLORS.contains(&keyword) && word.parse::<f64>().is_ok_and(|v| v < 0.0)
            {
                Some(format!(
                    "the colour `{keyword}` must not be negative, got {word}"
                ))
            } else {
                out_of_range(keyword, word)
                    .map(|error| format!("`{keyword}` {word} is out of range: {error}"))
            };
            if ok && let Some(message) = word.parse::<f64>().ok().and_then(|v| clamped(keyword, v))
            {
                push_limited(&mut diagnostics, Severity::Warning, || {
                    Diagnostic::warning(path, source, span.clone(), message)
                });
            }
            if ok && let Some(message) = problem {
                push_limited(&mut diagnostics, Severity::Error, || {
                    Diagnostic::new(path, source, span, message)
                });
                found = wanted;
                break;
            }
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
            "{count} texture map{} in this library not applied: only `map_Ka`, `map_Kd`, \
             `map_Ks`, `map_d`, bump (`bump`, `map_Bump`) and normal (`norm`) maps are; \
             displacement, decal, reflection and other maps are ignored",
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
    dissolve: Option<ImageTexture>,
    bump: Option<Bump>,
}

/// How a map's file is decoded: colours as sRGB; a dissolve map as opacity
/// (alpha when the image has it) unless `-imfchan` says luminance; bump and
/// normal maps as data, a bump map's alpha with `-imfchan m`.
fn decoding(statement: &MapStatement) -> Decoding {
    match (statement.slot, statement.channel) {
        (MapSlot::Ambient | MapSlot::Diffuse | MapSlot::Specular, _) => Decoding::Color,
        (MapSlot::Dissolve, Channel::Default) | (_, Channel::Matte) => Decoding::Opacity,
        _ => Decoding::Data,
    }
}

/// True when an image read as data looks like a tangent-space normal map:
/// its mean texel is close to (0.5, 0.5, 1), a straight-up normal, and
/// bluer than it is red (no grey height map is). Exporters (Blender's among
/// them) write normal maps as `map_Bump`.
fn looks_like_normal_map(data: &ImageData) -> bool {
    let mean = data.mean();
    (mean.r - 0.5).abs() < 0.1 && (mean.g - 0.5).abs() < 0.1 && mean.b > 0.75
}

/// Decodes each map; a file that cannot be read is a warning and the
/// material does without the map.
fn load_maps(
    statements: &[MapStatement],
    images: &mut ImageCache,
    path: &Path,
    source: &str,
    diagnostics: &mut Vec<Diagnostic>,
) -> Maps {
    let mut maps = Maps::default();
    for statement in statements {
        for unknown in &statement.unknown_options {
            let taken = match unknown.arguments.as_str() {
                "" => String::new(),
                words => format!(" with `{words}`"),
            };
            let message = format!(
                "unknown texture map option `{}`; ignored{taken}, the file is `{}`",
                unknown.name,
                statement.file.display()
            );
            push_limited(diagnostics, Severity::Warning, || {
                Diagnostic::warning(path, source, unknown.span.clone(), message)
            });
        }
        // As the library writes it.
        let name = source.get(statement.span.clone()).unwrap_or_default();
        let data = match images.load_noting(&statement.file, name, decoding(statement)) {
            Ok((data, note)) => {
                if let Some(note) = note {
                    push_limited(diagnostics, Severity::Warning, || {
                        Diagnostic::warning(path, source, statement.span.clone(), note)
                    });
                }
                data
            }
            Err(error) => {
                let message = format!("{error}; {}", statement.slot.fallback());
                push_limited(diagnostics, Severity::Warning, || {
                    Diagnostic::warning(path, source, statement.span.clone(), message)
                });
                continue;
            }
        };
        let image = ImageTexture {
            data,
            wrap: statement.wrap,
            scale: statement.scale,
            offset: statement.offset,
        };
        let strength = statement.bump_multiplier;
        match statement.slot {
            MapSlot::Ambient => maps.ambient = Some(Texture::Image(image)),
            MapSlot::Diffuse => maps.diffuse = Some(Texture::Image(image)),
            MapSlot::Specular => maps.specular = Some(Texture::Image(image)),
            MapSlot::Dissolve => maps.dissolve = Some(image),
            MapSlot::Bump if !looks_like_normal_map(&image.data) => {
                maps.bump = Some(Bump::Height {
                    texture: Texture::Image(image),
                    strength,
                });
            }
            MapSlot::Bump | MapSlot::Normal => {
                maps.bump = Some(Bump::Normal {
                    texture: Texture::Image(image),
                    strength,
                    flip_green: false,
                });
            }
        }
    }
    maps
}

fn color(c: Option<[f64; 3]>, default: Color) -> Color {
    c.map_or(default, Color::from)
}

/// Our material for an MTL material, by its illumination model (see
/// `docs/obj.md`); a colour map replaces the constant colour of its slot, a
/// dissolve map scales `d` per texel, a bump or normal map tilts the
/// shading normal.
///
/// The dissolve `d` (or `1 - Tr`, times the dissolve map) is the opacity of
/// every model but 4: the surface's own light and mirror fade with it and
/// what is behind shows through. Model 4, the MTL's glass, keeps its
/// highlights and reflection whatever the dissolve, so there `d` sets the
/// transmission instead: `Tf (1 - d)`, straight through.
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
    // `d`, per texel with a dissolve map.
    let opacity = match &maps.dissolve {
        Some(opacity) => Texture::Dissolve(DissolveMap {
            opacity: opacity.clone(),
            dissolve,
            filter: None,
        }),
        None => Color::splat(dissolve).into(),
    };
    let mut material = Material {
        ambient: ka,
        diffuse: kd_map.clone(),
        specular: Color::ZERO.into(),
        shininess: m.shininess.unwrap_or(32.0).max(1.0),
        reflection: Color::ZERO.into(),
        transmission: Color::ZERO.into(),
        emission: ke.into(),
        ior: 1.0,
        fresnel: false,
        bump: maps.bump.clone(),
        opacity,
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
        material.transmission = match &maps.dissolve {
            Some(opacity) => Texture::Dissolve(DissolveMap {
                opacity: opacity.clone(),
                dissolve,
                filter: Some(filter),
            }),
            None => (filter * (1.0 - dissolve)).into(),
        };
        material.opacity = Color::ONE.into();
    }
    if matches!(illum, 6 | 7) {
        // Glass: its own transmission is `Tf`, or clear when neither `Tf`
        // nor a dissolve says otherwise; a dissolve without `Tf` is all the
        // light it lets through.
        let dissolved = dissolve < 1.0 || maps.dissolve.is_some();
        material.transmission = match extra.transmission_filter {
            Some(filter) => filter.into(),
            None if dissolved => Color::ZERO.into(),
            None => Color::ONE.into(),
        };
        material.ior = m.optical_density.filter(|n| *n > 0.0).unwrap_or(1.0);
        material.fresnel = illum == 7;
    }
    material
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec2;
    use crate::shading::Texture;

    fn read(source: &str) -> Library {
        read_library(source, Path::new("m.mtl"), &mut ImageCache::default())
    }

    #[test]
    fn dissolves_and_exponents_out_of_range_are_warned_and_clamped() {
        let lib =
            read("newmtl a\nd -1\nNs -5\nnewmtl b\nTr 2\nnewmtl c\nd 2\nNs 0\nnewmtl d\nTr -0.5\n");
        let text: Vec<String> = lib.diagnostics.iter().map(ToString::to_string).collect();
        let firsts: Vec<&str> = text.iter().map(|t| t.lines().next().unwrap()).collect();
        assert_eq!(
            firsts,
            [
                "m.mtl:2:3: warning: `d` -1 is out of range (0 to 1); taken as 0: the surface \
                 is invisible",
                "m.mtl:3:4: warning: `Ns` -5 is out of range (0 or more); taken as 1",
                "m.mtl:5:4: warning: `Tr` 2 is out of range (0 to 1); taken as 1: the surface \
                 is invisible",
                "m.mtl:7:3: warning: `d` 2 is out of range (0 to 1); taken as 1",
                "m.mtl:10:4: warning: `Tr` -0.5 is out of range (0 to 1); taken as 0",
            ]
        );
        let m = &lib.materials;
        assert_eq!(m["a"].opacity, Texture::Constant(Color::ZERO));
        assert_eq!(m["a"].shininess, 1.0);
        assert_eq!(m["b"].opacity, Texture::Constant(Color::ZERO));
        assert_eq!(m["c"].opacity, Texture::Constant(Color::ONE));
        assert_eq!(m["d"].opacity, Texture::Constant(Color::ONE));
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
        assert_eq!(glass.opacity, Texture::Constant(Color::ONE));
        // A dissolve is an opacity, not a transmission.
        assert_eq!(m["half"].opacity, Texture::Constant(Color::splat(0.75)));
        assert!(m["half"].transmission.is_black());
    }

    #[test]
    fn glass_keeps_its_transmission_and_a_dissolve_fades_the_rest() {
        let lib = read(
            "newmtl clear\nKs 0.1 0.1 0.1\nNi 1.5\nillum 7\n\
             newmtl blender glass\nd 0.2\nNi 1.45\nillum 6\n\
             newmtl tinted\nTf 0.5 1 1\nd 0.5\nillum 6\n\
             newmtl old glass\nTf 0.5 1 1\nd 0.5\nillum 4\n",
        );
        assert!(lib.diagnostics.is_empty(), "{:?}", lib.diagnostics);
        let m = &lib.materials;
        let constant = |c: Color| Texture::Constant(c);
        let clear = &m["clear"];
        assert_eq!(
            (&clear.transmission, &clear.opacity),
            (&constant(Color::ONE), &constant(Color::ONE))
        );
        // Without `Tf`, the dissolve is all the glass lets through (as it
        // was before dissolve faded the surface): 1 - 0.2.
        let blender = &m["blender glass"];
        assert_eq!(blender.opacity, constant(Color::splat(0.2)));
        assert!(blender.transmission.is_black());
        assert_eq!(blender.pass_through(DVec2::ZERO), Color::splat(0.8));
        assert_eq!(blender.ior, 1.45);
        let tinted = &m["tinted"];
        assert_eq!(tinted.transmission, constant(Color::new(0.5, 1.0, 1.0)));
        assert_eq!(tinted.pass_through(DVec2::ZERO), Color::new(0.75, 1.0, 1.0));
        // Model 4 is not dissolved: `d` sets its transmission.
        let old = &m["old glass"];
        assert_eq!(old.opacity, constant(Color::ONE));
        assert_eq!(old.transmission, constant(Color::new(0.25, 0.5, 0.5)));
    }

    #[test]
    fn maps_fill_their_slots_and_one_file_is_shared() {
        let dir = tempfile::tempdir().unwrap();
        let png = crate::shading::texture::png_bytes(1, 1, &[255, 0, 0]);
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
    fn a_large_texture_is_noted_once_where_it_is_first_named() {
        let dir = tempfile::tempdir().unwrap();
        let png = crate::shading::texture::png_bytes(4, 4, &[255; 48]);
        std::fs::write(dir.path().join("big.png"), png).unwrap();
        let source = "newmtl a\nmap_Kd big.png\nnewmtl b\nmap_Kd big.png\n";
        // 4x4 texels at 3 bytes and 4 for the mipmap: 112 bytes charged.
        let mut images = ImageCache::noting_above(100);
        let lib = read_library(source, &dir.path().join("m.mtl"), &mut images);
        let notes: Vec<_> = lib
            .diagnostics
            .iter()
            .map(|d| (d.line, &d.message))
            .collect();
        assert_eq!(
            notes,
            [(
                2,
                &"the image `big.png` takes 112 bytes as a texture (4x4 texels and their \
                  mipmap): a smaller image would take less memory"
                    .to_string()
            )]
        );
        assert!(
            lib.diagnostics
                .iter()
                .all(|d| d.severity == Severity::Warning)
        );
        let mut images = ImageCache::noting_above(112);
        let lib = read_library(source, &dir.path().join("m.mtl"), &mut images);
        assert!(lib.diagnostics.is_empty(), "{:?}", lib.diagnostics);
    }

    #[test]
    fn dissolve_bump_and_normal_maps_are_applied_with_their_options() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, bytes: Vec<u8>| std::fs::write(dir.path().join(name), bytes);
        // Left texel clear (alpha 0), right texel opaque.
        write(
            "leaf.png",
            crate::shading::texture::rgba_png_bytes(2, 1, &[0, 255, 0, 0, 0, 255, 0, 255]),
        )
        .unwrap();
        write(
            "height.png",
            crate::shading::texture::png_bytes(2, 1, &[0, 0, 0, 255, 255, 255]),
        )
        .unwrap();
        write(
            "normal.png",
            crate::shading::texture::png_bytes(1, 1, &[128, 128, 255]),
        )
        .unwrap();
        let source = "newmtl leaf\nKd 0 1 0\nmap_d -s 2 1 leaf.png\nbump -bm 0.05 height.png\n\
                      newmtl tiles\nmap_Bump -bm 0.5 normal.png\n\
                      newmtl wall\nnorm -clamp on normal.png\n\
                      newmtl glass\nillum 4\nTf 1 0.5 0.5\nd 0.5\nmap_d -imfchan l height.png\n";
        let lib = read_library(
            source,
            &dir.path().join("m.mtl"),
            &mut ImageCache::default(),
        );
        assert!(lib.diagnostics.is_empty(), "{:?}", lib.diagnostics);
        let m = &lib.materials;
        let Texture::Dissolve(leaf) = &m["leaf"].opacity else {
            panic!("{:?}", m["leaf"].opacity);
        };
        assert_eq!((leaf.dissolve, leaf.filter), (1.0, None));
        assert_eq!(leaf.opacity.scale, DVec2::new(2.0, 1.0));
        let at = |u| m["leaf"].opacity.at(DVec2::new(u, 0.5));
        assert_eq!((at(0.125), at(0.375)), (Color::ZERO, Color::ONE));
        assert!(m["leaf"].transmission.is_black());
        assert!(matches!(
            m["leaf"].bump,
            Some(Bump::Height { strength: 0.05, .. })
        ));
        let Some(Bump::Normal { strength: 0.5, .. }) = m["tiles"].bump else {
            panic!("a bluish map_Bump is a normal map: {:?}", m["tiles"].bump);
        };
        let Some(Bump::Normal {
            texture: Texture::Image(wall),
            strength: 1.0,
            flip_green: false,
        }) = &m["wall"].bump
        else {
            panic!("{:?}", m["wall"].bump);
        };
        assert_eq!(wall.wrap, crate::shading::texture::Wrap::Clamp);
        let glass = &m["glass"].transmission;
        let (clear, opaque) = (
            glass.at(crate::math::DVec2::new(0.25, 0.5)),
            glass.at(crate::math::DVec2::new(0.75, 0.5)),
        );
        assert_eq!(clear, Color::new(1.0, 0.5, 0.5));
        assert!(
            (opaque - Color::new(0.5, 0.25, 0.25)).abs().max_element() < 1e-12,
            "{opaque}"
        );
    }

    #[test]
    fn missing_dissolve_and_bump_files_are_warnings_and_the_material_does_without() {
        let lib = read("newmtl a\nd 0.75\nmap_d none.png\nmap_Bump -bm 2 flat.png\n");
        let text: Vec<String> = lib.diagnostics.iter().map(ToString::to_string).collect();
        assert_eq!(text.len(), 2, "{text:?}");
        assert!(
            text[0].starts_with("m.mtl:3:7: warning: cannot read the image `none.png`")
                && text[0].contains("; `d` keeps its constant value"),
            "{}",
            text[0]
        );
        assert!(
            text[1].starts_with("m.mtl:4:16: warning: cannot read the image `flat.png`")
                && text[1].contains("; the surface is shaded without it"),
            "{}",
            text[1]
        );
        let a = &lib.materials["a"];
        assert_eq!(a.opacity, Texture::Constant(Color::splat(0.75)));
        assert_eq!(a.bump, None);
    }

    #[test]
    fn negative_colours_are_refused_at_their_place() {
        let lib = read("newmtl a\nKa 0 0 0\nKd -1 -1 -1\nKs 0 -0.5 0\nKe 0 0 -2\nTf -0 0 -1e-9\n");
        let text: Vec<String> = lib.diagnostics.iter().map(ToString::to_string).collect();
        let firsts: Vec<&str> = text.iter().filter_map(|t| t.lines().next()).collect();
        assert_eq!(
            firsts,
            [
                "m.mtl:3:4: error: the colour `Kd` must not be negative, got -1",
                "m.mtl:4:6: error: the colour `Ks` must not be negative, got -0.5",
                "m.mtl:5:8: error: the colour `Ke` must not be negative, got -2",
                "m.mtl:6:9: error: the colour `Tf` must not be negative, got -1e-9",
            ]
        );
        assert!(lib.materials.is_empty());
    }

    #[test]
    fn an_unknown_map_option_is_warned_about_by_name() {
        let lib = read("newmtl a\nmap_Kd -colorspace sRGB -halo 3 -o 0.1 diffuse.jpg\n");
        let text: Vec<&str> = lib.diagnostics.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(text.len(), 2, "{text:?}");
        assert_eq!(
            text[0],
            "unknown texture map option `-halo`; ignored with `3`, the file is `diffuse.jpg`"
        );
        assert!(text[1].starts_with("cannot read the image `diffuse.jpg`"));
        assert_eq!(lib.diagnostics[0].column, 25);
    }

    #[test]
    fn bad_numbers_are_located_and_texture_maps_warned_about() {
        let lib = read("newmtl a\nKd 1 x 0\ndisp wood.png\nNs\n");
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
