//! OBJ and MTL files as other tools write them, text encodings, and the
//! warnings a model may cause: each case runs `whitted render` on the file.

use std::path::Path;
use std::time::{Duration, Instant};

use crate::support::{MIB, Probe, probe};

/// Renders `scene` in `dir` to a tiny image, `--quiet` or not.
fn render(dir: &Path, scene: &str, quiet: bool) -> Probe {
    let mut args = vec![
        "render", scene, "--width", "8", "--height", "6", "-o", "out.png",
    ];
    if quiet {
        args.push("--quiet");
    }
    probe(&args, dir)
}

/// The first line of each warning `whitted` printed.
fn warnings(stderr: &str) -> Vec<&str> {
    stderr
        .lines()
        .filter(|l| l.contains(": warning: "))
        .collect()
}

/// Three vertices, then `faces`.
fn triangle(faces: &str) -> String {
    format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{faces}")
}

#[test]
fn sixteen_thousand_unknown_materials_give_a_hundred_warnings_and_none_when_quiet() {
    let dir = tempfile::tempdir().unwrap();
    let uses: String = (0..16_000)
        .map(|i| format!("usemtl m{i}\nf 1 2 3\n"))
        .collect();
    std::fs::write(dir.path().join("many.obj"), triangle(&uses)).unwrap();
    let start = Instant::now();
    let quiet = render(dir.path(), "many.obj", true);
    let took = start.elapsed();
    assert_eq!(quiet.code(), Some(0), "{}", quiet.stderr);
    assert_eq!(quiet.stderr, "");
    // Before, 3.4 s in release (quadratic: 200,000 names took a minute).
    assert!(took < Duration::from_secs(5), "{took:?}");
    assert!(quiet.peak_bytes < 200 * MIB, "{}", quiet.peak_bytes);

    let told = render(dir.path(), "many.obj", false);
    assert_eq!(told.code(), Some(0), "{}", told.stderr);
    let shown = warnings(&told.stderr);
    assert_eq!(shown.len(), 101, "{}", told.stderr);
    assert_eq!(
        shown[0],
        "many.obj:4:8: warning: no material `m0` in the material libraries; it is grey"
    );
    assert_eq!(
        shown[100],
        "many.obj:204:8: warning: too many warnings: the first 100 are reported, \
         the rest from here on are not"
    );
    assert!(told.stderr.len() < 20_000, "{}", told.stderr.len());
}

#[test]
fn a_byte_order_mark_hides_no_vertex_and_no_entity() {
    let dir = tempfile::tempdir().unwrap();
    let bom = '\u{feff}';
    std::fs::write(
        dir.path().join("a.obj"),
        format!("{bom}v 0 0 0\nv 1 0 0\nv 0 1 0\nmtllib a.mtl\nusemtl red\nf 1 2 3\n"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("a.mtl"),
        format!("{bom}newmtl red\nKd 1 0 0\n"),
    )
    .unwrap();
    // Before: "vertex index 3 is out of range: 2 vertices are defined".
    let p = render(dir.path(), "a.obj", false);
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    assert_eq!(warnings(&p.stderr), Vec::<&str>::new());

    std::fs::write(
        dir.path().join("a.nff"),
        format!(
            "{bom}b 0 0 1\nv\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 30\nhither 1\nresolution 8 6\n"
        ),
    )
    .unwrap();
    // Before: "a.nff:1:1: error: unknown entity `b`".
    let p = render(dir.path(), "a.nff", true);
    assert_eq!((p.code(), p.stderr.as_str()), (Some(0), ""));
    assert!(dir.path().join("out.png").is_file());
}

#[test]
fn a_negative_mtl_colour_is_refused_at_its_place() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("a.obj"),
        triangle("mtllib a.mtl\nusemtl dark\nf 1 2 3\n"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("a.mtl"),
        "newmtl dark\nKe 0 0 0\nKd -1 -1 -1\n",
    )
    .unwrap();
    let p = render(dir.path(), "a.obj", true);
    assert_eq!(p.code(), Some(1), "{}", p.stderr);
    assert!(
        p.stderr
            .contains("a.mtl:3:4: error: the colour `Kd` must not be negative, got -1\n"),
        "{}",
        p.stderr
    );
    assert!(!dir.path().join("out.png").exists());
}
