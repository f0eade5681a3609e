//! `whitted explain` from the command line: the tree's root is the pixel
//! `whitted render` writes, the text names what a reader needs, the JSON
//! follows docs/explain.md, the SVG is drawn, and bad pixels are refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

#[path = "common/pfm.rs"]
mod pfm;
use pfm::read_pfm;

fn whitted(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn scene(name: &str) -> String {
    let path: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", "..", "scenes", name]
        .iter()
        .collect();
    path.to_string_lossy().into_owned()
}

fn json(output: &Output) -> serde_json::Value {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

fn rgb(value: &serde_json::Value) -> [f64; 3] {
    let v: Vec<f64> = value
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect();
    [v[0], v[1], v[2]]
}

#[test]
fn the_json_root_is_the_pixel_render_writes_for_one_and_several_samples_and_adaptive() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    let whitted_toml = scene("whitted.toml");
    let samplings: [&[&str]; 3] = [
        &["--spp", "1"],
        &["--spp", "3"],
        &[
            "--aa",
            "adaptive",
            "--aa-threshold",
            "0.1",
            "--aa-depth",
            "2",
        ],
    ];
    for (i, sampling) in samplings.into_iter().enumerate() {
        let mut size = vec!["--width", "40", "--height", "30"];
        size.extend(sampling);
        let out = dir.join(format!("sampling{i}.pfm"));
        let mut args = vec![
            "render",
            whitted_toml.as_str(),
            "-q",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(&size);
        assert!(whitted(&args, dir).status.success());
        let (width, pixels) = read_pfm(&std::fs::read(&out).unwrap());
        for (x, y) in [(20, 14), (5, 25), (33, 8), (24, 17)] {
            let pixel = format!("{x},{y}");
            let mut args = vec![
                "explain",
                whitted_toml.as_str(),
                "--pixel",
                &pixel,
                "--json",
                "-q",
            ];
            args.extend(&size);
            let explained = json(&whitted(&args, dir));
            let value: Vec<f32> = rgb(&explained["pixel"]["value"]).map(|c| c as f32).to_vec();
            assert_eq!(
                value,
                pixels[y * width + x].to_vec(),
                "pixel {pixel}, {sampling:?}"
            );
            let root = rgb(&explained["tree"]["color"]);
            let samples: Vec<[f64; 3]> = explained["sample_colors"]
                .as_array()
                .unwrap()
                .iter()
                .map(rgb)
                .collect();
            assert_eq!(root, samples[0]);
            if i == 0 {
                assert_eq!(root.map(|c| c as f32).to_vec(), value);
            }
            let method = &explained["anti_aliasing"]["method"];
            assert_eq!(method, if i == 2 { "adaptive" } else { "stratified" });
        }
    }
}

#[test]
fn the_text_of_an_adaptive_pixel_says_it_is_the_area_average_of_its_corners() {
    let folder = tempfile::tempdir().unwrap();
    let args = [
        "explain",
        &scene("whitted.toml"),
        "--pixel",
        "20,14",
        "--width",
        "40",
        "--height",
        "30",
        "--aa",
        "adaptive",
        "--aa-min-depth",
        "1",
        "--sample",
        "8",
        "-q",
    ];
    let output = whitted(&args, folder.path());
    assert!(output.status.success(), "{output:?}");
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(text.contains("sample 8 of "), "{text}");
    assert!(
        text.contains(
            "adaptive anti-aliasing (threshold 0.3, depth 1 to 3): the area average of its squares"
        ),
        "{text}"
    );
    assert!(text.contains("on a grid 1/8 of a pixel wide"), "{text}");
    // The corner lies on the pixel, on the grid of eighths.
    let header = text.lines().next().unwrap();
    let at = header.rsplit_once(" at (").unwrap().1.trim_end_matches(')');
    let (px, py) = at.split_once(", ").unwrap();
    let (px, py): (f64, f64) = (px.parse().unwrap(), py.parse().unwrap());
    assert!(
        (20.0..=21.0).contains(&px) && (14.0..=15.0).contains(&py),
        "{header}"
    );
    assert_eq!(
        ((px * 8.0).fract(), (py * 8.0).fract()),
        (0.0, 0.0),
        "{header}"
    );
}

#[test]
fn the_json_follows_the_documented_schema() {
    let folder = tempfile::tempdir().unwrap();
    let args = [
        "explain",
        &scene("whitted.toml"),
        "--pixel",
        "20,14",
        "--width",
        "40",
        "--height",
        "30",
        "--json",
        "-q",
    ];
    let e = json(&whitted(&args, folder.path()));
    assert_eq!(e["schema"], "whitted-explain/1");
    assert_eq!(e["image"]["width"], 40);
    assert_eq!(e["accel"], "bvh");
    let root = &e["tree"];
    assert_eq!(root["kind"], "camera");
    assert_eq!(root["depth"], 0);
    let hit = &root["hit"];
    assert_eq!(hit["object"]["label"], "objects[2]");
    assert_eq!(hit["object"]["kind"], "sphere");
    assert!(
        hit["object"]["file"]
            .as_str()
            .unwrap()
            .ends_with("whitted.toml")
    );
    assert!(hit["object"]["line"].as_u64().unwrap() > 1);
    assert_eq!(hit["material"]["name"], "`glass`");
    assert_eq!(hit["entering"], true);
    assert_eq!(hit["indices_of_refraction"], serde_json::json!([1.0, 1.5]));
    let lights = hit["lights"].as_array().unwrap();
    assert_eq!(lights.len(), 2);
    assert!(
        lights
            .iter()
            .all(|l| l["shadow_rays"][0]["cost"]["nodes"].is_u64())
    );
    let kinds: Vec<&str> = hit["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["reflected", "refracted"]);
}

#[test]
fn the_text_names_rays_objects_terms_and_why_the_tree_stops() {
    let folder = tempfile::tempdir().unwrap();
    let file = scene("whitted.toml");
    let args = [
        "explain", &file, "--pixel", "20,14", "--width", "40", "--height", "30", "-q",
    ];
    let output = whitted(&args, folder.path());
    assert!(output.status.success());
    let text = String::from_utf8(output.stdout).unwrap();
    for expected in [
        "pixel 20,14 of ",
        "camera ray, depth 0",
        "hits objects[2] sphere, primitive 2, ",
        "whitted.toml:",
        "material `glass`",
        "arriving from outside (entering)",
        "ambient ka Ia",
        "light 0: ",
        "shadow ray from ",
        "kr × reflected",
        "kt × transmitted",
        "refracted ray, depth 1",
        "arriving from inside (leaving)",
        "stop: no ",
        "passes up (",
    ] {
        assert!(text.contains(expected), "no `{expected}` in:\n{text}");
    }
    assert!(output.stderr.is_empty());
}

#[test]
fn svg_draws_the_tree_over_the_embedded_picture() {
    let folder = tempfile::tempdir().unwrap();
    let file = scene("whitted.toml");
    let args = [
        "explain", &file, "--pixel", "20,14", "--width", "40", "--height", "30", "--svg",
        "tree.svg", "-q",
    ];
    assert!(whitted(&args, folder.path()).status.success());
    let svg = std::fs::read_to_string(folder.path().join("tree.svg")).unwrap();
    assert!(
        svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"40\" height=\"30\"")
    );
    assert!(
        svg.contains("href=\"data:image/png;base64,iVBORw0KGgo"),
        "no PNG embedded"
    );
    assert!(svg.contains("<title>refracted ray, depth 1</title>"));
    assert!(svg.contains("<circle "));
    assert!(svg.trim_end().ends_with("</svg>"));
    let partials: Vec<_> = std::fs::read_dir(folder.path())
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .ends_with(".partial")
        })
        .collect();
    assert!(partials.is_empty());
}

#[test]
fn a_pixel_outside_the_image_or_badly_written_is_refused() {
    let folder = tempfile::tempdir().unwrap();
    let file = scene("whitted.toml");
    let outside = whitted(
        &[
            "explain", &file, "--pixel", "40,0", "--width", "40", "--height", "30",
        ],
        folder.path(),
    );
    assert_eq!(outside.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&outside.stderr);
    assert!(
        stderr.contains(
            "error: the pixel 40,0 is outside the 40x30 image (columns 0 to 39, rows 0 to 29)"
        ),
        "{stderr}"
    );
    let bad = whitted(&["explain", &file, "--pixel", "3"], folder.path());
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("`3` is not two numbers"));
    let sample = whitted(
        &["explain", &file, "--pixel", "1,1", "--sample", "1"],
        folder.path(),
    );
    assert!(
        String::from_utf8_lossy(&sample.stderr)
            .contains("sample 1 does not exist: the pixel has 1")
    );
}
