//! A frame split over workers (`whitted render --tile`, `--crop`) and
//! merged (`whitted merge`) is the single render, bit for bit; parts that
//! do not fit together are refused naming the one at fault; a stopped
//! worker leaves no part.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn whitted(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn succeeds(args: &[&str], dir: &Path) {
    let out = whitted(args, dir);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The error message of a command that must fail.
fn fails(args: &[&str], dir: &Path) -> String {
    let out = whitted(args, dir);
    assert_eq!(out.status.code(), Some(1), "{args:?} did not fail");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn scene_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/whitted.toml")
}

const PICTURE: [&str; 6] = ["--width", "61", "--height", "37", "--spp", "3"];

/// Every output of the single render and of the merge, by file name.
const OUTPUTS: [(&str, &str); 10] = [
    ("-o", "image.png"),
    ("-o", "image.exr"),
    ("-o", "image.pfm"),
    ("--aov", "depth=depth.pfm"),
    ("--aov", "normal=normal.exr"),
    ("--aov", "id=id.pfm"),
    ("--aov", "instance=instance.exr"),
    ("--aov", "cost=cost.exr"),
    ("--aov", "cost=cost.png"),
    ("--aov", "depth=depth.exr"),
];

/// Renders `scene` in `count` tiles with every AOV into `dir/parts`.
fn render_tiles(scene: &str, count: u32, dir: &Path) -> Vec<String> {
    std::fs::create_dir_all(dir.join("parts")).unwrap();
    (0..count)
        .map(|i| {
            let part = format!("parts/{i}.wpart");
            let tile = format!("{i}/{count}");
            let mut args = vec!["render", scene, "--tile", &tile, "-o", &part, "-q"];
            args.extend(PICTURE);
            args.extend(["--aov", "depth", "--aov", "normal", "--aov", "id"]);
            args.extend(["--aov", "cost", "--aov", "instance"]);
            succeeds(&args, dir);
            part
        })
        .collect()
}

#[test]
fn merged_tiles_are_the_single_render_bit_for_bit_in_every_format_and_aov() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file();
    let scene = scene.to_str().unwrap();
    let parts = render_tiles(scene, 3, dir.path());
    std::fs::create_dir_all(dir.path().join("single")).unwrap();
    std::fs::create_dir_all(dir.path().join("merged")).unwrap();
    // One command per image format, each with the AOVs that fit it.
    for (image, aovs) in [
        (0, &OUTPUTS[3..8]),
        (1, &OUTPUTS[8..9]),
        (2, &OUTPUTS[9..10]),
    ] {
        let (_, name) = OUTPUTS[image];
        let outputs = |folder: &str| -> Vec<String> {
            let mut args = vec!["-o".to_string(), format!("{folder}/{name}")];
            for (option, spec) in aovs {
                let (aov, file) = spec.split_once('=').unwrap();
                args.extend([option.to_string(), format!("{aov}={folder}/{file}")]);
            }
            args
        };
        let mut single = vec!["render", scene, "-q"];
        single.extend(PICTURE);
        let single_outputs = outputs("single");
        single.extend(single_outputs.iter().map(String::as_str));
        succeeds(&single, dir.path());
        let mut merge: Vec<&str> = vec!["merge", "-q"];
        merge.extend(parts.iter().rev().map(String::as_str));
        let merged_outputs = outputs("merged");
        merge.extend(merged_outputs.iter().map(String::as_str));
        succeeds(&merge, dir.path());
    }
    for (_, spec) in OUTPUTS {
        let file = spec.split('=').next_back().unwrap();
        let single = std::fs::read(dir.path().join("single").join(file)).unwrap();
        let merged = std::fs::read(dir.path().join("merged").join(file)).unwrap();
        assert!(single == merged, "{file} differs");
    }
}

#[test]
fn parts_that_do_not_make_one_frame_are_refused_naming_the_culprit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::copy(scene_file(), &scene).unwrap();
    let parts = render_tiles("scene.toml", 3, dir.path());
    let merge = |parts: &[&str]| {
        let mut args = vec!["merge", "-o", "out.png"];
        args.extend(parts);
        fails(&args, dir.path())
    };
    let error = merge(&[&parts[0], &parts[2]]);
    assert!(
        error.contains("in no part, the first at column 0, row 1; missing: tile 1/3"),
        "{error}"
    );
    let error = merge(&[&parts[0], &parts[1], &parts[2], &parts[1]]);
    assert!(
        error.contains("parts/1.wpart: pixel (0, 1) is also in parts/1.wpart"),
        "{error}"
    );
    // The same scene file, changed by one comment: another render.
    std::fs::write(
        &scene,
        std::fs::read_to_string(&scene).unwrap() + "# changed\n",
    )
    .unwrap();
    let mut args = vec![
        "render",
        "scene.toml",
        "--tile",
        "1/3",
        "-o",
        "other.wpart",
        "-q",
    ];
    args.extend(PICTURE);
    args.extend(["--aov", "depth", "--aov", "normal", "--aov", "id"]);
    args.extend(["--aov", "cost"]);
    succeeds(&args, dir.path());
    let error = merge(&[&parts[0], "other.wpart", &parts[2]]);
    assert!(
        error.contains(
            "error: other.wpart: not a part of the same render as parts/0.wpart: its \
             scene-sha256 is"
        ),
        "{error}"
    );
    let error = merge(&["scene.toml"]);
    assert!(
        error.contains("scene.toml:1: not a whitted part"),
        "{error}"
    );
    assert!(!dir.path().join("out.png").exists());
    let error = fails(
        &[
            "merge",
            &parts[0],
            &parts[1],
            &parts[2],
            "-o",
            "out.png",
            "--aov",
            "depth=d.pfm",
            "--aov",
            "albedo=a.pfm",
        ],
        dir.path(),
    );
    assert!(error.contains("unknown AOV `albedo`"), "{error}");
    let error = fails(&["render", "--tile", "0/2", "-o", "x.png"], dir.path());
    assert!(error.contains("name the output NAME.wpart"), "{error}");
    let error = fails(
        &["render", "--crop", "0,0,700,10", "-o", "x.wpart"],
        dir.path(),
    );
    assert!(
        error.contains("--crop 0,0,700,10: the window 0,0,700,10 does not fit the 640x480 image"),
        "{error}"
    );
}

