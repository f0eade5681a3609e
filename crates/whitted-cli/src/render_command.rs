//! `whitted render`: load a scene, render it, write the image and AOVs.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use whitted::image::{Destination, ImageError, ImageFormat, check_destination};
use whitted::limits::{InputFile, identify_input, inputs_read};
use whitted::render::{Aov, Share, Window, render, render_selected, slow_implicit_surfaces};

use crate::arguments;
use crate::progress::ProgressReport;
use crate::render_stats::{self, StageSeconds};
use crate::report::note;
use crate::scene_arguments::SceneArgs;
use crate::split::{self, PartRender};

/// Render a scene to an image.
///
/// The output format follows the file name: .png (8-bit sRGB), .exr or
/// .pfm (linear 32-bit float). Command-line settings override the scene
/// file's [render] table (or an NFF file's resolution).
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  whitted render                                  the built-in scene, to whitted.png
  whitted render scenes/shapes.toml -o shapes.png --width 800 --height 600 --spp 4
  whitted render balls.nff -o balls.png           an SPD scene in NFF
  whitted render bunny.obj --eye 0,0.1,0.3 --fov 40   a Wavefront OBJ model, seen from elsewhere
  whitted render scenes/whitted.toml -o out.exr --aov depth=depth.pfm --aov normal=normal.exr")]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,

    /// Output image: .png, .exr or .pfm; or .wpart, a part of the image
    /// for `whitted merge` (docs/cluster.md).
    #[arg(short, long, value_name = "OUT", default_value = "whitted.png")]
    output: PathBuf,

    /// Worker threads (default: all cores). The picture is the same for any
    /// number.
    #[arg(long, value_name = "T", value_parser = arguments::threads, allow_negative_numbers = true)]
    threads: Option<usize>,

    /// Also write per-pixel data of the ray through each pixel centre, as
    /// NAME=FILE with FILE a .pfm or .exr. NAME is depth (distance along the
    /// ray, +inf on a miss), normal (world-space normal of the first hit, 0
    /// on a miss), id (primitive index, -1 on a miss) or cost (acceleration
    /// structure nodes visited plus primitives tested; as .png it is drawn
    /// as a heat map with a legend). Repeatable.
    #[arg(long, value_name = "NAME=FILE")]
    aov: Vec<String>,

    /// Render only worker I's share (from 0) of N: every N-th row, into a
    /// .wpart part for `whitted merge`.
    #[arg(long, value_name = "I/N", value_parser = split::tile, allow_hyphen_values = true)]
    tile: Option<Share>,

    /// Render only the window X0,Y0,X1,Y1 (ends excluded), into a .wpart
    /// part for `whitted merge`.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = split::crop, allow_hyphen_values = true)]
    crop: Option<Window>,

    /// After the summary, print where the time went (reading, building,
    /// photons, tracing with the threads' use, writing) and the rays by
    /// kind with their rates (printed even with --quiet).
    #[arg(long)]
    stats: bool,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

/// Parses `NAME=FILE` into an AOV and its destination.
pub fn parse_aov(spec: &str) -> Result<(Aov, PathBuf), String> {
    let names = Aov::ALL.map(|a| a.name()).join(", ");
    let (name, file) = spec
        .split_once('=')
        .ok_or_else(|| format!("--aov {spec}: expected NAME=FILE with NAME one of {names}"))?;
    let aov = Aov::from_name(name)
        .ok_or_else(|| format!("--aov {spec}: unknown AOV `{name}`; expected one of {names}"))?;
    let path = PathBuf::from(file);
    match (aov, ImageFormat::from_path(&path)) {
        (_, Ok(ImageFormat::Exr | ImageFormat::Pfm)) | (Aov::Cost, Ok(ImageFormat::Png)) => {
            Ok((aov, path))
        }
        (_, Err(e @ ImageError::Refused { .. })) => Err(format!("--aov {spec}: {e}")),
        (Aov::Cost, _) => Err(format!(
            "--aov {spec}: the cost AOV is written as .png (a heat map) or .pfm/.exr"
        )),
        _ => Err(format!(
            "--aov {spec}: AOVs are written as .pfm or .exr files"
        )),
    }
}

/// Refuses, before any work, outputs that cannot be written (see
/// [`check_destination`]: names that are no image file, missing or
/// unwritable folders, files the user may not write) and two outputs to
/// the same file (by canonical path and by file identity); unless `quiet`,
/// says what the user should know about the files that will be replaced.
/// Returns the outputs, each with the option that named it, for
/// [`refuse_writing_inputs`].
pub fn check_destinations(
    output: &Path,
    aovs: &[(Aov, PathBuf)],
    quiet: bool,
) -> Result<Vec<(String, Destination)>, String> {
    let image = check_destination(output).map_err(|e| e.to_string())?;
    let mut checked = vec![(format!("-o {}", output.display()), image)];
    for (aov, path) in aovs {
        let destination = check_destination(path).map_err(|e| e.to_string())?;
        let option = format!("--aov {}={}", aov.name(), path.display());
        if let Some((other, _)) = checked
            .iter()
            .find(|(_, d)| d.is_same_file_as(&destination))
        {
            return Err(format!(
                "{option}: that file is already an output of this render ({other})"
            ));
        }
        checked.push((option, destination));
    }
    for (_, destination) in checked.iter().filter(|_| !quiet) {
        for warning in destination.notes() {
            note!("warning: {warning}");
        }
    }
    Ok(checked)
}

