//! `whitted bench`: build every acceleration structure over a scene or mesh
//! and measure it: build time, memory, size, SAH cost, and for primary,
//! shadow and diffuse rays the speed on one thread and on all, with the work
//! per ray; with `--rays DIR`, the very rays of the Embree anchor harness and
//! how many results agree with Embree's.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use serde_json::{Value, json};
use whitted::accel::{AccelKind, AccelStats, AccelerationStructure};
use whitted::bench::obj_positions::load_obj_positions;
use whitted::bench::ray_files::{RayFile, agreement, read_ray_file};
use whitted::bench::{
    RayKind, RaySet, TraceResults, Walk, check_bench_size, scene_ray_sets, time_set, trace_all,
};
use whitted::limits::MemoryBudget;
use whitted::render::Camera;
use whitted::render::Scene;
use whitted::scene::{LoadOptions, load_any_with};
use whitted::world::World;

use crate::arguments;
use crate::progress::Status;
use crate::report::{self, note};

/// Brute force is skipped in `--accel all` above this many primitive tests
/// (primitives × rays): it would take minutes. Ask for it by name instead.
const LINEAR_BUDGET: f64 = 2e9;

/// Measure the acceleration structures on a scene or mesh.
///
/// For each structure: build time, memory, nodes, leaves, SAH cost; then for
/// primary rays (one per pixel centre), shadow rays (one per hit, towards
/// the first light) and diffuse rays (one cosine-distributed bounce per hit):
/// Mrays/s on 1 thread and on all threads, and the mean nodes visited and
/// primitives tested per ray.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  whitted bench scenes/shapes.toml
  whitted bench bunny.obj --accel bvh --width 512 --height 512
  whitted bench bunny.obj --rays /tmp/anchor_rays/bunny --json
The ray files come from the Embree harness in shared/peers/embree (bench --dump DIR).")]
pub struct BenchArgs {
    /// A scene file (.toml or .nff) or a triangle mesh (.obj: positions and
    /// faces).
    scene: PathBuf,

    /// Which structures: all, or one or more of bvh, kdtree, grid, linear
    /// separated by commas (measured in that order).
    #[arg(long, default_value = "all", value_name = "NAME")]
    accel: String,

    /// Width of the image the primary rays cover (1 to 65535; at most
    /// 4194304 pixels in all).
    #[arg(long, default_value_t = 1024, value_name = "W", value_parser = arguments::image_side, allow_negative_numbers = true)]
    width: u32,

    /// Height of the image the primary rays cover (1 to 65535; at most
    /// 4194304 pixels in all).
    #[arg(long, default_value_t = 1024, value_name = "H", value_parser = arguments::image_side, allow_negative_numbers = true)]
    height: u32,

    /// Trace the rays in DIR ({primary,shadow,diffuse}.rays and .hits, as
    /// written by the Embree harness's --dump) and compare with its results.
    #[arg(long, value_name = "DIR")]
    rays: Option<PathBuf>,

    /// Timed passes per measurement, and builds per structure (the best is
    /// reported; 1 to 1000).
    #[arg(long, default_value_t = 3, value_name = "N", value_parser = arguments::runs, allow_negative_numbers = true)]
    runs: usize,

    /// The memory budget: the most the rays, an input file or the scene's
    /// textures may take, like 512M or 8G (default: 3/4 of this machine's
    /// memory).
    #[arg(long, value_name = "SIZE", value_parser = whitted::limits::parse_size)]
    max_memory: Option<u64>,

    /// Walk the rays in packets of 8 consecutive rays, as the renderer
    /// walks a tile row's camera rays (together where the scene allows
    /// it), to compare with the single-ray walk.
    #[arg(long)]
    packets: bool,

    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,

    /// Print nothing but the results.
    #[arg(short, long)]
    quiet: bool,
}

/// The structures asked for: `all`, or names separated by commas, each
/// at most once, in the order given.
fn kinds(list: &str) -> Result<Vec<AccelKind>, String> {
    if list == "all" {
        return Ok(AccelKind::ALL.to_vec());
    }
    let mut kinds = Vec::new();
    for name in list.split(',').map(str::trim) {
        let Some(kind) = AccelKind::from_name(name) else {
            let names: Vec<&str> = AccelKind::ALL.iter().map(AccelKind::name).collect();
            return Err(format!(
                "--accel {list}: `{name}` is not a structure; expected all, or one or more of {} \
                 separated by commas",
                names.join(", ")
            ));
        };
        if kinds.contains(&kind) {
            return Err(format!("--accel {list}: {name} is named twice"));
        }
        kinds.push(kind);
    }
    Ok(kinds)
}

