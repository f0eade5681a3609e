//! The readers under test: for each, where its inputs come from and what is
//! done with one. Whatever a reader accepts goes on to the renderer, so the
//! hostile numbers it let through meet the acceleration structures and the
//! shading too.

use std::path::PathBuf;
use std::sync::Arc;

use whitted::accel::{AccelKind, AccelerationStructure};
use whitted::bench::obj_positions::parse_obj_positions;
use whitted::bench::ray_files::read_ray_file;
use whitted::bench::{RayKind, Walk, trace_all};
use whitted::math::{DVec2, Vec3};
use whitted::render::Camera;
use whitted::render::Scene;
use whitted::render::{
    Aov, PartHeader, PixelSelection, Share, Window, encode_part, merge_parts, parse_part, render,
    render_selected,
};
use whitted::scene::{
    MAX_DIAGNOSTICS, MAX_SHOWN_CHARS, SceneError, parse_nff, parse_obj, parse_scene,
};
use whitted::shading::texture::{Decoding, ImageTexture, Wrap, decode_image};
use whitted::world::World;

use super::corpus::{self, fixtures, read_all, repository};
use whitted::math::random::Rng;

/// One reader and its inputs.
pub struct Target {
    /// Its name in messages and in `WHITTED_FUZZ_REPLAY`.
    pub name: &'static str,
    /// Whether its inputs are text.
    pub text: bool,
    /// Starting inputs, one list per part of a case (an OBJ case is the
    /// model and its material library; a ray-file case the rays and the
    /// hits).
    pub corpus: Vec<Vec<Vec<u8>>>,
    /// Words of the format, for token mutations.
    pub vocabulary: Vec<String>,
    /// Makes a fresh input for a part from randomness.
    pub generate: fn(&mut Rng, usize) -> Vec<u8>,
    /// Reads a case and renders whatever it accepts; true when it was
    /// accepted.
    pub run: fn(&Workspace, &[Vec<u8>], AccelKind) -> bool,
}

/// A folder holding what cases refer to (textures, the material library
/// and ray files a case writes), one per target.
pub struct Workspace {
    dir: tempfile::TempDir,
}

impl Workspace {
    /// A fresh folder with the repository's textures in `textures/`.
    pub fn new() -> Self {
        let dir = tempfile::tempdir().expect("a temporary folder");
        let textures = dir.path().join("textures");
        std::fs::create_dir(&textures).expect("a textures folder");
        let images = fixtures("scenes/textures", &["png", "jpg"])
            .into_iter()
            .chain(fixtures("crates/whitted/tests", &["png", "jpg"]));
        for image in images {
            let name = image.file_name().expect("a file name");
            std::fs::copy(&image, textures.join(name)).expect("a copied texture");
        }
        Self { dir }
    }

    /// `name` inside the folder.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
}

/// Text of an input, with invalid UTF-8 replaced (every reader takes text;
/// the file loaders refuse what is not UTF-8 before that).
fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Renders `scene` small, with `accel` and every AOV, on one thread.
/// Sampling and depth are capped so that the case stays short; what the
/// file says about them is the readers' business, already checked.
fn exercise(mut scene: Scene, accel: AccelKind) {
    let settings = &mut scene.settings;
    settings.width = 8;
    settings.height = 6;
    settings.samples_per_pixel = settings.samples_per_pixel.clamp(1, 2);
    settings.max_depth = settings.max_depth.min(4);
    settings.accel = accel;
    let world = World::build(&scene.objects, accel);
    let _ = world.accelerator().validate(&[]);
    let _ = scene.objects.primitive_count();
    drop(world);
    settings.threads = Some(1);
    settings.aovs = Aov::ALL.to_vec();
    let _ = render(&scene, &|_| {});
}

