//! Whole files: entities together, the scene they make, and recovery from
//! errors.

use super::*;
use crate::shape::Shape;

/// A view block, to put in front of a test's own entities.
const VIEW: &str = "v\nfrom 0 -5 0\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.01\nresolution 32 24\n";

fn scene(source: &str) -> Scene {
    match parse_nff(source, Path::new("t.nff")) {
        Ok(scene) => scene,
        Err(error) => panic!("{error}"),
    }
}

/// `line:column: message` of every error in `source`.
fn errors(source: &str) -> Vec<String> {
    match parse_nff(source, Path::new("t.nff")) {
        Ok(_) => panic!("no error in:\n{source}"),
        Err(SceneError::Invalid { diagnostics }) => diagnostics
            .into_iter()
            .map(|d| format!("{}:{}: {}", d.line, d.column, d.message))
            .collect(),
        Err(error) => panic!("{error}"),
    }
}

#[test]
fn the_view_sets_camera_size_and_the_spd_tracing_rules() {
    let s = scene(VIEW);
    assert_eq!(s.camera.eye(), Vec3::new(0.0, -5.0, 0.0));
    assert_eq!(s.camera.up(), Vec3::Z);
    assert_eq!(s.camera.fov_degrees(), view::edge_to_edge_fov(45.0, 24));
    assert_eq!((s.settings.width, s.settings.height), (32, 24));
    assert_eq!((s.settings.max_depth, s.settings.min_weight), (4, 0.0));
    assert_eq!(s.background, Color::ZERO);
    assert_eq!(s.ambient, Color::splat(AMBIENT));
    assert!(s.objects.primitives.is_empty() && s.lights.is_empty());
}

#[test]
fn nff_colours_are_display_values() {
    assert_eq!(scene(VIEW).color_space, ColorSpace::Display);
}

