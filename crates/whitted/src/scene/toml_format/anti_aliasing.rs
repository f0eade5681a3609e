//! The anti-aliasing keys of `[render]`: `aa`, `aa_threshold`,
//! `aa_depth` and `aa_min_depth` (see [`crate::render::AntiAliasing`]).
//!
//! ```toml
//! [render]
//! aa = "adaptive"      # or "stratified" (the default: `samples` per pixel)
//! aa_threshold = 0.1   # subdivide where corners differ by more (default 0.3)
//! aa_depth = 3         # halve a pixel at most this often (default 3, at most 6)
//! aa_min_depth = 1     # halve it this often whatever the corners (default 0)
//! ```

use super::reader::{Fields, Parsed, Reader, list};
use crate::render::{Adaptive, AntiAliasing, MAX_AA_DEPTH};

/// The keys read here.
pub(super) const AA_KEYS: [&str; 4] = ["aa", "aa_threshold", "aa_depth", "aa_min_depth"];

/// The anti-aliasing of a `[render]` table: stratified unless `aa` says
/// otherwise; the threshold and depth only with `aa = "adaptive"`.
pub(super) fn read_anti_aliasing(r: &mut Reader<'_>, f: &Fields<'_, '_>) -> Parsed<AntiAliasing> {
    let method = r.or_default(f, "aa", AntiAliasing::Stratified, |r, v, k| {
        let (name, span) = r.string(v, k)?;
        AntiAliasing::from_name(name).ok_or_else(|| {
            let message = format!(
                "unknown anti-aliasing `{name}` for `{k}`; expected one of: {}",
                list(&AntiAliasing::NAMES)
            );
            r.error(span, message)
        })
    });
    let d = Adaptive::default();
    let threshold = r.or_default(f, "aa_threshold", d.threshold, Reader::non_negative);
    let depth = r.or_default(f, "aa_depth", d.depth, |r, v, k| {
        r.count(v, k, 0, MAX_AA_DEPTH)
    });
    let min_depth = r.or_default(f, "aa_min_depth", d.min_depth, |r, v, k| {
        r.count(v, k, 0, MAX_AA_DEPTH)
    });
    let method = method?;
    let (threshold, depth, min_depth) = (threshold?, depth?, min_depth?);
    if method == AntiAliasing::Stratified {
        for key in &AA_KEYS[1..] {
            if f.get(key).is_some() {
                let span = r.value_span(f, key);
                return Err(r.error(
                    span,
                    format!(
                        "`{key}` applies only to adaptive anti-aliasing; add aa = \"adaptive\""
                    ),
                ));
            }
        }
        return Ok(method);
    }
    if min_depth > depth {
        let span = r.value_span(f, "aa_min_depth");
        return Err(r.error(
            span,
            format!("`aa_min_depth` must be at most `aa_depth` ({depth}), got {min_depth}"),
        ));
    }
    Ok(AntiAliasing::Adaptive(Adaptive {
        threshold,
        depth,
        min_depth,
    }))
}

#[cfg(test)]
mod tests {
    use super::super::tests::{CAMERA, errors, scene};
    use super::*;

    #[test]
    fn anti_aliasing_keys_are_read_and_default_to_stratified() {
        assert_eq!(scene(CAMERA).settings.aa, AntiAliasing::Stratified);
        let aa = |keys: &str| scene(&format!("{CAMERA}[render]\n{keys}")).settings.aa;
        assert_eq!(aa("aa = \"stratified\"\n"), AntiAliasing::Stratified);
        assert_eq!(
            aa("aa = \"adaptive\"\n"),
            AntiAliasing::Adaptive(Adaptive::default())
        );
        assert_eq!(
            aa("aa = \"adaptive\"\naa_threshold = 0.05\naa_depth = 4\naa_min_depth = 1\n"),
            AntiAliasing::Adaptive(Adaptive {
                threshold: 0.05,
                depth: 4,
                min_depth: 1,
            })
        );
    }

    #[test]
    fn bad_anti_aliasing_keys_are_reported() {
        let bad = |keys: &str| errors(&format!("{CAMERA}[render]\n{keys}"));
        assert_eq!(
            bad("aa = \"jitter\"\naa_threshold = -1\naa_depth = 7\n"),
            [
                "unknown anti-aliasing `jitter` for `aa`; expected one of: stratified, adaptive",
                "`aa_threshold` must not be negative, got -1",
                "`aa_depth` must be at most 6, got 7",
            ]
        );
        assert_eq!(
            bad("aa_depth = 2\n"),
            ["`aa_depth` applies only to adaptive anti-aliasing; add aa = \"adaptive\""]
        );
        assert_eq!(
            bad("aa = \"adaptive\"\naa_depth = 2\naa_min_depth = 3\n"),
            ["`aa_min_depth` must be at most `aa_depth` (2), got 3"]
        );
    }
}
