//! `whitted merge`: put a frame rendered in parts (`whitted render --tile`
//! or `--crop` into .wpart files) back together and write it, as the
//! single render of the same command would have, bit for bit.

use std::path::PathBuf;

use clap::Args;
use whitted::image::ImageFormat;
use whitted::limits::MemoryBudget;
use whitted::render::merge_parts;

use crate::render_command::{check_destinations, parse_aov, refuse_writing_inputs};
use crate::report::note;

/// Merge the parts of a split render into the full image.
///
/// The parts must come from one render (the same scene file, by its
/// SHA-256, the same settings and camera) and hold every pixel exactly
/// once; otherwise nothing is written and the error names the part at
/// fault. See docs/cluster.md for Slurm and Kubernetes recipes.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  whitted render scene.toml --tile 0/2 -o parts/0.wpart --aov depth
  whitted render scene.toml --tile 1/2 -o parts/1.wpart --aov depth
  whitted merge parts/*.wpart -o scene.png --aov depth=depth.pfm")]
pub struct MergeArgs {
    /// The parts (.wpart files), in any order.
    #[arg(required = true, value_name = "PARTS")]
    parts: Vec<PathBuf>,

    /// Output image: .png, .exr or .pfm.
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,

    /// Also write an AOV the parts hold, as NAME=FILE (see `whitted render
    /// --help`). Repeatable.
    #[arg(long, value_name = "NAME=FILE")]
    aov: Vec<String>,

    /// The memory budget, like 512M or 8G (default: 3/4 of this machine's
    /// memory).
    #[arg(long, value_name = "SIZE", value_parser = whitted::limits::parse_size)]
    max_memory: Option<u64>,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

/// Runs the command.
pub fn run(args: &MergeArgs) -> Result<(), String> {
    if let Some(bytes) = args.max_memory {
        MemoryBudget::given(bytes).set_current();
    }
    if ImageFormat::from_path(&args.output).ok() == Some(ImageFormat::Part) {
        return Err(format!(
            "-o {}: merge writes the full image; name it .png, .exr or .pfm",
            args.output.display()
        ));
    }
    let aov_outputs = args
        .aov
        .iter()
        .map(|s| parse_aov(s))
        .collect::<Result<Vec<_>, _>>()?;
    let outputs = check_destinations(&args.output, &aov_outputs, args.quiet)?;
    let parts: Vec<&std::path::Path> = args.parts.iter().map(PathBuf::as_path).collect();
    refuse_writing_inputs(&outputs, &parts)?;
    let merged = merge_parts(&args.parts).map_err(|e| e.to_string())?;
    refuse_writing_inputs(&outputs, &[])?;
    let held: Vec<&str> = merged.aovs.iter().map(|(a, _)| a.name()).collect();
    let mut aovs = Vec::new();
    for (aov, path) in &aov_outputs {
        let Some((_, film)) = merged.aovs.iter().find(|(a, _)| a == aov) else {
            return Err(format!(
                "--aov {}={}: the parts hold no {} AOV (they hold {}); render them with \
                 --aov {}",
                aov.name(),
                path.display(),
                aov.name(),
                match held.as_slice() {
                    [] => "none".to_string(),
                    names => names.join(", "),
                },
                aov.name()
            ));
        };
        aovs.push((*aov, film, path));
    }
    crate::outputs::write_films(&merged.image, &args.output, &aovs)?;
    if !args.quiet {
        for (aov, _) in &merged.aovs {
            if !aov_outputs.iter().any(|(a, _)| a == aov) {
                note!(
                    "note: the parts also hold the {0} AOV; add --aov {0}=FILE to write it",
                    aov.name()
                );
            }
        }
        let header = &merged.header;
        note!(
            "{}: {}x{}, {} spp, merged from {} part(s) of {}",
            args.output.display(),
            header.width,
            header.height,
            header.spp,
            args.parts.len(),
            header.scene
        );
    }
    Ok(())
}