/// The scene to measure: a scene file (its reader's warnings printed), or
/// a mesh framed by the anchor harness's default camera.
fn load(path: &Path, width: u32, height: u32) -> Result<Scene, String> {
    let is_obj = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if !is_obj {
        let loaded = load_any_with(path, &LoadOptions::default()).map_err(|e| e.to_string())?;
        for warning in &loaded.warnings {
            note!("{warning}\n");
        }
        return Ok(loaded.scene);
    }
    let soup = load_obj_positions(path).map_err(|e| e.to_string())?;
    let aspect = f64::from(width) / f64::from(height);
    let camera = Camera::framing(&soup.bounds(), aspect, 50.0)
        .map_err(|e| format!("{}: cannot frame the mesh: {e}", path.display()))?;
    soup.into_scene(camera)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// One kind of ray measured through one structure.
struct KindReport {
    kind: RayKind,
    rays: usize,
    seconds_one: f64,
    seconds_all: f64,
    nodes_per_ray: f64,
    primitives_per_ray: f64,
    agreeing: Option<(usize, usize)>,
}

/// One structure measured.
struct AccelReport {
    kind: AccelKind,
    build_seconds: f64,
    stats: AccelStats,
    /// Whether `--packets` was asked for and this structure, in this
    /// scene, walks packets together (otherwise its rays went one at a
    /// time).
    packets: bool,
    kinds: Vec<KindReport>,
}

/// Runs the command.
pub fn run(args: &BenchArgs) -> Result<(), String> {
    let kinds = kinds(&args.accel)?;
    report::check_results_stream()?;
    if let Some(bytes) = args.max_memory {
        MemoryBudget::given(bytes).set_current();
    }
    if args.rays.is_none() {
        check_bench_size(args.width, args.height).map_err(|e| e.to_string())?;
    }
    let status = Status::new(args.quiet || args.json);
    status.set(format!("loading {}", args.scene.display()));
    let scene = load(&args.scene, args.width, args.height)?;
    whitted::render::check_objects(&scene.objects).map_err(|e| e.to_string())?;
    let all_threads = std::thread::available_parallelism().map_or(1, usize::from);

    let (sets, references): (Vec<RaySet>, Vec<Option<TraceResults>>) = match &args.rays {
        Some(dir) => {
            status.set(format!("reading rays from {}", dir.display()));
            let files = RayKind::ALL
                .iter()
                .map(|&k| read_ray_file(dir, k))
                .collect::<Result<Vec<RayFile>, _>>()
                .map_err(|e| e.to_string())?;
            files
                .into_iter()
                .map(|f| (f.set, Some(f.reference)))
                .unzip()
        }
        None => {
            status.set("generating rays".to_string());
            let world = World::new(&scene.objects);
            let sets = scene_ray_sets(&scene, &world, args.width, args.height);
            let none = sets.iter().map(|_| None).collect();
            (sets, none)
        }
    };
    let walk = if args.packets {
        Walk::Packets
    } else {
        Walk::Single
    };
    let total_rays: usize = sets.iter().map(|s| s.rays.len()).sum();
    let primitives = scene.objects.primitive_count();

    let mut reports = Vec::new();
    for &kind in &kinds {
        let work = primitives as f64 * total_rays as f64;
        if kind == AccelKind::Linear && args.accel == "all" && work > LINEAR_BUDGET {
            if !args.quiet && !args.json {
                note!(
                    "linear skipped: {primitives} primitives x {total_rays} rays is too much \
                     brute force; use --accel linear to run it anyway"
                );
            }
            continue;
        }
        status.set(format!("building {}", kind.name()));
        // Held while the structure is measured.
        let _world_charge =
            whitted::render::charge_world(&scene.objects, (kind, kind), MemoryBudget::current())
                .map_err(|e| e.to_string())?;
        let (world, build_seconds) = time_build(&scene, kind, args.runs);
        let stats = world.accelerator().stats();
        let mut kind_reports = Vec::new();
        for (set, reference) in sets.iter().zip(&references) {
            status.set(format!(
                "{}: {} rays, counting",
                kind.name(),
                set.kind.name()
            ));
            let (results, counters) = trace_all(&world, set, walk);
            let per_ray = |n: u64| n as f64 / set.rays.len().max(1) as f64;
            status.set(format!(
                "{}: {} rays, 1 thread",
                kind.name(),
                set.kind.name()
            ));
            let seconds_one = time_set(&world, set, walk, 1, args.runs)?;
            status.set(format!(
                "{}: {} rays, {all_threads} threads",
                kind.name(),
                set.kind.name()
            ));
            let seconds_all = time_set(&world, set, walk, all_threads, args.runs)?;
            kind_reports.push(KindReport {
                kind: set.kind,
                rays: set.rays.len(),
                seconds_one,
                seconds_all,
                nodes_per_ray: per_ray(counters.nodes),
                primitives_per_ray: per_ray(counters.primitives),
                agreeing: reference.as_ref().map(|r| agreement(&results, r)),
            });
        }
        reports.push(AccelReport {
            kind,
            build_seconds,
            stats,
            packets: args.packets && world.walks_packets(),
            kinds: kind_reports,
        });
    }
    status.finish();

    let results = if args.json {
        format!("{}\n", to_json(args, primitives, all_threads, &reports))
    } else {
        table(args, primitives, all_threads, &reports)
    };
    report::results(&results)
}

/// The geometry with structure `kind`, built `runs` times (at least once),
/// and the best time: the first build alone also pays for starting the
/// thread pool and for fresh memory, which the Embree harness's median of
/// three builds does not.
fn time_build(scene: &Scene, kind: AccelKind, runs: usize) -> (World<'_>, f64) {
    let build = || {
        let start = Instant::now();
        let world = World::build(&scene.objects, kind);
        (world, start.elapsed().as_secs_f64())
    };
    let (mut world, mut best) = build();
    for _ in 1..runs {
        // The previous structure goes first, as Embree's scene does.
        drop(world);
        let (rebuilt, seconds) = build();
        (world, best) = (rebuilt, best.min(seconds));
    }
    (world, best)
}

fn mrays(rays: usize, seconds: f64) -> f64 {
    if seconds > 0.0 {
        rays as f64 / seconds / 1e6
    } else {
        0.0
    }
}

/// The results as a table, one block of lines per structure.
fn table(args: &BenchArgs, primitives: usize, threads: usize, reports: &[AccelReport]) -> String {
    let source = match &args.rays {
        Some(dir) => format!("rays from {}", dir.display()),
        None => format!("rays for a {}x{} image", args.width, args.height),
    };
    let mut lines = vec![format!(
        "{}: {primitives} primitives; {source}; best of {} runs",
        args.scene.display(),
        args.runs
    )];
    for r in reports {
        let s = &r.stats;
        lines.push(String::new());
        lines.push(format!(
            "{:<7} build {:.1} ms, {:.2} MB, {} nodes, {} leaves, {} references, SAH cost {:.2}, depth {}",
            r.kind.name(),
            r.build_seconds * 1e3,
            s.memory_bytes as f64 / 1e6,
            s.nodes,
            s.leaves,
            s.references,
            s.sah_cost,
            s.max_depth
        ));
        if args.packets {
            lines.push(if r.packets {
                "        rays in packets of 8".to_string()
            } else {
                "        rays one at a time: this structure or scene walks no packets".to_string()
            });
        }
        let agree_header = if args.rays.is_some() { "  agree" } else { "" };
        lines.push(format!(
            "        {:<8} {:>9} {:>11} {:>11} {:>10} {:>10}{agree_header}",
            "rays",
            "count",
            "Mrays/s 1T",
            format!("Mrays/s {threads}T"),
            "nodes/ray",
            "prims/ray"
        ));
        for k in &r.kinds {
            let agree = k
                .agreeing
                .map(|(a, n)| format!("  {:.4}%", 100.0 * a as f64 / n.max(1) as f64))
                .unwrap_or_default();
            lines.push(format!(
                "        {:<8} {:>9} {:>11.2} {:>11.2} {:>10.1} {:>10.1}{agree}",
                k.kind.name(),
                k.rays,
                mrays(k.rays, k.seconds_one),
                mrays(k.rays, k.seconds_all),
                k.nodes_per_ray,
                k.primitives_per_ray
            ));
        }
    }
    lines.iter().map(|line| format!("{line}\n")).collect()
}

fn to_json(args: &BenchArgs, primitives: usize, threads: usize, reports: &[AccelReport]) -> Value {
    let structures: Vec<Value> = reports
        .iter()
        .map(|r| {
            let kinds: Vec<Value> = r
                .kinds
                .iter()
                .map(|k| {
                    json!({
                        "rays": k.kind.name(),
                        "count": k.rays,
                        "mrays_per_s_1_thread": mrays(k.rays, k.seconds_one),
                        "mrays_per_s_all_threads": mrays(k.rays, k.seconds_all),
                        "nodes_per_ray": k.nodes_per_ray,
                        "primitives_per_ray": k.primitives_per_ray,
                        "agreeing": k.agreeing.map(|(a, _)| a),
                    })
                })
                .collect();
            json!({
                "accel": r.kind.name(),
                "build_ms": r.build_seconds * 1e3,
                "memory_bytes": r.stats.memory_bytes,
                "nodes": r.stats.nodes,
                "leaves": r.stats.leaves,
                "references": r.stats.references,
                "sah_cost": r.stats.sah_cost,
                "max_depth": r.stats.max_depth,
                "packets": r.packets,
                "kinds": kinds,
            })
        })
        .collect();
    json!({
        "scene": args.scene.display().to_string(),
        "primitives": primitives,
        "rays_from": args.rays.as_ref().map(|d| d.display().to_string()),
        "width": args.width,
        "height": args.height,
        "runs": args.runs,
        "packets": args.packets,
        "threads": threads,
        "structures": structures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accel_lists_name_structures_in_order() {
        assert_eq!(kinds("all").unwrap(), AccelKind::ALL.to_vec());
        assert_eq!(kinds("kdtree").unwrap(), vec![AccelKind::KdTree]);
        assert_eq!(
            kinds("bvh, kdtree,linear").unwrap(),
            vec![AccelKind::Bvh, AccelKind::KdTree, AccelKind::Linear]
        );
    }

    #[test]
    fn unknown_repeated_or_empty_names_are_refused() {
        for (list, says) in [
            ("bvh,octree", "`octree` is not a structure"),
            ("bvh,", "`` is not a structure"),
            ("", "`` is not a structure"),
            ("grid,grid", "grid is named twice"),
        ] {
            let error = kinds(list).unwrap_err();
            assert!(error.contains(says), "{list}: {error}");
        }
    }
}
