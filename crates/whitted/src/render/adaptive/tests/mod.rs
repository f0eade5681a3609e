use super::*;
use crate::integrator::RayKind;
use crate::render::{PixelSelection, RenderOutput, Scene, Share, Window, render, render_selected};

/// A black ball (no lights) on a white background: one sharp edge.
const EDGE: &str = "[render]\nwidth = 24\nheight = 20\nbackground = [1, 1, 1]\n\
    [camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\nfov = 30\n\
    [[objects]]\nshape = \"sphere\"\ncenter = [0.3, 0.1, 0]\nradius = 0.8\n";

/// The ball lit from the side: shading that varies inside it too.
const LIT: &str = "[render]\nwidth = 24\nheight = 20\nbackground = [1, 1, 1]\n\
    [camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\nfov = 30\n\
    [[lights]]\ntype = \"point\"\nposition = [-3, 2, -3]\n\
    [[objects]]\nshape = \"sphere\"\ncenter = [0.3, 0.1, 0]\nradius = 0.8\n";

/// A grey background and nothing else.
const FLAT: &str = "[render]\nwidth = 40\nheight = 20\nbackground = [0.5, 0.5, 0.5]\n\
    [camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\n";

fn scene(text: &str, aa: AntiAliasing) -> Scene {
    let mut scene = crate::scene::parse_scene(text, std::path::Path::new("t.toml")).unwrap();
    scene.settings.aa = aa;
    scene
}

fn adaptive(threshold: f64, depth: u32) -> AntiAliasing {
    AntiAliasing::Adaptive(Adaptive {
        threshold,
        depth,
        min_depth: 0,
    })
}

fn camera_rays(output: &RenderOutput) -> u64 {
    output.rays[RayKind::Primary]
}

/// The largest difference between two films' values.
fn max_difference(a: &RenderOutput, b: &RenderOutput) -> f32 {
    a.image
        .data()
        .iter()
        .zip(b.image.data())
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f32::max)
}

#[test]
fn names_defaults_and_limits() {
    assert_eq!(AntiAliasing::default(), AntiAliasing::Stratified);
    assert_eq!(AntiAliasing::from_name("adaptive"), Some(adaptive(0.3, 3)));
    for name in AntiAliasing::NAMES {
        assert_eq!(AntiAliasing::from_name(name).unwrap().name(), name);
    }
    assert_eq!(AntiAliasing::from_name("jitter"), None);
    assert!(adaptive(0.0, MAX_AA_DEPTH).check().is_ok());
    assert_eq!(
        adaptive(0.1, MAX_AA_DEPTH + 1).check(),
        Err(AdaptiveError::Depth(MAX_AA_DEPTH + 1))
    );
    let min = |min_depth, depth| Adaptive {
        threshold: 0.1,
        depth,
        min_depth,
    };
    assert!(min(2, 2).check().is_ok());
    assert_eq!(
        min(3, 2).check(),
        Err(AdaptiveError::MinDepth {
            min_depth: 3,
            depth: 2
        })
    );
    assert_eq!(
        min(1, 4).to_string(),
        "adaptive anti-aliasing (threshold 0.1, depth 1 to 4)"
    );
    for bad in [-0.1, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            adaptive(bad, 1).check(),
            Err(AdaptiveError::Threshold(_))
        ));
    }
}

#[test]
fn a_flat_scene_costs_exactly_the_pixel_corners() {
    let output = render(&scene(FLAT, adaptive(0.0, 3)), &|_| {}).unwrap();
    // Tiles of 16: columns 16, 16, 8 and rows 16, 4; each tile traces its
    // own corners, (w + 1) x (h + 1).
    let corners: u64 = [16, 16, 8]
        .iter()
        .flat_map(|w| [16, 4].map(|h| (w + 1) * (h + 1)))
        .sum();
    assert_eq!(camera_rays(&output), corners);
    assert_eq!(output.rays.total(), corners);
    assert!(output.image.data().iter().all(|&v| v == 0.5));
}

#[test]
fn an_edge_is_subdivided_and_only_there() {
    let flat = render(&scene(EDGE, adaptive(0.3, 0)), &|_| {}).unwrap();
    let deep = render(&scene(EDGE, adaptive(0.3, 3)), &|_| {}).unwrap();
    let corners = camera_rays(&flat);
    assert!(camera_rays(&deep) > corners + 100, "{}", camera_rays(&deep));
    // Far from subdividing every pixel to 1/8 (81 corners each).
    assert!(camera_rays(&deep) < 20 * corners, "{}", camera_rays(&deep));
    // Pixels wholly inside or outside the ball are unchanged; the edge's
    // are partly covered.
    let image = &deep.image;
    assert_eq!(image.pixel(0, 0), [1.0; 3]);
    assert_eq!(image.pixel(13, 11), [0.0; 3]);
    let partial = image
        .data()
        .iter()
        .filter(|&&v| v > 0.01 && v < 0.99)
        .count();
    assert!(partial > 30, "{partial}");
}