/// Renders the scene a reader accepted, or checks the size of its report:
/// a bounded number of diagnostics, each of bounded size apart from the
/// words of the input it quotes. (Before reports were bounded, 64 KB of
/// `s s s ...` gave a 2 GB NFF message.)
fn render_or_check_report(
    parsed: Result<Scene, SceneError>,
    parts: &[Vec<u8>],
    accel: AccelKind,
) -> bool {
    match parsed {
        Ok(scene) => {
            exercise(scene, accel);
            true
        }
        Err(error) => {
            let input: usize = parts.iter().map(Vec::len).sum();
            // Three readers' worth of errors (an OBJ and its libraries),
            // each at most about 1.5 KB plus the input quoted, a few times.
            let limit = 3 * (MAX_DIAGNOSTICS + 1) * (1024 + 4 * MAX_SHOWN_CHARS) + 4 * input;
            let length = error.to_string().len();
            assert!(
                length <= limit,
                "a report of {length} bytes for {input} bytes of input"
            );
            false
        }
    }
}

fn run_toml(workspace: &Workspace, parts: &[Vec<u8>], accel: AccelKind) -> bool {
    let parsed = parse_scene(&text(&parts[0]), &workspace.path("scene.toml"));
    render_or_check_report(parsed, parts, accel)
}

fn run_nff(workspace: &Workspace, parts: &[Vec<u8>], accel: AccelKind) -> bool {
    let parsed = parse_nff(&text(&parts[0]), &workspace.path("scene.nff"));
    render_or_check_report(parsed, parts, accel)
}

fn run_obj(workspace: &Workspace, parts: &[Vec<u8>], accel: AccelKind) -> bool {
    let library = workspace.path("fuzz.mtl");
    std::fs::write(&library, &parts[1]).expect("the material library written");
    let parsed = parse_obj(&text(&parts[0]), &workspace.path("model.obj"));
    render_or_check_report(parsed.map(|loaded| loaded.scene), parts, accel)
}

fn run_obj_positions(workspace: &Workspace, parts: &[Vec<u8>], accel: AccelKind) -> bool {
    let soup = match parse_obj_positions(&text(&parts[0]), &workspace.path("mesh.obj")) {
        Ok(soup) => soup,
        Err(error) => return render_or_check_report(Err(error), parts, accel),
    };
    let camera = Camera::framing(&soup.bounds(), 4.0 / 3.0, 50.0)
        .or_else(|_| Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 50.0));
    let scene = camera
        .map_err(drop)
        .and_then(|c| soup.into_scene(c).map_err(drop));
    scene.map(|scene| exercise(scene, accel)).is_ok()
}

fn run_image(_: &Workspace, parts: &[Vec<u8>], _: AccelKind) -> bool {
    // Each decoding in turn, chosen by the input's length.
    let decoding = [Decoding::Color, Decoding::Data, Decoding::Opacity][parts[0].len() % 3];
    let Ok(data) = decode_image(&parts[0], decoding) else {
        return false;
    };
    let data = Arc::new(data);
    let coordinates = [
        0.0,
        0.5,
        1.0,
        -0.25,
        1e-300,
        1e300,
        -1e300,
        f64::NAN,
        f64::INFINITY,
    ];
    let placements = [(1.0, 0.0), (1e300, -1e300), (-3.0, 0.5)];
    for (wrap, (scale, offset)) in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror]
        .into_iter()
        .zip(placements)
    {
        let mut texture = ImageTexture::new(Arc::clone(&data));
        texture.wrap = wrap;
        texture.scale = DVec2::splat(scale);
        texture.offset = DVec2::splat(offset);
        for u in coordinates {
            for v in coordinates {
                let _ = texture.at(DVec2::new(u, v));
            }
        }
        let _ = texture.max_component();
    }
    true
}

/// The rays of a ray-file case are traced through this scene.
fn ray_target_scene() -> Scene {
    let source = std::fs::read_to_string(repository().join("scenes/shapes.toml"))
        .expect("scenes/shapes.toml");
    parse_scene(&source, &repository().join("scenes/shapes.toml")).expect("a valid scene")
}

