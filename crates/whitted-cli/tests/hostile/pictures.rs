//! Wrong pictures without a word and numbers out of range (issue 23, items
//! 13, 16, 17, 18, 21 and part of 19): every number that multiplies into
//! radiance or is squared in intersection is bounded where it is read, with
//! its place and the true cause; a colour output never holds inf or NaN.

use std::path::Path;

use crate::support::{Probe, probe};

/// The camera of the small TOML scenes below.
const CAMERA: &str = "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
                      [render]\nwidth = 16\nheight = 16\n";

/// A unit sphere at the origin lit from the eye, with `extra` keys (a
/// material, a light's own keys) around it.
fn lit_sphere(light: &str, object: &str) -> String {
    format!(
        "{CAMERA}[[lights]]\ntype = 'point'\nposition = [0, 0, 5]\n{light}\n\
         [[objects]]\nshape = 'sphere'\nradius = 1\n{object}\n"
    )
}

/// Renders `file` (written with `text`) to `out.pfm` in a fresh folder.
fn render(file: &str, text: &str) -> (Probe, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(file), text).unwrap();
    let p = probe(&["render", file, "-o", "out.pfm"], dir.path());
    (p, dir)
}

/// Asserts that `p` failed with `message` as its only error and wrote no
/// picture in `dir`.
fn refused(p: &Probe, dir: &Path, message: &str) {
    assert_eq!(p.code(), Some(1), "{}", p.stderr);
    assert!(p.stderr.contains(message), "{}", p.stderr);
    assert!(!dir.join("out.pfm").exists());
}

/// The pixels of a PFM file written by whitted (colour, bottom row first).
fn pfm_pixels(path: &Path) -> Vec<[f32; 3]> {
    let bytes = std::fs::read(path).unwrap();
    let mut header_end = 0;
    for _ in 0..3 {
        header_end += bytes[header_end..]
            .iter()
            .position(|&b| b == b'\n')
            .unwrap()
            + 1;
    }
    assert!(bytes.starts_with(b"PF\n"));
    bytes[header_end..]
        .chunks_exact(12)
        .map(|p| {
            let f = |i: usize| f32::from_le_bytes(p[i..i + 4].try_into().unwrap());
            [f(0), f(4), f(8)]
        })
        .collect()
}

#[test]
fn a_flat_obj_is_framed_from_its_normal_side_and_seen() {
    let quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n";
    let (p, dir) = render("quad.obj", quad);
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    let pixels = pfm_pixels(&dir.path().join("out.pfm"));
    let lit = pixels.iter().filter(|c| c[0] > 0.1).count();
    assert!(
        lit > pixels.len() / 4,
        "{lit} of {} pixels lit",
        pixels.len()
    );
}

#[test]
fn radiance_factors_beyond_range_are_refused_where_written() {
    for (light, object, message) in [
        (
            "intensity = 1e39",
            "",
            "t.toml:10:13: error: `intensity` is out of range: 1e39 is too large: at most 1e12",
        ),
        (
            "attenuation = [1e-308, 0, 0]",
            "",
            "t.toml:10:16: error: `attenuation` is out of range: 1e-308 is too small: a non-zero \
             number that divides the light must be at least 1e-12",
        ),
        (
            "[materials.hot]\nemission = 1e39",
            "material = 'hot'",
            "t.toml:11:12: error: `emission` is out of range: 1e39 is too large",
        ),
        (
            "[materials.red]\ndiffuse = [1e308, 0, 0]",
            "material = 'red'",
            "t.toml:11:12: error: `diffuse` is out of range: 1e308 is too large",
        ),
    ] {
        let (p, dir) = render("t.toml", &lit_sphere(light, object));
        refused(&p, dir.path(), message);
    }
}

#[test]
fn radiance_factors_beyond_range_are_refused_in_nff_and_mtl_too() {
    let nff = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\n\
               l 0 0 5 1e20 1 1\nf 1 1 1 1 0 0 0 1\ns 0 0 0 1\n";
    let (p, dir) = render("t.nff", nff);
    refused(
        &p,
        dir.path(),
        "t.nff:8:9: error: the light's colour is out of range: 1e20 is too large: at most 1e12",
    );

    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lamp.mtl"), "newmtl lamp\nKe 1e39 1 1\n").unwrap();
    let obj = "mtllib lamp.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n";
    std::fs::write(dir.path().join("t.obj"), obj).unwrap();
    let p = probe(&["render", "t.obj", "-o", "out.pfm"], dir.path());
    refused(
        &p,
        dir.path(),
        "lamp.mtl:2:4: error: `Ke` 1e39 is out of range: 1e39 is too large",
    );
}

#[test]
fn a_render_whose_colours_still_overflow_is_refused_and_writes_nothing() {
    // Inside a mirror sphere that emits: each bounce multiplies by 1e12.
    let scene = "[camera]\neye = [0, 0, 0]\nlook_at = [0, 0, -1]\n\
                 [render]\nwidth = 8\nheight = 8\n\
                 [materials.mirror]\nemission = 1e12\nreflection = 1e12\n\
                 [[objects]]\nshape = 'sphere'\nradius = 10\nmaterial = 'mirror'\n";
    let (p, dir) = render("t.toml", scene);
    refused(
        &p,
        dir.path(),
        "error: 64 pixel(s) came out with a colour that is not a finite number (the first at \
         column 0, row 0)",
    );
}