#[test]
fn a_missing_aov_is_named_and_crops_merge_like_tiles() {
    let dir = tempfile::tempdir().unwrap();
    for (crop, part) in [("0,0,40,20", "a.wpart"), ("0,20,40,30", "b.wpart")] {
        succeeds(
            &[
                "render", "--width", "40", "--height", "30", "--crop", crop, "-o", part, "-q",
            ],
            dir.path(),
        );
    }
    succeeds(
        &[
            "render",
            "--width",
            "40",
            "--height",
            "30",
            "-o",
            "single.pfm",
            "-q",
        ],
        dir.path(),
    );
    succeeds(
        &["merge", "a.wpart", "b.wpart", "-o", "merged.pfm", "-q"],
        dir.path(),
    );
    assert_eq!(
        std::fs::read(dir.path().join("single.pfm")).unwrap(),
        std::fs::read(dir.path().join("merged.pfm")).unwrap()
    );
    let error = fails(
        &[
            "merge",
            "a.wpart",
            "b.wpart",
            "-o",
            "m.png",
            "--aov",
            "depth=d.pfm",
        ],
        dir.path(),
    );
    assert!(
        error.contains("--aov depth=d.pfm: the parts hold no depth AOV (they hold none)"),
        "{error}"
    );
}

/// A worker stopped by SIGTERM or SIGKILL at any moment leaves either its
/// whole part or nothing named like one; rendering that tile again
/// completes the frame.
#[cfg(unix)]
#[test]
fn a_stopped_worker_leaves_no_part_and_its_tile_can_be_rendered_again() {
    let dir = tempfile::tempdir().unwrap();
    let tile = |i: u32| -> Vec<String> {
        [
            "render",
            "--tile",
            &format!("{i}/2"),
            "-o",
            &format!("{i}.wpart"),
            "-q",
        ]
        .map(String::from)
        .into()
    };
    succeeds(
        &tile(0).iter().map(String::as_str).collect::<Vec<_>>(),
        dir.path(),
    );
    for (signal, delay) in [(libc::SIGTERM, 200), (libc::SIGKILL, 300)] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_whitted"))
            .args(tile(1))
            .current_dir(dir.path())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay));
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let status = child.wait().unwrap();
        let part = dir.path().join("1.wpart");
        if status.success() {
            // It finished first: the part is whole, so it merges.
            std::fs::remove_file(part).unwrap();
            continue;
        }
        assert!(!part.exists(), "a stopped worker left {}", part.display());
        if signal == libc::SIGTERM {
            assert_eq!(std::os::unix::process::ExitStatusExt::signal(&status), None);
            assert_eq!(status.code(), Some(143));
        }
        let error = fails(&["merge", "0.wpart", "-o", "m.png"], dir.path());
        assert!(error.contains("missing: tile 1/2"), "{error}");
    }
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with(".whitted-"))
        .collect();
    assert_eq!(names, ["0.wpart"]);
    succeeds(
        &tile(1).iter().map(String::as_str).collect::<Vec<_>>(),
        dir.path(),
    );
    succeeds(
        &["merge", "0.wpart", "1.wpart", "-o", "m.png", "-q"],
        dir.path(),
    );
    succeeds(&["render", "-o", "single.png", "-q"], dir.path());
    assert_eq!(
        std::fs::read(dir.path().join("single.png")).unwrap(),
        std::fs::read(dir.path().join("m.png")).unwrap()
    );
}

#[test]
fn with_photons_every_worker_builds_the_same_map_and_the_merge_is_the_single_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/caustics.toml");
    let scene = scene.to_str().unwrap();
    let picture = ["--width", "48", "--height", "30", "-q", "--photons"];
    let mut single = vec!["render", scene, "-o", "single.pfm"];
    single.extend(picture);
    single.push("20000");
    succeeds(&single, dir.path());
    for (i, photons) in [(0, "20000"), (1, "20000"), (1, "10000")] {
        let part = format!("{i}-{photons}.wpart");
        let tile = format!("{i}/2");
        let mut args = vec!["render", scene, "--tile", &tile, "-o", &part];
        args.extend(picture);
        args.push(photons);
        succeeds(&args, dir.path());
    }
    succeeds(
        &[
            "merge",
            "-q",
            "0-20000.wpart",
            "1-20000.wpart",
            "-o",
            "merged.pfm",
        ],
        dir.path(),
    );
    let single = std::fs::read(dir.path().join("single.pfm")).unwrap();
    let merged = std::fs::read(dir.path().join("merged.pfm")).unwrap();
    assert!(
        single == merged,
        "the merged caustics differ from the single render"
    );
    let refused = fails(
        &["merge", "0-20000.wpart", "1-10000.wpart", "-o", "mixed.pfm"],
        dir.path(),
    );
    assert!(refused.contains("1-10000.wpart"), "{refused}");
}
