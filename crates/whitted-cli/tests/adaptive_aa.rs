//! `whitted render --aa adaptive` as a user runs it: the options, the
//! summary, and a frame split over workers merging into the single render.

use std::path::{Path, PathBuf};
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

fn scene_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/whitted.toml")
}

const PICTURE: [&str; 8] = [
    "--width",
    "45",
    "--height",
    "33",
    "--aa",
    "adaptive",
    "--aa-threshold",
    "0.1",
];

#[test]
fn adaptive_renders_say_so_and_trace_more_than_the_corners() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file();
    let mut args = vec!["render", scene.to_str().unwrap(), "-o", "a.png"];
    args.extend(PICTURE);
    let out = whitted(&args, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let summary = stderr(&out);
    assert!(
        summary.contains("45x33, adaptive anti-aliasing (threshold 0.1, depth 3)"),
        "{summary}"
    );
    let primary: u64 = summary
        .split(" primary")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{summary}"));
    assert!(primary > 46 * 34, "{summary}");
}

#[test]
fn threshold_or_depth_without_adaptive_and_bad_values_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = whitted(&["render", "--aa-depth", "2"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("add --aa adaptive"),
        "{}",
        stderr(&out)
    );
    for bad in [
        ["--aa", "jitter"],
        ["--aa-depth", "7"],
        ["--aa-threshold", "-0.1"],
    ] {
        let out = whitted(&["render", bad[0], bad[1]], dir.path());
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        assert!(stderr(&out).contains(bad[1]), "{}", stderr(&out));
    }
    assert!(!dir.path().join("whitted.png").exists());
}

#[test]
fn adaptive_tiles_and_crops_merge_into_the_single_render_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file();
    let scene = scene.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["render", scene, "-q"];
        args.extend(PICTURE);
        args.extend(extra);
        let out = whitted(&args, dir.path());
        assert!(out.status.success(), "{extra:?}: {}", stderr(&out));
    };
    run(&["-o", "single.pfm"]);
    run(&["--tile", "0/3", "-o", "t0.wpart"]);
    run(&["--tile", "1/3", "-o", "t1.wpart"]);
    run(&["--tile", "2/3", "-o", "t2.wpart"]);
    run(&["--crop", "0,0,45,20", "-o", "c0.wpart"]);
    run(&["--crop", "0,20,45,33", "-o", "c1.wpart"]);
    let single = std::fs::read(dir.path().join("single.pfm")).unwrap();
    for (parts, name) in [
        (&["t2.wpart", "t0.wpart", "t1.wpart"][..], "tiles.pfm"),
        (&["c0.wpart", "c1.wpart"][..], "crops.pfm"),
    ] {
        let mut args = vec!["merge", "-q"];
        args.extend(parts);
        args.extend(["-o", name]);
        let out = whitted(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        let merged = std::fs::read(dir.path().join(name)).unwrap();
        assert!(merged == single, "{name} differs from the single render");
    }
}