#[test]
fn lights_without_a_colour_share_one_over_root_n() {
    let s = scene(&format!(
        "b 0.1 0.2 0.3\n{VIEW}l 1 2 3\nl 4 5 6 0.5 0.25 1\nl 0 0 9\nl 1 1 1\n"
    ));
    assert_eq!(s.background, Color::new(0.1, 0.2, 0.3));
    let intensities: Vec<Color> = s
        .lights
        .iter()
        .map(|light| match light {
            Light::Point { intensity, .. } => *intensity,
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(
        intensities,
        [
            Color::splat(0.5),
            Color::new(0.5, 0.25, 1.0),
            Color::splat(0.5),
            Color::splat(0.5)
        ]
    );
    let Light::Point { position, .. } = &s.lights[1] else {
        unreachable!()
    };
    assert_eq!(*position, Vec3::new(4.0, 5.0, 6.0));
}

#[test]
fn each_object_takes_the_material_of_the_last_fill_and_repeats_share_one() {
    let s = scene(&format!(
        "{VIEW}s 0 0 0 1\nf 1 0 0 1 0 0 0 0\ns 0 0 0 1\nf 0 1 0 1 0 0 0 0\n\
         c 0 0 0 1 0 0 1 1\nf 1 0 0 1 0 0 0 0\np 3 0 0 0 1 0 0 0 1 0\n"
    ));
    let materials: Vec<u32> = s.objects.primitives.iter().map(|p| p.material.0).collect();
    // The first sphere, before any `f`, gets the default grey.
    assert_eq!(materials, [0, 1, 2, 1]);
    assert_eq!(s.materials.len(), 3);
    assert_eq!(s.materials[0], Material::default());
    assert_eq!(s.materials[1].diffuse, Color::new(1.0, 0.0, 0.0).into());
}

#[test]
fn every_entity_is_read_and_patches_follow_the_other_shapes() {
    let s = scene(&format!(
        "{VIEW}f 1 1 1 1 0 0 0 0\npp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n\
         s 0 0 0 1 # a comment\nc\n0 0 0 1\n0 0 1 0.5\n\
         p 5 0 0 0 2 0 0 2 2 0 1 1 0 0 2 0\n"
    ));
    let kinds: Vec<&str> = s
        .objects
        .primitives
        .iter()
        .map(|p| p.shape.kind())
        .collect();
    assert_eq!(kinds, ["sphere", "cone", "polygon"]);
    assert_eq!(s.objects.meshes.len(), 1);
    assert_eq!(s.objects.meshes[0].len(), 1);
    assert_eq!(s.objects.primitive_count(), 4);
    let cone = &s.objects.primitives[1];
    let placement = cone.transform.map_or(Transform::IDENTITY, |id| {
        s.objects.transforms[id.0 as usize]
    });
    let apex = placement.point_to_world(Vec3::new(0.0, 0.0, 1.0));
    assert!(apex.abs_diff_eq(Vec3::Z, 1e-15));
    assert!(matches!(cone.shape, Shape::Cone(c) if !c.caps()));
}

#[test]
fn every_error_is_reported_and_reading_resumes_at_the_next_entity() {
    assert_eq!(
        errors(&format!(
            "{VIEW}s 0 0 0 abc\ns 0 0 0 1\nq 1 2\nf 1 1 1 1 0 0 0\nl 1 2 3\n\
             p 3 0 0 0 1 0 0 0 1 0 5\ns 1 1\n"
        )),
        [
            "8:9: expected a number for the sphere's radius, found `abc`",
            "10:1: unknown entity `q`; expected one of: v, b, l, f, c, s, p, pp (or a # comment)",
            "12:1: expected a number for the material's index of refraction, found `l`",
            "13:23: expected an entity keyword (v, b, l, f, c, s, p, pp), found the number `5`: \
             too many numbers for the entity before it?",
            "14:6: expected a number for the sphere's centre, found the end of the file",
        ]
    );
}

#[test]
fn the_view_is_required_once_and_checked() {
    assert_eq!(
        errors("s 0 0 0 1\n"),
        ["1:1: the file has no view `v`: an NFF scene needs one"]
    );
    assert_eq!(
        errors(""),
        ["1:1: the file has no view `v`: an NFF scene needs one"]
    );
    assert_eq!(
        errors(&format!("{VIEW}{VIEW}")),
        ["8:1: a second view `v`: a file has only one"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 0 0 0\nup 0 0 1\nangle 45\nhither 1\nresolution 8 8\n"),
        ["3:4: the view's `from` and `at` are the same point"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 2 0 0\nangle 45\nhither 1\nresolution 8 8\n"),
        ["4:4: the view's `up` is zero or parallel to the view direction"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 0 0 1\nangle 180\nhither 1\nresolution 8 8\n"),
        ["5:7: the view's `angle` must be between 0 and 180 degrees, got 180"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nangle 45\nhither 1\nresolution 8 8\n"),
        ["4:1: expected `up` in the view, found `angle`"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 1 0 0\nangle 45\nhither -1\nresolution 0 8\n"),
        ["6:8: the view's `hither` must not be negative, got -1"]
    );
    assert_eq!(
        errors("v\nfrom 0 0 0\nat 1 0 0\nup 1 0 0\nangle 45\nhither 1\nresolution 0 8\n"),
        ["7:12: the view's resolution (width) must be at least 1, got 0"]
    );
}

#[test]
fn a_degenerate_patch_is_refused_at_its_place() {
    assert_eq!(
        errors(&format!(
            "{VIEW}pp 3 0 0 0 0 0 1 1 1 1 0 0 1 2 2 2 0 0 1\ns 0 0 0 0\n"
        )),
        [
            "8:1: degenerate triangle: its vertices are collinear or coincide",
            "9:1: radius must be a positive number, got 0",
        ]
    );
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let error = load_nff(Path::new("/nonexistent/scene.nff")).unwrap_err();
    assert!(matches!(error, SceneError::Io { .. }));
    assert!(error.to_string().contains("/nonexistent/scene.nff"));
}

#[test]
fn truncated_and_mangled_files_give_errors_never_panics() {
    let source = include_str!("../../../tests/nff/spd_like.nff");
    for end in (0..=source.len()).filter(|&end| source.is_char_boundary(end)) {
        let _ = parse_nff(&source[..end], Path::new("t.nff"));
    }
    // Seeded replacements of single tokens by troublesome words.
    let words = [
        "-1",
        "0",
        "nan",
        "1e999",
        "x",
        "p",
        "pp",
        "#",
        "99999999999",
        "é",
    ];
    let tokens: Vec<&str> = source.split_ascii_whitespace().collect();
    let mut rng = crate::math::random::Rng::new(7);
    for _ in 0..2000 {
        let mut mangled = tokens.clone();
        let at = rng.below(mangled.len() as u32) as usize;
        mangled[at] = words[rng.below(words.len() as u32) as usize];
        let _ = parse_nff(&mangled.join(" "), Path::new("t.nff"));
    }
}
