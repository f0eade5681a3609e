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

#[test]
fn an_exporters_model_loads_with_located_warnings() {
    let dir = tempfile::tempdir().unwrap();
    // Several libraries on one line, one of them missing, one with an
    // escaped space; normals commented out but still named by the faces.
    std::fs::write(
        dir.path().join("a.obj"),
        "mtllib a.mtl gone.mtl my\\ b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n# vn 0 0 1\n\
         usemtl red\nf 1//1 2//1 3//1\nusemtl blue\nf 1//1 3//1 2//1\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("a.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    std::fs::write(
        dir.path().join("my b.mtl"),
        "newmtl blue\nKd 0 0 1\nmap_Kd -colorspace sRGB -halo 2 -o 0.1 texture 01.png\n",
    )
    .unwrap();
    // Before: every material lost ("cannot read the material library
    // `a.mtl gone.mtl my\ b.mtl`"), then "normal index 1 is out of range"
    // refused the file.
    let p = render(dir.path(), "a.obj", false);
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    let shown = warnings(&p.stderr);
    assert_eq!(shown.len(), 4, "{}", p.stderr);
    assert!(
        shown[0].starts_with("a.obj:1:14: warning: cannot read the material library `")
            && shown[0].ends_with(
                "gone.mtl` (No such file or directory (os error 2)); its materials are grey"
            ),
        "{}",
        shown[0]
    );
    assert!(
        shown[1].starts_with(
            "a.obj:7:6: warning: normal index 1 is out of range: 0 normals are defined before this line"
        ),
        "{}",
        shown[1]
    );
    assert_eq!(
        shown[2],
        "my b.mtl:3:25: warning: unknown texture map option `-halo`; ignored with `2`, \
         the file is `texture 01.png`"
    );
    assert!(
        shown[3].starts_with("my b.mtl:3:40: warning: cannot read the image `texture 01.png`"),
        "{}",
        shown[3]
    );
    assert!(dir.path().join("out.png").is_file());
}