fn run_ray_files(workspace: &Workspace, parts: &[Vec<u8>], accel: AccelKind) -> bool {
    let (rays, mut hits) = (&parts[0], parts[1].clone());
    let kind = RayKind::ALL[hits.len() % RayKind::ALL.len()];
    // Half the cases get hits of the right size, so that their rays, however
    // hostile, are traced.
    if hits.first().is_some_and(|b| b % 2 == 1) {
        let record = if kind.is_any_hit() { 1 } else { 8 };
        hits.resize(rays.len() / 32 * record, 0);
    }
    let name = kind.name();
    std::fs::write(workspace.path(&format!("{name}.rays")), rays).expect("rays written");
    std::fs::write(workspace.path(&format!("{name}.hits")), hits).expect("hits written");
    let Ok(file) = read_ray_file(workspace.path("").as_path(), kind) else {
        return false;
    };
    thread_local! {
        static SCENE: Scene = ray_target_scene();
    }
    SCENE.with(|scene| {
        let world = World::build(&scene.objects, accel);
        let _ = trace_all(&world, &file.set, Walk::Single);
    });
    true
}

/// The text inputs of `folders` with `extensions`.
fn text_corpus(folders: &[&str], extensions: &[&str]) -> Vec<Vec<u8>> {
    let paths: Vec<PathBuf> = folders
        .iter()
        .flat_map(|folder| fixtures(folder, extensions))
        .collect();
    read_all(&paths)
}

/// Our TOML scenes.
pub fn toml() -> Target {
    let corpus = text_corpus(&["scenes", "crates/whitted/tests", "docs"], &["toml"]);
    let vocabulary = corpus::vocabulary(
        &corpus,
        &[
            "[render]",
            "[camera]",
            "[[lights]]",
            "[[objects]]",
            "[materials.x]",
            "{",
            "}",
        ],
    );
    Target {
        name: "toml",
        text: true,
        corpus: vec![corpus],
        vocabulary,
        generate: |rng, _| match rng.below(8) {
            0 => corpus::deep_toml(rng.below(100_000) as usize, rng.below(2) == 0).into_bytes(),
            _ => corpus::toml_scene(rng).into_bytes(),
        },
        run: run_toml,
    }
}

/// NFF scenes.
pub fn nff() -> Target {
    let corpus = text_corpus(&["crates/whitted/tests", "docs", "scenes"], &["nff"]);
    let vocabulary = corpus::vocabulary(
        &corpus,
        &[
            "v",
            "from",
            "at",
            "up",
            "angle",
            "hither",
            "resolution",
            "b",
            "l",
            "f",
            "s",
            "c",
            "p",
            "pp",
        ],
    );
    Target {
        name: "nff",
        text: true,
        corpus: vec![corpus],
        vocabulary,
        generate: |rng, _| corpus::nff_scene(rng).into_bytes(),
        run: run_nff,
    }
}

/// OBJ models with an MTL library.
pub fn obj() -> Target {
    let models = text_corpus(&["crates/whitted/tests", "scenes", "docs"], &["obj"]);
    let libraries = text_corpus(&["crates/whitted/tests", "scenes", "docs"], &["mtl"]);
    let vocabulary = corpus::vocabulary(
        &[models.clone(), libraries.clone()].concat(),
        &[
            "mtllib fuzz.mtl",
            "usemtl fuzz",
            "f",
            "v",
            "vt",
            "vn",
            "s",
            "o",
            "g",
            "newmtl",
            "-bm",
            "-s",
            "-o",
            "-clamp",
        ],
    );
    Target {
        name: "obj",
        text: true,
        corpus: vec![models, libraries],
        vocabulary,
        generate: |rng, part| match part {
            0 => corpus::obj_model(rng).into_bytes(),
            _ => corpus::mtl_library(rng).into_bytes(),
        },
        run: run_obj,
    }
}

/// The positions-only OBJ reader of the benchmarks.
pub fn obj_positions() -> Target {
    let corpus = text_corpus(&["crates/whitted/tests", "scenes", "docs"], &["obj"]);
    let vocabulary = corpus::vocabulary(&corpus, &["v", "f", "vt", "vn"]);
    Target {
        name: "objpos",
        text: true,
        corpus: vec![corpus],
        vocabulary,
        generate: |rng, _| corpus::obj_model(rng).into_bytes(),
        run: run_obj_positions,
    }
}

