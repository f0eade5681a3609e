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
