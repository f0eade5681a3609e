//! The `texture_filter` key of `[render]` (see
//! [`crate::shading::differential`]).
//!
//! ```toml
//! [render]
//! texture_filter = "mipmap"   # "none" (the default) or "mipmap"
//! ```

use super::reader::{Fields, Parsed, Reader};
use crate::shading::TextureFilter;
use toml_span::value::Value;

/// The key read here.
pub(super) const TEXTURE_FILTER_KEY: &str = "texture_filter";

/// The texture filter of a `[render]` table; none where the key is absent.
pub(super) fn read_texture_filter(r: &mut Reader<'_>, f: &Fields<'_, '_>) -> Parsed<TextureFilter> {
    r.or_default(f, TEXTURE_FILTER_KEY, TextureFilter::None, read_name)
}

/// A texture filter's name.
fn read_name(r: &mut Reader<'_>, value: &Value<'_>, key: &str) -> Parsed<TextureFilter> {
    let (name, span) = r.string(value, key)?;
    TextureFilter::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = TextureFilter::ALL.iter().map(|f| f.name()).collect();
        r.error(
            span,
            format!(
                "unknown texture filter `{name}` for `{key}`; expected one of: {}",
                names.join(", ")
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, errors, scene};
    use super::*;

    #[test]
    fn the_filter_is_read_and_defaults_to_none() {
        assert_eq!(scene(CAMERA).settings.texture_filter, TextureFilter::None);
        let s = scene(&format!("{CAMERA}[render]\ntexture_filter = 'mipmap'\n"));
        assert_eq!(s.settings.texture_filter, TextureFilter::Mipmap);
    }

    #[test]
    fn an_unknown_filter_names_the_known_ones() {
        assert_eq!(
            errors(&format!("{CAMERA}[render]\ntexture_filter = 'ewa'\n")),
            ["unknown texture filter `ewa` for `texture_filter`; expected one of: none, mipmap"]
        );
    }
}
