//! The anti-aliasing options of `whitted render` and `whitted explain`:
//! `--aa`, `--aa-threshold`, `--aa-depth` and `--aa-min-depth`, which
//! override the scene's `[render]` keys.

use clap::Args;
use whitted::render::{Adaptive, AntiAliasing, MAX_AA_DEPTH, RenderSettings};

/// How each pixel is sampled.
#[derive(Debug, Default, Args)]
pub struct AaArgs {
    /// Anti-aliasing: stratified (--spp samples per pixel, the default) or
    /// adaptive (POV-Ray's +AM2: pixel corners, subdivided where they
    /// differ; --spp is not used).
    #[arg(long, value_name = "METHOD", value_parser = method)]
    aa: Option<AntiAliasing>,

    /// Adaptive anti-aliasing: subdivide a square where two corners differ
    /// by more than this, the sum over red, green and blue of their
    /// displayed values' differences, each from 0 to 1 (default 0.3, as
    /// POV-Ray's).
    #[arg(long, value_name = "T", value_parser = threshold, allow_negative_numbers = true)]
    aa_threshold: Option<f64>,

    /// Adaptive anti-aliasing: halve a pixel at most D times along each
    /// side, down to squares 1/2^D of a pixel wide (default 3; at most 6).
    #[arg(long, value_name = "D", value_parser = depth, allow_negative_numbers = true)]
    aa_depth: Option<u32>,

    /// Adaptive anti-aliasing: halve every pixel D times whatever its
    /// corners (default 0, POV-Ray's way; 1 finds features smaller than a
    /// pixel that no corner sees; at most --aa-depth).
    #[arg(long, value_name = "D", value_parser = depth, allow_negative_numbers = true)]
    aa_min_depth: Option<u32>,
}

impl AaArgs {
    /// `aa` (the scene's) with these options applied; an error when a
    /// threshold or depth is given for stratified sampling.
    pub fn apply(&self, aa: AntiAliasing) -> Result<AntiAliasing, String> {
        let method = match (self.aa, aa) {
            (Some(AntiAliasing::Adaptive(_)), AntiAliasing::Adaptive(scene)) => {
                AntiAliasing::Adaptive(scene)
            }
            (Some(asked), _) => asked,
            (None, scene) => scene,
        };
        match method {
            AntiAliasing::Stratified => {
                if self.aa_threshold.is_some()
                    || self.aa_depth.is_some()
                    || self.aa_min_depth.is_some()
                {
                    return Err(
                        "--aa-threshold, --aa-depth and --aa-min-depth apply only to adaptive \
                         anti-aliasing; add --aa adaptive"
                            .to_string(),
                    );
                }
                Ok(method)
            }
            AntiAliasing::Adaptive(a) => {
                let adaptive = Adaptive {
                    threshold: self.aa_threshold.unwrap_or(a.threshold),
                    depth: self.aa_depth.unwrap_or(a.depth),
                    min_depth: self.aa_min_depth.unwrap_or(a.min_depth),
                };
                adaptive.check().map_err(|e| e.to_string())?;
                Ok(AntiAliasing::Adaptive(adaptive))
            }
        }
    }
}

/// How the pixels were sampled, for the summary: `4 spp` or the adaptive
/// parameters.
pub fn sampling(settings: &RenderSettings) -> String {
    match settings.aa {
        AntiAliasing::Stratified => format!("{} spp", settings.samples_per_pixel),
        AntiAliasing::Adaptive(a) => a.to_string(),
    }
}

/// Parses an anti-aliasing method's name.
fn method(name: &str) -> Result<AntiAliasing, String> {
    AntiAliasing::from_name(name)
        .ok_or_else(|| format!("expected one of: {}", AntiAliasing::NAMES.join(", ")))
}

/// Parses a threshold: a number, at least 0.
fn threshold(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() && value >= 0.0 => Ok(value),
        _ => Err(format!(
            "`{text}` is not valid; expected a number, at least 0"
        )),
    }
}

/// Parses a depth: 0 to [`MAX_AA_DEPTH`].
fn depth(text: &str) -> Result<u32, String> {
    match text.parse::<u32>() {
        Ok(value) if value <= MAX_AA_DEPTH => Ok(value),
        _ => Err(format!(
            "`{text}` is not valid; expected a whole number from 0 to {MAX_AA_DEPTH} (squares \
             1/64 of a pixel wide)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_override_the_scene_and_keep_what_they_do_not_name() {
        let scene = AntiAliasing::Adaptive(Adaptive {
            threshold: 0.1,
            depth: 2,
            min_depth: 1,
        });
        let none = AaArgs::default();
        assert_eq!(none.apply(scene), Ok(scene));
        assert_eq!(
            none.apply(AntiAliasing::Stratified),
            Ok(AntiAliasing::Stratified)
        );
        let adaptive = AaArgs {
            aa: method("adaptive").ok(),
            aa_threshold: None,
            aa_depth: Some(4),
            aa_min_depth: None,
        };
        assert_eq!(
            adaptive.apply(AntiAliasing::Stratified),
            Ok(AntiAliasing::Adaptive(Adaptive {
                threshold: 0.3,
                depth: 4,
                min_depth: 0,
            }))
        );
        assert_eq!(
            adaptive.apply(scene),
            Ok(AntiAliasing::Adaptive(Adaptive {
                threshold: 0.1,
                depth: 4,
                min_depth: 1,
            }))
        );
        let stratified = AaArgs {
            aa: Some(AntiAliasing::Stratified),
            aa_threshold: Some(0.1),
            aa_depth: None,
            aa_min_depth: None,
        };
        let message = stratified.apply(scene).unwrap_err();
        assert!(message.contains("--aa adaptive"), "{message}");
        let too_deep = AaArgs {
            aa_min_depth: Some(3),
            ..AaArgs::default()
        };
        let message = too_deep.apply(scene).unwrap_err();
        assert!(message.contains("minimum depth 3"), "{message}");
    }

    #[test]
    fn bad_values_are_refused_with_what_was_expected() {
        assert!(
            method("jitter")
                .unwrap_err()
                .contains("stratified, adaptive")
        );
        assert_eq!(threshold("0.05"), Ok(0.05));
        for bad in ["-1", "nan", "inf", "x"] {
            assert!(threshold(bad).unwrap_err().contains("at least 0"), "{bad}");
        }
        assert_eq!(depth("6"), Ok(6));
        for bad in ["7", "-1", "2.5"] {
            assert!(depth(bad).unwrap_err().contains("from 0 to 6"), "{bad}");
        }
    }
}
