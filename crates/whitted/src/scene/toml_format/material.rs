//! Materials: one table per material under `[materials]`, named by its key.
//!
//! ```toml
//! [materials.floor]
//! diffuse = { checker = { even = [1, 0, 0], odd = [1, 1, 0], size = 0.5 } }
//!
//! [materials.wood]                # paths are relative to the scene file
//! diffuse = { image = "textures/wood.png", wrap = "mirror", scale = [2, 2] }
//!
//! [materials.stone]               # a tangent-space normal map (OpenGL: green is up)
//! normal_map = { image = "textures/stone_normal.png", strength = 1, flip_green = false }
//!
//! [materials.plaster]             # or a height field, strength in scene units
//! bump_map = { image = "textures/plaster_height.png", scale = [4, 4], strength = 0.01 }
//!
//! [materials.leaves]             # a cut-out: clear where the image's alpha is 0
//! diffuse = { image = "textures/leaves.png" }
//! opacity = { image = "textures/leaves.png" }
//!
//! [materials.glass]
//! diffuse = 0.05                  # colour slots: [r, g, b], a grey, a checker or an image
//! specular = 0.8
//! shininess = 200
//! transmission = 0.9
//! ior = 1.5
//! fresnel = true
//! ```
//!
//! `diffuse` defaults to a 0.8 grey and `ambient` to the diffuse value; the
//! other colour slots default to black, `shininess` to 32, `ior` to 1 and
//! `fresnel` to false. A checker's `size` defaults to 1; an image's `wrap` to
//! `"repeat"` (or `"clamp"`, `"mirror"`), `scale` to `[1, 1]` and `offset` to
//! `[0, 0]`. A material takes a normal map or a bump map, not both; both
//! read their image as data (no sRGB curve) and place it like a colour
//! slot's; `strength` defaults to 1 and `flip_green` to false. `opacity`
//! (default 1) is a slot like the colour slots, each component at most 1;
//! its image is read as opacity (the alpha channel when there is one, else
//! the values as stored).

use toml_span::value::Value;

use super::reader::{Fields, Parsed, Reader, all};
use crate::math::{DVec2, magnitude};
use crate::shading::Bump;
use crate::shading::Color;
use crate::shading::Material;
use crate::shading::Texture;
use crate::shading::texture::{Checker, Decoding, ImageTexture, Wrap};

/// The keys of a material.
const KEYS: &[&str] = &[
    "ambient",
    "diffuse",
    "specular",
    "reflection",
    "transmission",
    "emission",
    "shininess",
    "ior",
    "fresnel",
    "normal_map",
    "bump_map",
    "opacity",
];

/// The materials of a scene, in the order they appear in the file.
pub(super) struct Materials {
    /// Every name, even of a material with errors, so that objects naming
    /// it are not reported as well.
    pub(super) names: Vec<String>,
    /// The materials, in the order of `names`.
    pub(super) list: Parsed<Vec<Material>>,
}

/// Reads the `[materials]` table, if any.
pub(super) fn read_materials(r: &mut Reader<'_>, value: Option<&Value<'_>>) -> Materials {
    let Some(value) = value else {
        return Materials {
            names: Vec::new(),
            list: Ok(Vec::new()),
        };
    };
    let table = match r.table(value, "materials", "[materials]") {
        Ok(table) => table,
        Err(reported) => {
            return Materials {
                names: Vec::new(),
                list: Err(reported),
            };
        }
    };
    let entries = table.entries_in_file_order();
    Materials {
        names: entries
            .iter()
            .map(|(key, _)| key.name.to_string())
            .collect(),
        list: all(entries
            .iter()
            .map(|(key, value)| read_material(r, value, &key.name))),
    }
}

