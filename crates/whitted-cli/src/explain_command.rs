//! `whitted explain`: the ray tree of one pixel's sample, as text, as
//! JSON (`docs/explain.md` has the schema) or drawn over the picture as
//! SVG.

use std::path::PathBuf;

use clap::Args;
use whitted::image::{check_text_destination, encode_text};
use whitted::integrator::DEFAULT_MAX_TREE_RAYS;
use whitted::render::{Explainer, PixelExplanation, Scene, render};
use whitted::scene::parse_whole_number;

use crate::explain_json::explanation_json;
use crate::explain_svg::svg_drawing;
use crate::explain_text::explanation_text;
use crate::progress::ProgressReport;
use crate::render_command::refuse_writing_inputs;
use crate::report::{note, results};
use crate::scene_arguments::SceneArgs;

/// Show why a pixel has its colour: the ray tree of one of its samples.
///
/// Every ray (camera, reflected, refracted) with what it hit, where the
/// scene file defines that object, the terms of the shading formula, each
/// light's shadow rays and verdict, why the tree stopped, the colour each
/// ray passes up, and what each ray cost in the acceleration structure.
/// The colour at the root is the rendered sample, exactly.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  whitted explain scenes/whitted.toml --pixel 320,240
  whitted explain scenes/whitted.toml --pixel 400,300 --json > tree.json
  whitted explain scenes/shapes.toml --pixel 10,20 --spp 4 --sample 3 --accel kdtree
  whitted explain scenes/whitted.toml --pixel 320,240 --svg tree.svg")]
pub struct ExplainArgs {
    #[command(flatten)]
    scene: SceneArgs,

    /// The pixel: column and row from the top left corner, from 0.
    #[arg(long, value_name = "X,Y", value_parser = pixel, allow_hyphen_values = true)]
    pixel: (u32, u32),

    /// Which of the pixel's samples (from 0; the pixel is the mean of its
    /// samples). With --aa adaptive, which of the corners the pixel's
    /// subdivision traces, row by row (the pixel is their area average).
    #[arg(long, value_name = "K", default_value = "0", value_parser = sample_index, allow_negative_numbers = true)]
    sample: u32,

    /// Print the tree as JSON instead of text.
    #[arg(long)]
    json: bool,

    /// Also render the picture and write it to FILE (an .svg drawing)
    /// with the tree's rays projected over it.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,

    /// The most rays and light verdicts the tree records (at least 1).
    /// Past it, the tree says at each hit how many it left out; the
    /// colours stay exact.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_TREE_RAYS, value_parser = max_tree_rays)]
    max_tree_rays: u64,

    /// Print nothing but errors on standard error (the tree is still
    /// printed).
    #[arg(short, long)]
    quiet: bool,
}

/// `X,Y`: two whole numbers.
fn pixel(text: &str) -> Result<(u32, u32), String> {
    let expected = "expected the column and row of a pixel, like 320,240";
    let Some((x, y)) = text.split_once(',') else {
        return Err(format!("`{text}` is not two numbers; {expected}"));
    };
    let number = |part: &str| {
        parse_whole_number(part.trim(), 0, u64::from(u32::MAX))
            .map(|n| n as u32)
            .map_err(|_| format!("`{}` is not a whole number from 0; {expected}", part.trim()))
    };
    Ok((number(x)?, number(y)?))
}

/// A sample's index: a whole number from 0.
fn sample_index(text: &str) -> Result<u32, String> {
    parse_whole_number(text, 0, u64::from(u32::MAX))
        .map(|n| n as u32)
        .map_err(|_| format!("`{text}` is not a whole number from 0"))
}

/// A tree's limit: a whole number from 1.
fn max_tree_rays(text: &str) -> Result<u64, String> {
    parse_whole_number(text, 1, u64::MAX)
        .map_err(|_| format!("`{text}` is not a whole number from 1"))
}

/// Runs the command.
pub fn run(args: &ExplainArgs) -> Result<(), String> {
    crate::report::check_results_stream()?;
    args.scene.check()?;
    let mut outputs = Vec::new();
    if let Some(path) = &args.svg {
        let drawing = check_text_destination(path, "svg").map_err(|e| e.to_string())?;
        outputs.push((format!("--svg {}", path.display()), drawing));
    }
    let scene_file: Vec<&std::path::Path> = args.scene.scene.as_deref().into_iter().collect();
    refuse_writing_inputs(&outputs, &scene_file)?;
    let scene = args.scene.load(args.quiet)?;
    refuse_writing_inputs(&outputs, &[])?;
    let explanation = Explainer::new(&scene)
        .and_then(|explainer| {
            explainer.with_max_tree_rays(args.max_tree_rays).explain(
                &scene.camera,
                args.pixel,
                args.sample,
            )
        })
        .map_err(|e| e.to_string())?;
    let file = args.scene.scene.as_deref();
    let text = if args.json {
        let mut json = explanation_json(&scene, file, &explanation);
        json.push('\n');
        json
    } else {
        explanation_text(&scene, file, &explanation)
    };
    if let Some(path) = &args.svg {
        write_svg(&scene, file, &explanation, path, args.quiet)?;
    }
    results(&text)
}

/// Renders the picture and writes it with the tree drawn over it.
fn write_svg(
    scene: &Scene,
    file: Option<&std::path::Path>,
    explanation: &PixelExplanation,
    path: &std::path::Path,
    quiet: bool,
) -> Result<(), String> {
    let total = u64::from(scene.settings.width) * u64::from(scene.settings.height);
    let bar = ProgressReport::new(total, quiet);
    let output = render(scene, &|p| bar.update(p));
    bar.finish();
    let output = output.map_err(|e| e.to_string())?;
    let png = output.image.png_bytes().map_err(|e| e.to_string())?;
    let svg = svg_drawing(scene, file, explanation, &png);
    encode_text(path, &svg)
        .and_then(|pending| pending.commit())
        .map_err(|e| e.to_string())?;
    if !quiet {
        note!("{}: the ray tree over the picture", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pixel_is_two_whole_numbers() {
        assert_eq!(pixel("320,240"), Ok((320, 240)));
        assert_eq!(pixel(" 0, 7"), Ok((0, 7)));
        assert_eq!(
            pixel("320").unwrap_err(),
            "`320` is not two numbers; expected the column and row of a pixel, like 320,240"
        );
        assert_eq!(
            pixel("-1,2").unwrap_err(),
            "`-1` is not a whole number from 0; expected the column and row of a pixel, like \
             320,240"
        );
        assert!(pixel("1,2,3").is_err());
        assert!(sample_index("2.5").is_err());
        assert_eq!(sample_index("3"), Ok(3));
    }
}