/// Refuses an output (each with the option that named it) that is a file
/// this run reads, whatever the name or link it is reached by: one of
/// `named` (inputs named on the command line, compared before they are
/// read) or one read so far ([`inputs_read`]: the scene, its models,
/// material libraries, patches and textures, the parts). Called before
/// the inputs are read and again once they are, before any rendering.
pub fn refuse_writing_inputs(
    outputs: &[(String, Destination)],
    named: &[&Path],
) -> Result<(), String> {
    let mut inputs: Vec<InputFile> = named.iter().filter_map(|p| identify_input(p)).collect();
    inputs.extend(inputs_read());
    for (option, destination) in outputs {
        if let Some(input) = inputs.iter().find(|i| destination.is_input(i)) {
            return Err(format!(
                "{option}: that file is an input of this run ({}); writing it would destroy \
                 it, so give the output another name",
                input.path.display()
            ));
        }
    }
    Ok(())
}

/// Runs the command.
pub fn run(args: &RenderArgs) -> Result<(), String> {
    args.scene.check()?;
    let part = PartRender::from_args(&args.output, args.tile, args.crop, &args.aov)?;
    let aov_outputs = match part {
        Some(_) => Vec::new(),
        None => args
            .aov
            .iter()
            .map(|s| parse_aov(s))
            .collect::<Result<Vec<_>, _>>()?,
    };
    let outputs = check_destinations(&args.output, &aov_outputs, args.quiet)?;
    let scene_file: Vec<&Path> = args.scene.scene.as_deref().into_iter().collect();
    refuse_writing_inputs(&outputs, &scene_file)?;
    let load_start = Instant::now();
    let mut scene = args.scene.load(args.quiet)?;
    refuse_writing_inputs(&outputs, &[])?;
    let load_seconds = load_start.elapsed().as_secs_f64();

    scene.settings.threads = args.threads;
    scene.settings.aovs = match &part {
        Some(part) => part.aovs.clone(),
        None => aov_outputs.iter().map(|(a, _)| *a).collect(),
    };
    let selection = match &part {
        Some(part) => Some(part.selection(scene.settings.width, scene.settings.height)?),
        None => None,
    };
    let total = selection.map_or(
        u64::from(scene.settings.width) * u64::from(scene.settings.height),
        |s| s.pixel_count(),
    );
    if !args.quiet {
        for slow in slow_implicit_surfaces(&scene) {
            note!("warning: {slow}");
        }
    }
    let bar = ProgressReport::new(total, args.quiet);
    let start = Instant::now();
    let output = match &selection {
        Some(selection) => render_selected(&scene, selection, &|p| bar.update(p)),
        None => render(&scene, &|p| bar.update(p)),
    };
    bar.finish();
    let output = output.map_err(|e| e.to_string())?;
    let elapsed = start.elapsed().as_secs_f64();
    if let Some(clamp) = &output.thread_clamp
        && !args.quiet
    {
        note!("note: {clamp}");
    }
    if let Some(cut) = &output.ray_budget_cut
        && !args.quiet
    {
        note!("warning: {cut}");
    }
    if let Some(exceeded) = &output.gradient_exceeded
        && !args.quiet
    {
        note!("warning: {exceeded}");
    }
    if let Some(photons) = &output.photons
        && !args.quiet
    {
        note!("{photons}");
    }

    let write_start = Instant::now();
    match selection {
        Some(selection) => PartRender::write(
            &args.output,
            &scene,
            args.scene.scene.as_deref(),
            selection,
            &output,
        )?,
        None => {
            let aovs: Vec<_> = output
                .aovs
                .iter()
                .zip(&aov_outputs)
                .map(|((aov, film), (_, path))| (*aov, film, path))
                .collect();
            crate::outputs::write_films(&output.image, &args.output, &aovs)?;
        }
    }

    let write_seconds = write_start.elapsed().as_secs_f64();
    if !args.quiet {
        let rays = output.rays;
        let by_kind = output
            .ray_kinds
            .iter()
            .map(|&kind| format!("{} {}", rays[kind], kind.name()))
            .collect::<Vec<_>>()
            .join(", ");
        note!(
            "{}: {}x{}, {} in {:.3} s (world built in {:.3} s); rays: {by_kind}; \
             {:.2} Mrays/s",
            args.output.display(),
            scene.settings.width,
            scene.settings.height,
            crate::anti_aliasing::sampling(&scene.settings),
            elapsed,
            output.build_seconds,
            rays.total() as f64 / elapsed / 1e6,
        );
    }
    if args.stats {
        let stages = StageSeconds {
            load: load_seconds,
            render: elapsed,
            write: write_seconds,
        };
        for line in render_stats::lines(&output, stages) {
            note!("{line}");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aov_specs_name_a_known_aov_and_a_float_format() {
        assert_eq!(
            parse_aov("depth=d.pfm"),
            Ok((Aov::Depth, PathBuf::from("d.pfm")))
        );
        assert_eq!(
            parse_aov("normal=n.EXR"),
            Ok((Aov::Normal, PathBuf::from("n.EXR")))
        );
        assert!(
            parse_aov("depth")
                .unwrap_err()
                .contains("expected NAME=FILE")
        );
        assert!(
            parse_aov("albedo=a.pfm")
                .unwrap_err()
                .contains("unknown AOV `albedo`")
        );
        assert!(parse_aov("id=i.png").unwrap_err().contains(".pfm or .exr"));
        assert_eq!(
            parse_aov("cost=c.png"),
            Ok((Aov::Cost, PathBuf::from("c.png")))
        );
        assert!(parse_aov("cost=c.bmp").unwrap_err().contains("heat map"));
        assert!(
            parse_aov("depth=.pfm")
                .unwrap_err()
                .contains("`.pfm` is a hidden file's name with no extension")
        );
    }
}