#[test]
fn shapes_whose_squares_overflow_or_underflow_are_refused_at_their_key() {
    for (object, message) in [
        (
            "shape = 'sphere'\nradius = 2e154",
            "t.toml:9:10: error: radius is out of range: 2e154 is too large: at most 1e30 in \
             magnitude is allowed",
        ),
        (
            "shape = 'cone'\nbase = [0, 0, 0]\nbase_radius = 1\ntop = [0, 0, 1e-300]\n\
             top_radius = 0",
            "t.toml:11:7: error: the height from `base` to `top` is out of range: 1e-300 is too \
             small: a non-zero length must be at least 1e-30",
        ),
        (
            "shape = 'sphere'\nradius = 1\ntransform = { scale = 1e103 }",
            "t.toml:10:23: error: the transform's scale factor is out of range: 1e103 is too \
             large: at most 1e30 in magnitude is allowed",
        ),
        (
            "shape = 'disk'\ncenter = [0, 0, 0]\nnormal = [0, 0, 1]\nradius = 1\n\
             inner_radius = 1e-300",
            "t.toml:12:16: error: inner_radius is out of range: 1e-300 is too small",
        ),
        (
            "shape = 'sphere'\nradius = 1e20\ntransform = [{ scale = 1e20 }]",
            "t.toml:10:13: error: the object reaches out of range in the world: 1e40 is too large",
        ),
    ] {
        let (p, dir) = render("t.toml", &format!("{CAMERA}[[objects]]\n{object}\n"));
        refused(&p, dir.path(), message);
    }
}

#[test]
fn a_model_too_large_to_represent_is_refused_at_its_coordinates() {
    let obj = "v -1e308 0 0\nv 1e308 0 0\nv 0 1 0\nf 1 2 3\n";
    let (p, dir) = render("t.obj", obj);
    refused(
        &p,
        dir.path(),
        "t.obj:1:3: error: `-1e308` is out of range: -1e308 is too large: at most 1e30 in \
         magnitude is allowed",
    );
    assert!(!p.stderr.contains("same point"), "{}", p.stderr);
}

#[test]
fn a_bow_tie_polygon_renders_by_the_even_odd_rule() {
    let scene = format!(
        "{CAMERA}[[lights]]\ntype = 'point'\nposition = [0, 0, 5]\n\
         [[objects]]\nshape = 'polygon'\n\
         vertices = [[-1, -1, 0], [1, 1, 0], [1, -1, 0], [-1, 1, 0]]\n"
    );
    let (p, dir) = render("t.toml", &scene);
    assert_eq!(p.code(), Some(0), "{}", p.stderr);
    let pixels = pfm_pixels(&dir.path().join("out.pfm"));
    // 16x16, rows bottom first: the lobes are left and right of the
    // centre, the wedges above and below it are empty.
    let at = |x: usize, y_from_top: usize| pixels[(15 - y_from_top) * 16 + x][0];
    assert!(at(5, 8) > 0.1 && at(10, 8) > 0.1, "the lobes are dark");
    assert!(at(8, 5) == 0.0 && at(8, 10) == 0.0, "the wedges are lit");
}

#[test]
fn a_camera_out_of_range_is_refused_with_the_true_cause() {
    let dir = tempfile::tempdir().unwrap();
    let p = probe(
        &["render", "--eye", "3e38,3e38,3e38", "-o", "out.pfm"],
        dir.path(),
    );
    refused(
        &p,
        dir.path(),
        "the camera's eye is out of range: 3e38 is too large: at most 1e30 in magnitude is allowed",
    );
}

/// One 32-byte ray record of the Embree harness's dump format.
fn ray_record(origin: [f32; 3], dir: [f32; 3], t_far: f32) -> Vec<u8> {
    let mut record = 0u32.to_le_bytes().to_vec();
    for v in origin.iter().chain(&dir).chain(&[t_far]) {
        record.extend_from_slice(&v.to_le_bytes());
    }
    record
}

#[test]
fn bench_refuses_rays_that_cannot_be_traced_naming_file_and_index() {
    let good = ray_record([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], f32::INFINITY);
    for (bad, why) in [
        (
            ray_record([0.0; 3], [0.0; 3], 1.0),
            "the direction has zero length",
        ),
        (
            ray_record([f32::NAN, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0),
            "a value is not a finite number",
        ),
        (
            ray_record([3e38; 3], [0.0, 0.0, -1.0], f32::INFINITY),
            "the origin is out of range: 3",
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let rays = dir.path().join("rays");
        std::fs::create_dir(&rays).unwrap();
        let obj = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
        std::fs::write(dir.path().join("t.obj"), obj).unwrap();
        for kind in ["primary", "shadow", "diffuse"] {
            let records = [good.clone(), bad.clone()].concat();
            std::fs::write(rays.join(format!("{kind}.rays")), records).unwrap();
            let hits = if kind == "shadow" { 2 } else { 16 };
            std::fs::write(rays.join(format!("{kind}.hits")), vec![0u8; hits]).unwrap();
        }
        let p = probe(&["bench", "t.obj", "--rays", "rays"], dir.path());
        assert_eq!(p.code(), Some(1), "{}", p.stderr);
        let message = format!("primary.rays: ray 1: {why}");
        assert!(p.stderr.contains(&message), "{}", p.stderr);
        assert!(!p.stdout.contains("agree"), "{}", p.stdout);
    }
}