/// PNG and JPEG textures.
pub fn image() -> Target {
    let corpus = read_all(
        &[
            fixtures("scenes/textures", &["png", "jpg"]),
            fixtures("crates/whitted/tests", &["png", "jpg"]),
        ]
        .concat(),
    );
    Target {
        name: "image",
        text: false,
        corpus: vec![corpus],
        vocabulary: Vec::new(),
        generate: |rng, _| match rng.below(5) {
            1 => {
                let side = |rng: &mut Rng| [1, 1000, 4096, 16384, 65535][rng.below(5) as usize];
                corpus::jpeg_claiming(side(rng), side(rng))
            }
            0 => {
                let side = |rng: &mut Rng| {
                    [1, 65535, 100_000, 1 << 24, u32::MAX >> 1][rng.below(5) as usize]
                };
                corpus::png_header(side(rng), side(rng))
            }
            _ => corpus::png_image(rng),
        },
        run: run_image,
    }
}

/// The Embree harness's ray and hit files.
pub fn ray_files() -> Target {
    let mut rng = Rng::new(7);
    let rays: Vec<Vec<u8>> = [0, 1, 3].map(|n| corpus::ray_records(&mut rng, n)).to_vec();
    let hits: Vec<Vec<u8>> = vec![vec![], vec![0; 1], vec![1; 3], vec![0; 8], vec![0; 24]];
    Target {
        name: "rays",
        text: false,
        corpus: vec![rays, hits],
        vocabulary: Vec::new(),
        generate: |rng, part| match part {
            0 => {
                let count = rng.below(5) as usize;
                corpus::ray_records(rng, count)
            }
            _ => (0..8 * rng.below(5))
                .map(|_| rng.next_u32() as u8)
                .collect(),
        },
        run: run_ray_files,
    }
}

/// A part of the built-in scene at 12×9 holding `selection`, with `aovs`.
fn part_of_built_in(selection: PixelSelection, aovs: &[Aov]) -> Vec<u8> {
    let mut scene = whitted::scene::default_scene();
    scene.settings.width = 12;
    scene.settings.height = 9;
    scene.settings.aovs = aovs.to_vec();
    scene.settings.threads = Some(1);
    let output = render_selected(&scene, &selection, &|_| {}).expect("a part renders");
    let header = PartHeader::new(&scene, "built-in", "built-in", selection);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join("part.wpart");
    encode_part(&path, &header, &output)
        .and_then(|pending| pending.commit())
        .expect("a part written");
    std::fs::read(path).expect("the part read back")
}

fn run_parts(workspace: &Workspace, parts: &[Vec<u8>], _: AccelKind) -> bool {
    let path = workspace.path("case.wpart");
    if parse_part(&parts[0], &path).is_err() {
        return false;
    }
    std::fs::write(&path, &parts[0]).expect("part written");
    // Accepted: it must merge, or be refused for its holes.
    let _ = merge_parts(&[path]);
    true
}

/// The pixels of a window, or one share of its rows.
fn crop(x0: u32, y0: u32, x1: u32, y1: u32, share: Option<Share>) -> PixelSelection {
    PixelSelection {
        window: Window { x0, y0, x1, y1 },
        share,
    }
}

/// The partial images of a split render (`.wpart`).
pub fn parts() -> Target {
    let corpus = vec![
        part_of_built_in(crop(0, 0, 12, 9, None), &[]),
        part_of_built_in(
            crop(0, 0, 12, 9, Some(Share { index: 1, count: 3 })),
            &Aov::ALL,
        ),
        part_of_built_in(
            crop(2, 3, 5, 8, Some(Share { index: 0, count: 2 })),
            &[Aov::Normal],
        ),
    ];
    let vocabulary = corpus::vocabulary(
        &corpus,
        &[
            "crop",
            "tile",
            "pixels",
            "data",
            "-",
            "0,0,65535,65535",
            "4294967295/1",
        ],
    );
    Target {
        name: "parts",
        text: false,
        corpus: vec![corpus],
        vocabulary,
        generate: |rng, _| {
            let x0 = rng.below(12);
            let y0 = rng.below(9);
            let count = 1 + rng.below(4);
            let share = (rng.below(2) == 0).then(|| Share {
                index: rng.below(count),
                count,
            });
            let selection = crop(x0, y0, 12, 9, share);
            if selection.check(12, 9).is_err() {
                return part_of_built_in(crop(0, 0, 12, 9, None), &[Aov::Depth]);
            }
            part_of_built_in(selection, &[Aov::Id, Aov::Cost])
        },
        run: run_parts,
    }
}