fn read_material(r: &mut Reader<'_>, value: &Value<'_>, name: &str) -> Parsed<Material> {
    let f = r.table(value, name, format!("material `{name}`"))?;
    let keys = r.check_keys(&f, KEYS);
    let ambient = r.optional(&f, "ambient", texture);
    let diffuse = r.or_default(&f, "diffuse", Texture::Constant(Color::splat(0.8)), texture);
    let specular = r.or_default(&f, "specular", Texture::default(), texture);
    let reflection = r.or_default(&f, "reflection", Texture::default(), texture);
    let transmission = r.or_default(&f, "transmission", Texture::default(), texture);
    let emission = r.or_default(&f, "emission", Texture::default(), texture);
    let shininess = r.or_default(&f, "shininess", 32.0, Reader::non_negative);
    let ior = r.or_default(&f, "ior", 1.0, |r, value, key| {
        let ior = r.positive(value, key)?;
        r.divisor(value, key).map(|_| ior)
    });
    let fresnel = r.or_default(&f, "fresnel", false, Reader::boolean);
    let normal_map = r.optional(&f, "normal_map", normal_map);
    let bump_map = r.optional(&f, "bump_map", bump_map);
    let opacity = r.or_default(&f, "opacity", Texture::Constant(Color::ONE), opacity);
    let bump = match (f.get("normal_map"), f.get("bump_map")) {
        (Some(_), Some(second)) => Err(r.error(
            second.span,
            "a material takes `normal_map` or `bump_map`, not both",
        )),
        _ => Ok(normal_map?.or(bump_map?)),
    };
    keys?;
    let diffuse = diffuse?;
    Ok(Material {
        ambient: ambient?.unwrap_or_else(|| diffuse.clone()),
        diffuse,
        specular: specular?,
        shininess: shininess?,
        reflection: reflection?,
        transmission: transmission?,
        emission: emission?,
        ior: ior?,
        fresnel: fresnel?,
        bump: bump?,
        opacity: opacity?,
    })
}

