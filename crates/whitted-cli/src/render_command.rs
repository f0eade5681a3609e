//! `whitted render`: load a scene, render it, write the image and AOVs.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use whitted::accel::AccelKind;
use whitted::image::{ImageError, ImageFormat, check_destination};
use whitted::limits::MemoryBudget;
use whitted::math::Vec3;
use whitted::render::{Aov, Share, Window, check_image_size, render, render_selected};
use whitted::scene::{CameraOverride, LoadOptions, load_any_with};

use crate::arguments;
use crate::progress::ProgressReport;
use crate::report::note;
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
    /// Scene file: .toml (ours), .nff (Neutral File Format), .obj
    /// (Wavefront, with its .mtl) or .bpt (Bézier patches). Without one,
    /// the built-in scene is rendered.
    scene: Option<PathBuf>,

    /// Output image: .png, .exr or .pfm; or .wpart, a part of the image
    /// for `whitted merge` (docs/cluster.md).
    #[arg(short, long, value_name = "OUT", default_value = "whitted.png")]
    output: PathBuf,

    /// Image width in pixels (1 to 65535; at most 268435456 pixels in all).
    #[arg(long, value_name = "W", value_parser = arguments::image_side, allow_negative_numbers = true)]
    width: Option<u32>,

    /// Image height in pixels (1 to 65535; at most 268435456 pixels in all).
    #[arg(long, value_name = "H", value_parser = arguments::image_side, allow_negative_numbers = true)]
    height: Option<u32>,

    /// Samples per pixel, on a stratified seeded pattern (1 = pixel centre;
    /// at most 65536).
    #[arg(long, value_name = "N", value_parser = arguments::samples, allow_negative_numbers = true)]
    spp: Option<u32>,

    /// Maximum reflection/refraction depth (0 = no secondary rays; default 8;
    /// at most 1000).
    #[arg(long, value_name = "D", value_parser = arguments::depth, allow_negative_numbers = true)]
    max_depth: Option<u32>,

    /// Photons to shoot for caustics (overrides the scene's `photons`; 0 =
    /// off, the default; at most 100000000).
    #[arg(long, value_name = "N", value_parser = arguments::photons, allow_negative_numbers = true)]
    photons: Option<u64>,

    #[command(flatten)]
    aa: Box<crate::anti_aliasing::AaArgs>,

    /// Acceleration structure over the objects (overrides the scene's
    /// `accel`); every structure gives the same picture.
    #[arg(long, value_name = "NAME", value_parser = parse_accel)]
    accel: Option<AccelKind>,

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

    /// Put the camera's eye here (replaces the scene's).
    #[arg(long, value_name = "X,Y,Z", value_parser = arguments::vec3, allow_hyphen_values = true)]
    eye: Option<Vec3>,

    /// Point the camera at this point (replaces the scene's).
    #[arg(long, value_name = "X,Y,Z", value_parser = arguments::vec3, allow_hyphen_values = true)]
    look_at: Option<Vec3>,

    /// The direction that is up on the image (replaces the scene's).
    #[arg(long, value_name = "X,Y,Z", value_parser = arguments::vec3, allow_hyphen_values = true)]
    up: Option<Vec3>,

    /// Vertical field of view in degrees, top edge to bottom edge
    /// (replaces the scene's; between 0 and 180, both excluded).
    #[arg(long, value_name = "DEG", value_parser = arguments::field_of_view, allow_hyphen_values = true)]
    fov: Option<f64>,

    /// The memory budget: the most an image, a texture or an input file
    /// may take, like 512M or 8G (default: 3/4 of this machine's memory).
    #[arg(long, value_name = "SIZE", value_parser = whitted::limits::parse_size)]
    max_memory: Option<u64>,

    /// Render only worker I's share (from 0) of N: every N-th row, into a
    /// .wpart part for `whitted merge`.
    #[arg(long, value_name = "I/N", value_parser = split::tile, allow_hyphen_values = true)]
    tile: Option<Share>,

    /// Render only the window X0,Y0,X1,Y1 (ends excluded), into a .wpart
    /// part for `whitted merge`.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = split::crop, allow_hyphen_values = true)]
    crop: Option<Window>,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

