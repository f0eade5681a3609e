//! The `whitted` command as a user runs it.

use std::path::Path;
use std::process::{Command, Output};

fn whitted(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_backend_that_is_no_instruction_set_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    for value in ["avx1024", ""] {
        let out = Command::new(env!("CARGO_BIN_EXE_whitted"))
            .args(["render", "--width", "8", "--height", "8"])
            .env(whitted::accel::ISA_VARIABLE, value)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(!out.status.success());
        let message = stderr(&out);
        assert!(
            message.contains("WHITTED_ISA") && message.contains("sse2, avx, avx2"),
            "{message}"
        );
        assert!(!dir.path().join("whitted.png").exists());
    }
    let out = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(["render", "--width", "8", "--height", "8"])
        .env(whitted::accel::ISA_VARIABLE, "sse2")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn render_without_a_scene_writes_the_built_in_scene_to_whitted_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = whitted(&["render", "--width", "40", "--height", "30"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let png = std::fs::read(dir.path().join("whitted.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let summary = stderr(&out);
    assert!(summary.contains("40x30"), "{summary}");
    assert!(summary.contains("1200 primary"), "{summary}");
    assert!(summary.contains("Mrays/s"), "{summary}");
}

#[test]
fn quiet_prints_nothing_and_aovs_are_written_as_float_images() {
    let dir = tempfile::tempdir().unwrap();
    let out = whitted(
        &[
            "render",
            "--width",
            "8",
            "--height",
            "6",
            "-o",
            "c.exr",
            "--aov",
            "depth=d.pfm",
            "--aov",
            "normal=n.exr",
            "--aov",
            "id=i.pfm",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stderr.is_empty() && out.stdout.is_empty());
    let depth = std::fs::read(dir.path().join("d.pfm")).unwrap();
    assert!(depth.starts_with(b"Pf\n8 6\n-1.0\n"));
    assert_eq!(depth.len(), b"Pf\n8 6\n-1.0\n".len() + 8 * 6 * 4);
    assert!(dir.path().join("n.exr").exists() && dir.path().join("c.exr").exists());
    assert!(dir.path().join("i.pfm").exists());
}

#[test]
fn a_missing_scene_file_fails_with_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = whitted(&["render", "nope.toml"], dir.path());
    assert!(!out.status.success());
    assert!(stderr(&out).contains("nope.toml"), "{}", stderr(&out));
    assert!(!dir.path().join("whitted.png").exists());
}

#[test]
fn a_bad_scene_file_reports_every_error_with_its_location() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.toml"),
        "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\n\n[[objects]]\nshape = \"sphere\"\nradius = -1\ncolour = 3\n",
    )
    .unwrap();
    let out = whitted(&["render", "bad.toml"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("bad.toml:7:"), "{err}");
    assert!(err.contains("bad.toml:8:1"), "{err}");
    assert!(!dir.path().join("whitted.png").exists());
}

#[test]
fn an_nff_scene_renders_at_its_own_resolution_unless_overridden() {
    let dir = tempfile::tempdir().unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../whitted/tests/nff/spd_like.nff");
    let fixture = fixture.to_str().unwrap();
    let out = whitted(&["render", fixture, "-o", "a.png"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("64x48"), "{}", stderr(&out));
    let out = whitted(
        &[
            "render", fixture, "-o", "b.png", "--width", "16", "--height", "16",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("16x16"), "{}", stderr(&out));
    let out = whitted(
        &[
            "bench", fixture, "--accel", "linear", "--width", "8", "--height", "8", "--json",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_scene_of_an_unknown_format_is_refused_naming_the_formats() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.rib"), "").unwrap();
    let out = whitted(&["render", "scene.rib"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("expected a file ending in .toml, .nff, .obj or .bpt"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn unknown_output_formats_and_aovs_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let out = whitted(&["render", "-o", "x.bmp"], dir.path());
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains(".png, .exr or .pfm"),
        "{}",
        stderr(&out)
    );
    let out = whitted(&["render", "--aov", "depth=d.png"], dir.path());
    assert!(!out.status.success());
    assert!(stderr(&out).contains(".pfm or .exr"), "{}", stderr(&out));
}

#[test]
fn help_explains_the_render_command() {
    let dir = tempfile::tempdir().unwrap();
    let out = whitted(&["render", "--help"], dir.path());
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for word in [
        "--spp",
        "--max-depth",
        "--aov",
        "--threads",
        "built-in scene",
    ] {
        assert!(help.contains(word), "missing {word} in:\n{help}");
    }
}

fn scenes_folder() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// `value` as a finite number, or a failure naming `what`.
fn finite(value: &serde_json::Value, what: &str) -> f64 {
    let number = value
        .as_f64()
        .unwrap_or_else(|| panic!("{what} is not a number: {value}"));
    assert!(number.is_finite(), "{what} is {number}");
    number
}

#[test]
fn bench_json_reports_each_structure_and_the_work_of_each_ray_kind_consistently() {
    let dir = tempfile::tempdir().unwrap();
    // Seven bounded primitives: a quad, two spheres, a cone, a cylinder, a
    // hexagon and a patch's triangle.
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../whitted/tests/nff/spd_like.nff");
    let (width, height, primitives) = (16, 12, 7);
    let out = whitted(
        &[
            "bench",
            scene.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "12",
            "--runs",
            "1",
            "--json",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["primitives"], primitives);
    assert_eq!(
        (&report["width"], &report["height"]),
        (&width.into(), &height.into())
    );
    assert_eq!(report["runs"], 1);
    assert!(report["rays_from"].is_null());
    assert!(report["threads"].as_u64().unwrap() >= 1);
    let structures = report["structures"].as_array().unwrap();
    let names: Vec<&str> = structures
        .iter()
        .map(|s| s["accel"].as_str().unwrap())
        .collect();
    let all: Vec<&str> = whitted::accel::AccelKind::ALL
        .iter()
        .map(|k| k.name())
        .collect();
    assert_eq!(names, all);
    // The ray sets are made once and traced by every structure.
    let mut counts_of_first: Option<Vec<u64>> = None;
    for s in structures {
        let accel = s["accel"].as_str().unwrap();
        let what = |field: &str| format!("{accel} {field}");
        assert!(finite(&s["build_ms"], &what("build_ms")) >= 0.0);
        assert!(s["memory_bytes"].as_u64().unwrap() > 0, "{accel}");
        let nodes = s["nodes"].as_u64().unwrap();
        let leaves = s["leaves"].as_u64().unwrap();
        let references = s["references"].as_u64().unwrap();
        assert!(
            nodes >= 1 && leaves >= 1,
            "{accel}: {nodes} nodes, {leaves} leaves"
        );
        // Every primitive is stored at least once; the BVH and brute force
        // store each once, the kd-tree and the grid may store one in
        // several leaves.
        assert!(references >= primitives, "{accel}: {references} references");
        if accel == "bvh" || accel == "linear" {
            assert_eq!(references, primitives, "{accel}");
        }
        let sah_cost = finite(&s["sah_cost"], &what("sah_cost"));
        // The grid has no SAH cost (0); the others cost at least a test.
        if accel == "grid" {
            assert!(sah_cost >= 0.0);
        } else {
            assert!(sah_cost >= 1.0, "{accel}: SAH cost {sah_cost}");
        }
        if accel == "linear" {
            // One leaf of every primitive, tested one by one.
            assert_eq!((nodes, leaves, s["max_depth"].as_u64()), (1, 1, Some(0)));
            assert_eq!(sah_cost, primitives as f64);
        }

        let kinds = s["kinds"].as_array().unwrap();
        let names: Vec<&str> = kinds.iter().map(|k| k["rays"].as_str().unwrap()).collect();
        assert_eq!(names, ["primary", "shadow", "diffuse"]);
        let counts: Vec<u64> = kinds.iter().map(|k| k["count"].as_u64().unwrap()).collect();
        // One primary ray per pixel; one diffuse ray per primary hit; one
        // shadow ray per primary hit that faces the light.
        let [primary, shadow, diffuse] = counts[..] else {
            unreachable!()
        };
        assert_eq!(primary, width * height);
        assert!(
            0 < shadow && shadow <= diffuse && diffuse <= primary,
            "{counts:?}"
        );
        assert_eq!(
            counts_of_first.get_or_insert_with(|| counts.clone()),
            &counts,
            "{accel}"
        );
        for k in kinds {
            let kind = k["rays"].as_str().unwrap();
            let what = |field: &str| format!("{accel} {kind} {field}");
            assert!(finite(&k["mrays_per_s_1_thread"], &what("Mrays/s")) > 0.0);
            assert!(finite(&k["mrays_per_s_all_threads"], &what("Mrays/s")) > 0.0);
            assert!(k["agreeing"].is_null(), "{}", what("agreeing"));
            let nodes_per_ray = finite(&k["nodes_per_ray"], &what("nodes per ray"));
            let primitives_per_ray = finite(&k["primitives_per_ray"], &what("primitives per ray"));
            // Each ray enters some nodes and tests some primitives, no
            // node or leaf twice and no reference twice (brute force's
            // `nodes` per ray are its boxes: below).
            assert!(0.0 < nodes_per_ray, "{}", what("nodes per ray"));
            assert!(
                accel == "linear" || nodes_per_ray <= (nodes + leaves) as f64,
                "{}: {nodes_per_ray}",
                what("nodes per ray")
            );
            assert!(
                0.0 < primitives_per_ray && primitives_per_ray <= references as f64,
                "{}: {primitives_per_ray}",
                what("primitives per ray")
            );
            if accel == "linear" {
                // Brute force tests every primitive's box (its `nodes`) and
                // the primitives whose box the ray meets. A closest hit
                // never stops early: every box, for every ray; an any-hit
                // query stops at the first blocker.
                if kind == "shadow" {
                    assert!(nodes_per_ray <= primitives as f64, "{nodes_per_ray}");
                } else {
                    assert_eq!(nodes_per_ray, primitives as f64, "{}", what("boxes"));
                }
                assert!(primitives_per_ray <= nodes_per_ray, "{}", what("tests"));
            }
        }
    }
}

/// One ray record of the anchor harness's dump format.
fn ray_record(o: [f32; 3], d: [f32; 3], t_far: f32) -> Vec<u8> {
    let mut r = 0u32.to_le_bytes().to_vec();
    for v in o.iter().chain(&d).chain(&[t_far]) {
        r.extend_from_slice(&v.to_le_bytes());
    }
    r
}

#[test]
fn bench_walks_closest_hits_in_packets_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../whitted/tests/nff/spd_like.nff");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "bench",
            scene.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "24",
            "--runs",
            "1",
        ];
        args.extend_from_slice(extra);
        let out = whitted(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        String::from_utf8(out.stdout).unwrap()
    };
    // The packet walk runs on AVX, over a BVH; elsewhere (or with a
    // narrower backend asked for) the bench says the rays went one at a
    // time.
    let avx = whitted::accel::Backend::current().has_avx();
    let table = run(&["--accel", "bvh", "--packets"]);
    let line = if avx {
        "rays in packets of 8"
    } else {
        "rays one at a time"
    };
    assert!(table.contains(line), "{table}");
    let kd = run(&["--accel", "kdtree", "--packets"]);
    assert!(kd.contains("rays one at a time"), "{kd}");
    let json = run(&["--accel", "bvh", "--packets", "--json"]);
    let report: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(report["packets"], true);
    assert_eq!(report["structures"][0]["packets"], avx);
    for kind in report["structures"][0]["kinds"].as_array().unwrap() {
        assert!(
            finite(&kind["mrays_per_s_1_thread"], "rate") > 0.0,
            "{kind}"
        );
    }
    let single: serde_json::Value =
        serde_json::from_str(&run(&["--accel", "bvh", "--json"])).unwrap();
    assert_eq!(single["packets"], false);
    assert_eq!(single["structures"][0]["packets"], false);
}

#[test]
fn bench_traces_anchor_ray_files_and_counts_agreement() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A unit square at z = 0 made of two triangles (a quad, fan-split).
    std::fs::write(
        d.join("quad.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let rays: Vec<u8> = [
        ray_record([0.25, 0.75, 1.0], [0.0, 0.0, -1.0], f32::INFINITY),
        ray_record([0.75, 0.25, 2.0], [0.0, 0.0, -1.0], f32::INFINITY),
        ray_record([2.0, 2.0, 1.0], [0.0, 0.0, -1.0], f32::INFINITY),
    ]
    .concat();
    let mut hits = Vec::new();
    for (t, id) in [(1.0f32, 1u32), (2.0, 0), (-1.0, 0)] {
        hits.extend(t.to_le_bytes());
        hits.extend(id.to_le_bytes());
    }
    for kind in ["primary", "diffuse"] {
        std::fs::write(d.join(format!("{kind}.rays")), &rays).unwrap();
        std::fs::write(d.join(format!("{kind}.hits")), &hits).unwrap();
    }
    // Shadow rays: the first is blocked by the quad, the second stops short.
    let shadow: Vec<u8> = [
        ray_record([0.5, 0.5, 1.0], [0.0, 0.0, -1.0], 3.0),
        ray_record([0.5, 0.5, 1.0], [0.0, 0.0, -1.0], 0.5),
    ]
    .concat();
    std::fs::write(d.join("shadow.rays"), shadow).unwrap();
    std::fs::write(d.join("shadow.hits"), [1u8, 1]).unwrap();
    let out = whitted(
        &["bench", "quad.obj", "--rays", ".", "--runs", "1", "--json"],
        d,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["primitives"], 2);
    for s in report["structures"].as_array().unwrap() {
        let agreeing: Vec<u64> = s["kinds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k["agreeing"].as_u64().unwrap())
            .collect();
        // All closest hits agree; the second shadow ray disagrees on purpose.
        assert_eq!(agreeing, [3, 1, 3], "{}", s["accel"]);
    }
}

#[test]
fn bench_refuses_unknown_structures_and_missing_ray_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scenes_folder().join("whitted.toml");
    let out = whitted(
        &["bench", scene.to_str().unwrap(), "--accel", "octree"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("`octree` is not a structure; expected all, or one or more of"),
        "{}",
        stderr(&out)
    );
    let out = whitted(
        &["bench", scene.to_str().unwrap(), "--rays", "nowhere"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("primary.rays"), "{}", stderr(&out));
}

#[test]
fn outputs_into_missing_folders_or_the_same_file_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let out = whitted(&["render", "-o", "missing/x.png"], dir.path());
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("the folder missing does not exist"),
        "{}",
        stderr(&out)
    );
    assert!(
        !stderr(&out).contains("Mrays/s"),
        "rendered anyway: {}",
        stderr(&out)
    );
    let out = whitted(
        &["render", "-o", "a.exr", "--aov", "depth=a.exr"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("already an output"),
        "{}",
        stderr(&out)
    );
    let out = whitted(&["render", "--aov", "depth=missing/d.pfm"], dir.path());
    assert!(!out.status.success());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn camera_overrides_replace_parts_of_the_scene_camera_and_bad_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let small = ["render", "--width", "8", "--height", "6", "--quiet"];
    let args = [
        &small[..],
        &[
            "--eye",
            "0,1,-8",
            "--look-at",
            "0,0,0",
            "--up",
            "0,1,0",
            "--fov",
            "30",
        ],
    ]
    .concat();
    let out = whitted(&args, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let moved = std::fs::read(dir.path().join("whitted.png")).unwrap();
    let out = whitted(&small, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let original = std::fs::read(dir.path().join("whitted.png")).unwrap();
    assert_ne!(moved, original);

    let out = whitted(&[&small[..], &["--eye", "1,2"]].concat(), dir.path());
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("expected three finite numbers separated by commas"),
        "{}",
        stderr(&out)
    );
    let out = whitted(&[&small[..], &["--fov", "200"]].concat(), dir.path());
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains(
            "invalid value '200' for '--fov <DEG>': 200 degrees is out of range; \
             expected degrees between 0 and 180 (both excluded)"
        ),
        "{}",
        stderr(&out)
    );
}

#[test]
fn bench_prints_the_scene_readers_warnings() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("tri.obj"),
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("s.toml"),
        "[camera]\neye = [0.3, 0.3, 3]\nlook_at = [0.3, 0.3, 0]\nfov = 40\n\
         [definitions.tri]\nmesh = 'tri.obj'\n[[objects]]\ninstance = 'tri'\n",
    )
    .unwrap();
    let args = ["bench", "s.toml", "--width", "8", "--height", "6"];
    let out = whitted(&[&args[..], &["--accel", "bvh"]].concat(), dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("tri.obj:1:8: warning: cannot read the material library"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn an_obj_model_renders_with_its_warnings_printed() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("tri.obj");
    std::fs::write(
        &model,
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let out = whitted(
        &[
            "render",
            "tri.obj",
            "--width",
            "8",
            "--height",
            "6",
            "--eye",
            "0.3,0.3,3",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("tri.obj:1:8: warning: cannot read the material library"),
        "{}",
        stderr(&out)
    );
    assert!(dir.path().join("whitted.png").exists());
}

#[test]
fn stats_break_the_time_down_by_stage_and_the_rays_by_kind() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scenes_folder().join("caustics.toml");
    let out = whitted(
        &[
            "render",
            scene.to_str().unwrap(),
            "-q",
            "--stats",
            "--width",
            "40",
            "--height",
            "30",
            "--photons",
            "2000",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stderr(&out);
    let stages: Vec<&str> = text
        .lines()
        .filter_map(|line| line.strip_prefix("  ")?.split_whitespace().next())
        .collect();
    assert_eq!(
        stages,
        [
            "load",
            "build",
            "photons",
            "trace",
            "other",
            "write",
            "total",
            "primary",
            "shadow",
            "reflected",
            "refracted",
            "all"
        ],
        "{text}"
    );
    // Only the stats: --quiet keeps the summary line away.
    assert!(text.starts_with("stats:\n"), "{text}");
    assert!(dir.path().join("whitted.png").exists());
}