/// A colour slot: a colour, `{ checker = { even, odd, size } }` or
/// `{ image = "file", wrap, scale, offset }`.
fn texture(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Texture> {
    let decoding = r.color_image_decoding();
    decoded_texture(r, value, key, decoding)
}

/// The opacity slot: like a colour slot, each component at most 1, an
/// image read as opacity.
fn opacity(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Texture> {
    let texture = decoded_texture(r, value, key, Decoding::Opacity)?;
    let largest = texture.max_component();
    if largest > 1.0 {
        let span = r.span_of(value);
        return Err(r.error(
            span,
            format!("`{key}` must be at most 1 in every component, got {largest}"),
        ));
    }
    Ok(texture)
}

/// A slot whose image is decoded as `decoding`.
fn decoded_texture(
    r: &mut Reader<'_>,
    value: &Value<'_>,
    key: &str,
    decoding: Decoding,
) -> Parsed<Texture> {
    if value.as_table().is_none() {
        if value.as_str().is_some() || value.as_bool().is_some() {
            return Err(r.wrong_type(
                value,
                key,
                "a colour ([r, g, b], a number, { checker = { ... } } or { image = \"...\" })",
            ));
        }
        return r.color(value, key).map(Texture::Constant);
    }
    let f = r.table(value, key, format!("`{key}`"))?;
    if f.get("image").is_some() {
        return image(r, &f, decoding);
    }
    let keys = r.check_keys(&f, &["checker", "image"]);
    let checker = r.require(&f, "checker", checker);
    keys?;
    checker
}

/// The keys placing an image.
const IMAGE_KEYS: [&str; 4] = ["image", "wrap", "scale", "offset"];

/// `{ image = "file", wrap = "repeat", scale = [su, sv], offset = [ou, ov] }`,
/// decoded as `decoding`.
fn image(r: &mut Reader<'_>, f: &Fields<'_, '_>, decoding: Decoding) -> Parsed<Texture> {
    let keys = r.check_keys(f, &IMAGE_KEYS);
    let image = placed_image(r, f, decoding);
    keys?;
    Ok(Texture::Image(image?))
}

/// The image of `f` decoded as `decoding`, placed by its `wrap`, `scale`
/// and `offset` (its keys are checked by the caller).
fn placed_image(
    r: &mut Reader<'_>,
    f: &Fields<'_, '_>,
    decoding: Decoding,
) -> Parsed<ImageTexture> {
    let data = r.require(f, "image", |r, value, key| {
        let (name, span) = r.string(value, key)?;
        r.image(name, span, decoding)
    });
    let wrap = r.or_default(f, "wrap", Wrap::Repeat, wrap);
    let scale = r.or_default(f, "scale", [1.0, 1.0], |r, v, k| {
        r.numbers::<2>(v, k, Reader::coordinate)
    });
    let offset = r.or_default(f, "offset", [0.0, 0.0], |r, v, k| {
        r.numbers::<2>(v, k, Reader::coordinate)
    });
    Ok(ImageTexture {
        data: data?,
        wrap: wrap?,
        scale: DVec2::from_array(scale?),
        offset: DVec2::from_array(offset?),
    })
}

/// `{ image = "file", wrap, scale, offset, strength = 1, flip_green = false }`.
fn normal_map(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Bump> {
    let f = r.table(value, key, format!("`{key}`"))?;
    let keys = r.check_keys(&f, &[&IMAGE_KEYS[..], &["strength", "flip_green"]].concat());
    let image = placed_image(r, &f, Decoding::Data);
    let strength = r.or_default(&f, "strength", 1.0, Reader::coordinate);
    let flip_green = r.or_default(&f, "flip_green", false, Reader::boolean);
    keys?;
    Ok(Bump::Normal {
        texture: Texture::Image(image?),
        strength: strength?,
        flip_green: flip_green?,
    })
}

/// `{ image = "file", wrap, scale, offset, strength = 1 }`.
fn bump_map(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Bump> {
    let f = r.table(value, key, format!("`{key}`"))?;
    let keys = r.check_keys(&f, &[&IMAGE_KEYS[..], &["strength"]].concat());
    let image = placed_image(r, &f, Decoding::Data);
    let strength = r.or_default(&f, "strength", 1.0, Reader::coordinate);
    keys?;
    Ok(Bump::Height {
        texture: Texture::Image(image?),
        strength: strength?,
    })
}

/// `"repeat"`, `"clamp"` or `"mirror"`.
fn wrap(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Wrap> {
    let (name, span) = r.string(value, key)?;
    match name {
        "repeat" => Ok(Wrap::Repeat),
        "clamp" => Ok(Wrap::Clamp),
        "mirror" => Ok(Wrap::Mirror),
        _ => Err(r.error(
            span,
            format!("unknown wrap mode `{name}`; expected one of: repeat, clamp, mirror"),
        )),
    }
}

/// `{ even = colour, odd = colour, size = s }`.
fn checker(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<Texture> {
    let f = r.table(value, key, "checker")?;
    let keys = r.check_keys(&f, &["even", "odd", "size"]);
    let even = r.require(&f, "even", Reader::color);
    let odd = r.require(&f, "odd", Reader::color);
    let size = r.or_default(&f, "size", 1.0, |r, value, key| {
        let size = r.positive(value, key)?;
        magnitude::length(size)
            .map_err(|error| r.error(value.span, format!("`{key}` is out of range: {error}")))
    });
    keys?;
    Ok(Texture::Checker(Checker {
        even: even?,
        odd: odd?,
        size: size?,
    }))
}

#[cfg(test)]
mod tests {
    use std::path::Path;
    use std::sync::Arc;

    use super::super::tests::{CAMERA, errors, scene};
    use super::*;
    use crate::scene::SceneError;

    #[test]
    fn defaults_are_a_matte_grey_with_ambient_following_diffuse() {
        let s = scene(&format!("{CAMERA}[materials.plain]\n"));
        assert_eq!(s.materials, [Material::default()]);
        let s = scene(&format!("{CAMERA}[materials.red]\ndiffuse = [1, 0, 0]\n"));
        assert_eq!(s.materials[0].ambient, Texture::Constant(Color::RED));
    }

    #[test]
    fn every_slot_is_read() {
        let s = scene(&format!(
            "{CAMERA}[materials.all]\nambient = 0.1\ndiffuse = [0.2, 0.3, 0.4]\nspecular = 0.5\n\
             reflection = 0.6\ntransmission = 0.7\nemission = [1, 2, 3]\nshininess = 100\n\
             ior = 1.33\nfresnel = true\nopacity = 0.5\n"
        ));
        assert_eq!(
            s.materials,
            [Material {
                ambient: Texture::Constant(Color::splat(0.1)),
                diffuse: Texture::Constant(Color::new(0.2, 0.3, 0.4)),
                specular: Texture::Constant(Color::splat(0.5)),
                shininess: 100.0,
                reflection: Texture::Constant(Color::splat(0.6)),
                transmission: Texture::Constant(Color::splat(0.7)),
                emission: Texture::Constant(Color::new(1.0, 2.0, 3.0)),
                ior: 1.33,
                fresnel: true,
                bump: None,
                opacity: Texture::Constant(Color::splat(0.5)),
            }]
        );
    }

    #[test]
    fn checker_slots_are_read_with_a_default_size() {
        let s = scene(&format!(
            "{CAMERA}[materials.floor]\n\
             diffuse = {{ checker = {{ even = [1, 0, 0], odd = 1 }} }}\n\
             [materials.floor.reflection.checker]\neven = 0\nodd = 0.5\nsize = 0.25\n"
        ));
        let m = &s.materials[0];
        assert_eq!(
            m.diffuse,
            Texture::Checker(Checker {
                even: Color::RED,
                odd: Color::ONE,
                size: 1.0,
            })
        );
        assert_eq!(m.ambient, m.diffuse);
        assert_eq!(
            m.reflection,
            Texture::Checker(Checker {
                even: Color::ZERO,
                odd: Color::splat(0.5),
                size: 0.25,
            })
        );
    }

    #[test]
    fn image_slots_are_read_relative_to_the_scene_and_decoded_once() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("textures")).unwrap();
        let png = crate::shading::texture::png_bytes(1, 1, &[255, 255, 255]);
        std::fs::write(dir.path().join("textures/white.png"), png).unwrap();
        let source = format!(
            "{CAMERA}[materials.a]\ndiffuse = {{ image = 'textures/white.png' }}\n\
             [materials.b]\nemission = {{ image = 'textures/./white.png', wrap = 'mirror', \
             scale = [2, 3], offset = [0.5, -1] }}\n"
        );
        let s = super::super::parse_scene(&source, &dir.path().join("s.toml")).unwrap();
        let (Texture::Image(a), Texture::Image(b)) =
            (&s.materials[0].diffuse, &s.materials[1].emission)
        else {
            panic!("not images: {:?}", s.materials);
        };
        assert!(Arc::ptr_eq(&a.data, &b.data));
        assert_eq!(
            (a.wrap, a.scale, a.offset),
            (Wrap::Repeat, DVec2::ONE, DVec2::ZERO)
        );
        assert_eq!(
            (b.wrap, b.scale, b.offset),
            (Wrap::Mirror, DVec2::new(2.0, 3.0), DVec2::new(0.5, -1.0))
        );
        assert_eq!(a.at(DVec2::splat(0.5)), Color::ONE);
    }

    #[test]
    fn a_large_texture_is_a_warning_where_it_is_first_named() {
        let dir = tempfile::tempdir().unwrap();
        let png = crate::shading::texture::png_bytes(4, 4, &[255; 48]);
        std::fs::write(dir.path().join("big.png"), png).unwrap();
        let source = format!(
            "{CAMERA}[materials.a]\ndiffuse = {{ image = 'big.png' }}\n\
             [materials.b]\nemission = {{ image = 'big.png' }}\n"
        );
        let path = dir.path().join("s.toml");
        let root = toml_span::parse(&source).unwrap();
        let warnings = |bytes: u64| {
            let mut reader = Reader::new(&source, &path).noting_images_above(bytes);
            let scene = super::super::read_document(&mut reader, &root);
            let (_, warnings) = reader.finish_with_warnings(scene).unwrap();
            warnings
                .iter()
                .map(|w| format!("{}:{}: {}", w.line, w.column, w.message))
                .collect::<Vec<_>>()
        };
        // 4x4 texels at 3 bytes and 4 for the mipmap: 112 bytes charged.
        assert_eq!(
            warnings(100),
            [
                "5:21: the image `big.png` takes 112 bytes as a texture (4x4 texels and their \
              mipmap): a smaller image would take less memory"
            ]
        );
        assert!(warnings(112).is_empty());
        let loaded = super::super::parse_scene_with_warnings(&source, &path).unwrap();
        assert!(loaded.warnings.is_empty());
    }

    #[test]
    fn a_display_scene_reads_colour_images_as_stored() {
        let dir = tempfile::tempdir().unwrap();
        let png = crate::shading::texture::png_bytes(1, 1, &[128, 128, 128]);
        std::fs::write(dir.path().join("grey.png"), png).unwrap();
        let texel = |colours: &str| {
            let source = format!(
                "{CAMERA}[render]\ncolours = '{colours}'\n\
                 [materials.a]\ndiffuse = {{ image = 'grey.png' }}\n"
            );
            let s = super::super::parse_scene(&source, &dir.path().join("s.toml")).unwrap();
            s.materials[0].diffuse.at(DVec2::splat(0.5)).r
        };
        assert!((texel("display") - 128.0 / 255.0).abs() < 1e-6);
        assert!((texel("linear") - 0.2158605).abs() < 1e-6);
    }

    #[test]
    fn a_missing_image_is_an_error_at_its_name() {
        let source = format!(
            "{CAMERA}[materials.a]\ndiffuse = {{ image = 'no/such.png', wrap = 'tile' }}\n"
        );
        let error = super::super::parse_scene(&source, Path::new("dir/s.toml")).unwrap_err();
        let SceneError::Invalid { diagnostics } = error else {
            panic!("{error}");
        };
        let text: Vec<String> = diagnostics.iter().map(ToString::to_string).collect();
        assert!(
            text[0].starts_with(
                "dir/s.toml:5:21: error: cannot read the image `dir/no/such.png`: \
                 No such file or directory (os error 2)"
            ),
            "{text:?}"
        );
        assert_eq!(
            diagnostics[1].message,
            "unknown wrap mode `tile`; expected one of: repeat, clamp, mirror"
        );
    }

    #[test]
    fn normal_and_bump_maps_are_read_as_data_with_their_options() {
        let dir = tempfile::tempdir().unwrap();
        let png = crate::shading::texture::png_bytes(1, 1, &[128, 128, 255]);
        std::fs::write(dir.path().join("n.png"), png).unwrap();
        let source = format!(
            "{CAMERA}[materials.a]\nnormal_map = {{ image = 'n.png', strength = 0.5, \
             flip_green = true, wrap = 'clamp' }}\n\
             [materials.b]\nbump_map = {{ image = 'n.png', scale = [2, 3], strength = 0.01 }}\n\
             [materials.c]\ndiffuse = {{ image = 'n.png' }}\n"
        );
        let s = super::super::parse_scene(&source, &dir.path().join("s.toml")).unwrap();
        let Some(Bump::Normal {
            texture: Texture::Image(normals),
            strength: 0.5,
            flip_green: true,
        }) = &s.materials[0].bump
        else {
            panic!("{:?}", s.materials[0].bump);
        };
        assert_eq!(normals.wrap, Wrap::Clamp);
        // Data: 128 is 128/255, not the sRGB-decoded 0.2158.
        let texel = normals.at(DVec2::splat(0.5));
        assert!((texel.r - 128.0 / 255.0).abs() < 1e-6, "{texel}");
        let Some(Bump::Height {
            texture: Texture::Image(heights),
            strength,
        }) = &s.materials[1].bump
        else {
            panic!("{:?}", s.materials[1].bump);
        };
        assert_eq!((heights.scale, *strength), (DVec2::new(2.0, 3.0), 0.01));
        assert!(Arc::ptr_eq(&normals.data, &heights.data));
        let Texture::Image(color) = &s.materials[2].diffuse else {
            panic!();
        };
        assert!(!Arc::ptr_eq(&color.data, &normals.data));
    }

    #[test]
    fn map_errors_are_located_and_both_maps_at_once_refused() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[materials.a]\nnormal_map = 'n.png'\n\
                 [materials.b]\nbump_map = {{ strength = 'high', flip_green = true }}\n\
                 [materials.c]\nnormal_map = {{ image = 1 }}\nbump_map = {{ image = 2 }}\n"
            )),
            [
                "expected a table for `normal_map`, found a string",
                "missing required key `image` in `bump_map`",
                "expected a number for `strength`, found a string",
                "unknown key `flip_green` in `bump_map`; expected one of: image, wrap, scale, \
                 offset, strength",
                "expected a string for `image`, found an integer",
                "a material takes `normal_map` or `bump_map`, not both",
                "expected a string for `image`, found an integer",
            ]
        );
    }

    #[test]
    fn materials_keep_the_order_of_the_file() {
        let s = scene(&format!(
            "{CAMERA}[materials.zinc]\nior = 2\n[materials.amber]\nior = 3\n"
        ));
        let iors: Vec<f64> = s.materials.iter().map(|m| m.ior).collect();
        assert_eq!(iors, [2.0, 3.0]);
    }

    #[test]
    fn every_material_error_is_reported() {
        assert_eq!(
            errors(&format!(
                "{CAMERA}[materials.bad]\ndiffuse = 'red'\nspecular = [1, 2]\nshininess = -1\n\
                 ior = 0\nfresnel = 1\nglow = 2\n\
                 [materials.worse]\nambient = {{ chequer = 1 }}\n\
                 emission = {{ checker = {{ even = 1, size = -2 }} }}\nopacity = [1, 2, 0.5]\n"
            )),
            [
                "expected a colour ([r, g, b], a number, { checker = { ... } } or \
                 { image = \"...\" }) for `diffuse`, found a string",
                "expected 3 numbers for `specular`, found 2",
                "`shininess` must not be negative, got -1",
                "`ior` must be greater than 0, got 0",
                "expected `true` or `false` for `fresnel`, found an integer",
                "unknown key `glow` in material `bad`; expected one of: ambient, diffuse, \
                 specular, reflection, transmission, emission, shininess, ior, fresnel, \
                 normal_map, bump_map, opacity",
                "missing required key `checker` in `ambient`",
                "unknown key `chequer` in `ambient`; expected one of: checker, image",
                "missing required key `odd` in checker",
                "`size` must be greater than 0, got -2",
                "`opacity` must be at most 1 in every component, got 2",
            ]
        );
        assert_eq!(
            errors(&format!("materials = [1]\n{CAMERA}")),
            ["expected a table for `materials`, found an array"]
        );
        assert_eq!(
            errors(&format!("{CAMERA}[materials]\nglass = 1.5\n")),
            ["expected a table for `glass`, found a float"]
        );
    }
}