/// Parses the name of an acceleration structure.
fn parse_accel(name: &str) -> Result<AccelKind, String> {
    AccelKind::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = AccelKind::ALL.iter().map(AccelKind::name).collect();
        format!("expected one of: {}", names.join(", "))
    })
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
pub fn check_destinations(
    output: &Path,
    aovs: &[(Aov, PathBuf)],
    quiet: bool,
) -> Result<(), String> {
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
    Ok(())
}

/// The parts of the scene's camera the arguments replace.
fn camera_override(args: &RenderArgs) -> CameraOverride {
    CameraOverride {
        eye: args.eye,
        look_at: args.look_at,
        up: args.up,
        fov_degrees: args.fov,
    }
}

/// Refuses, before the scene is read, what the arguments alone show cannot
/// be rendered: an image of too many pixels, a camera no scene could have.
/// (Each value was checked on its own as it was parsed.)
fn check_arguments(args: &RenderArgs) -> Result<(), String> {
    if let (Some(width), Some(height)) = (args.width, args.height) {
        check_image_size(width, height)
            .map_err(|e| format!("--width {width} --height {height}: {e}"))?;
    }
    camera_override(args)
        .check()
        .map_err(|e| format!("the camera asked for is invalid: {e}"))
}

/// Runs the command.
pub fn run(args: &RenderArgs) -> Result<(), String> {
    check_arguments(args)?;
    if let Some(bytes) = args.max_memory {
        MemoryBudget::given(bytes).set_current();
    }
    let part = PartRender::from_args(&args.output, args.tile, args.crop, &args.aov)?;
    let aov_outputs = match part {
        Some(_) => Vec::new(),
        None => args
            .aov
            .iter()
            .map(|s| parse_aov(s))
            .collect::<Result<Vec<_>, _>>()?,
    };
    check_destinations(&args.output, &aov_outputs, args.quiet)?;

    let options = LoadOptions {
        camera: camera_override(args),
    };
    let mut scene = match &args.scene {
        Some(path) => {
            let start = Instant::now();
            let loaded = load_any_with(path, &options).map_err(|e| e.to_string())?;
            if !args.quiet {
                for warning in &loaded.warnings {
                    note!("{warning}\n");
                }
                note!(
                    "{}: read in {:.3} s, {} primitives",
                    path.display(),
                    start.elapsed().as_secs_f64(),
                    loaded.scene.objects.primitive_count()
                );
            }
            loaded.scene
        }
        None => {
            let mut scene = whitted::scene::default_scene();
            scene.camera = options
                .camera
                .apply(&scene.camera)
                .map_err(|e| format!("the camera asked for is invalid: {e}"))?;
            scene
        }
    };
    let settings = &mut scene.settings;
    settings.width = args.width.unwrap_or(settings.width);
    settings.height = args.height.unwrap_or(settings.height);
    settings.samples_per_pixel = args.spp.unwrap_or(settings.samples_per_pixel);
    settings.max_depth = args.max_depth.unwrap_or(settings.max_depth);
    settings.accel = args.accel.unwrap_or(settings.accel);
    settings.photons.count = args.photons.unwrap_or(settings.photons.count);
    settings.aa = args.aa.apply(settings.aa)?;

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

    match selection {
        Some(selection) => PartRender::write(
            &args.output,
            &scene,
            args.scene.as_deref(),
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

    if !args.quiet {
        let rays = output.rays;
        let by_kind = output
            .ray_kinds
            .iter()
            .map(|&kind| format!("{} {}", rays[kind], kind.name()))
            .collect::<Vec<_>>()
            .join(", ");
        note!(
            "{}: {}x{}, {} in {:.3} s; rays: {by_kind}; {:.2} Mrays/s",
            args.output.display(),
            scene.settings.width,
            scene.settings.height,
            crate::anti_aliasing::sampling(&scene.settings),
            elapsed,
            rays.total() as f64 / elapsed / 1e6,
        );
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