#[test]
fn the_picture_does_not_depend_on_threads_tiles_or_crops() {
    let mut s = scene(LIT, adaptive(0.05, 3));
    s.settings.threads = Some(1);
    let one = render(&s, &|_| {}).unwrap();
    s.settings.threads = Some(3);
    let three = render(&s, &|_| {}).unwrap();
    assert_eq!(one.image, three.image);
    assert_eq!(one.rays, three.rays);
    let (width, height) = (s.settings.width, s.settings.height);
    let selections = [
        PixelSelection {
            window: Window::whole(width, height),
            share: Some(Share { index: 1, count: 3 }),
        },
        PixelSelection {
            window: Window {
                x0: 5,
                y0: 3,
                x1: 19,
                y1: 17,
            },
            share: Some(Share { index: 0, count: 2 }),
        },
        PixelSelection {
            window: Window {
                x0: 7,
                y0: 9,
                x1: 8,
                y1: 10,
            },
            share: None,
        },
    ];
    for selection in selections {
        let part = render_selected(&s, &selection, &|_| {}).unwrap();
        for y in 0..height {
            for x in 0..width {
                if selection.contains(x, y) {
                    assert_eq!(part.image.pixel(x, y), one.image.pixel(x, y), "{x},{y}");
                }
            }
        }
    }
}

#[test]
fn the_estimate_converges_to_the_stratified_reference_on_an_edge() {
    let reference = {
        let mut s = scene(EDGE, AntiAliasing::Stratified);
        s.settings.samples_per_pixel = 1024;
        render(&s, &|_| {}).unwrap()
    };
    let errors: Vec<f32> = (0..=5)
        .map(|depth| {
            let output = render(&scene(EDGE, adaptive(0.0, depth)), &|_| {}).unwrap();
            max_difference(&output, &reference)
        })
        .collect();
    for pair in errors.windows(2) {
        assert!(pair[1] < pair[0], "{errors:?}");
    }
    // 1/32-pixel squares and 32 x 32 strata both resolve the edge to a few
    // hundredths of a pixel's area.
    assert!(errors[5] < 0.04, "{errors:?}");
    assert!(errors[0] > 0.2, "{errors:?}");
}

#[test]
fn aovs_keep_the_pixel_centre_and_stratified_stays_as_it_was() {
    let mut s = scene(EDGE, adaptive(0.3, 2));
    s.settings.aovs = vec![crate::render::Aov::Id, crate::render::Aov::Depth];
    let with = render(&s, &|_| {}).unwrap();
    s.settings.aa = AntiAliasing::Stratified;
    let centre = render(&s, &|_| {}).unwrap();
    assert_eq!(with.aovs, centre.aovs);
    assert_eq!(camera_rays(&centre), 24 * 20);
}

#[test]
fn a_minimum_depth_subdivides_flat_pixels_and_finds_what_corners_miss() {
    let mut flat = scene(FLAT, adaptive(0.0, 3));
    flat.settings.aa = AntiAliasing::Adaptive(Adaptive {
        threshold: 0.0,
        depth: 3,
        min_depth: 2,
    });
    let output = render(&flat, &|_| {}).unwrap();
    // Each tile traces its corners on a grid 4 times finer.
    let corners: u64 = [16, 16, 8]
        .iter()
        .flat_map(|w| [16, 4].map(|h| (4 * w + 1) * (4 * h + 1)))
        .sum();
    assert_eq!(camera_rays(&output), corners);
    // A ball inside one pixel, between its corners: only the finer grid
    // sees it.
    let speck = "[render]\nwidth = 3\nheight = 3\nbackground = [1, 1, 1]\n\
        [camera]\neye = [0, 0, -5]\nlook_at = [0, 0, 0]\nfov = 30\n\
        [[objects]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.3\n";
    let corners_only = render(&scene(speck, adaptive(0.3, 3)), &|_| {}).unwrap();
    assert_eq!(corners_only.image.pixel(1, 1), [1.0; 3]);
    let mut finer = scene(speck, adaptive(0.3, 3));
    finer.settings.aa = AntiAliasing::Adaptive(Adaptive {
        threshold: 0.3,
        depth: 3,
        min_depth: 1,
    });
    let found = render(&finer, &|_| {}).unwrap();
    assert!(
        found.image.pixel(1, 1)[0] < 0.9,
        "{:?}",
        found.image.pixel(1, 1)
    );
}
