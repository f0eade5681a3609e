//! `whitted explain`'s promise: the colour at the root of a pixel's ray
//! tree is the rendered pixel, exactly. Checked on every example scene in
//! `scenes/`, for seeded random pixels, with one sample per pixel (the
//! root is the pixel), with several (each sample's root is that
//! sample's colour, and their mean is the pixel) and with adaptive
//! anti-aliasing (each corner's root is its colour, and their area
//! average is the pixel).

use std::path::{Path, PathBuf};

use whitted::accel::AccelKind;
use whitted::integrator::{RayNode, Stop};
use whitted::math::random::hash64;
use whitted::render::{Adaptive, AntiAliasing, Explainer, Scene, explain_pixel, render};
use whitted::scene::load_any;
use whitted::shading::{Color, TextureFilter};

/// The example scenes of every format, sorted by name.
fn example_scenes() -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| {
            path.extension()
                .is_some_and(|e| ["toml", "nff", "obj", "bpt"].iter().any(|x| e == *x))
        })
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 10, "too few scenes in {}", folder.display());
    scenes
}

/// `path` at `width`x`height` with `spp` samples.
fn small(path: &Path, (width, height): (u32, u32), spp: u32) -> Scene {
    let mut scene = load_any(path).unwrap_or_else(|e| panic!("{e}"));
    scene.settings.width = width;
    scene.settings.height = height;
    scene.settings.samples_per_pixel = spp;
    scene.settings.threads = Some(1);
    scene
}

/// `count` seeded pixels of a `width`x`height` image, for the scene `name`.
fn pixels(name: &str, (width, height): (u32, u32), count: u64) -> Vec<(u32, u32)> {
    let seed = name.bytes().fold(0u64, |h, b| hash64(h ^ u64::from(b)));
    (0..count)
        .map(|i| {
            let h = hash64(seed ^ i);
            (
                (h % u64::from(width)) as u32,
                ((h >> 32) % u64::from(height)) as u32,
            )
        })
        .collect()
}

/// How many rays the tree holds, and its deepest depth.
fn size(node: &RayNode) -> (usize, u32) {
    let children = node.hit.iter().flat_map(|hit| &hit.children);
    children.fold((1, node.depth), |(count, depth), child| {
        let (c, d) = size(child);
        (count + c, depth.max(d))
    })
}

#[test]
fn the_root_of_every_explained_pixel_is_the_rendered_pixel_with_one_sample() {
    let resolution = (24, 18);
    let mut deepest = 0;
    for path in example_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let scene = small(&path, resolution, 1);
        let film = render(&scene, &|_| {}).unwrap().image;
        for (x, y) in pixels(&name, resolution, 12) {
            let explained = explain_pixel(&scene, (x, y), 0).unwrap();
            let root = explained.tree.color.to_f32();
            assert_eq!(root, film.pixel(x, y), "{name} pixel {x},{y}");
            assert_eq!(explained.pixel, root, "{name} pixel {x},{y}");
            deepest = deepest.max(size(&explained.tree).1);
        }
    }
    // The scenes have mirrors and glass: some tree goes deeper than the
    // camera ray, so the comparison covers secondary rays.
    assert!(deepest >= 2, "no explained tree went past depth {deepest}");
}

#[test]
fn each_sample_s_root_is_its_colour_and_their_mean_the_rendered_pixel() {
    let resolution = (12, 9);
    for path in example_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let scene = small(&path, resolution, 3);
        let film = render(&scene, &|_| {}).unwrap().image;
        for (x, y) in pixels(&name, resolution, 3) {
            let first = explain_pixel(&scene, (x, y), 0).unwrap();
            assert_eq!(first.pixel, film.pixel(x, y), "{name} pixel {x},{y}");
            for k in 0..3 {
                let explained = explain_pixel(&scene, (x, y), k).unwrap();
                assert_eq!(
                    explained.tree.color, first.sample_colors[k as usize],
                    "{name} pixel {x},{y} sample {k}"
                );
                assert_eq!(explained.pixel, first.pixel);
            }
        }
    }
}

#[test]
fn adaptive_corners_roots_are_their_colours_and_their_area_average_the_rendered_pixel() {
    let resolution = (12, 9);
    let aa = AntiAliasing::Adaptive(Adaptive {
        threshold: 0.1,
        depth: 2,
        min_depth: 0,
    });
    let (mut explained_pixels, mut corners) = (0, 0);
    for path in example_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let mut scene = small(&path, resolution, 1);
        scene.settings.aa = aa;
        let film = render(&scene, &|_| {}).unwrap().image;
        for (x, y) in pixels(&name, resolution, 3) {
            let first = explain_pixel(&scene, (x, y), 0).unwrap();
            assert_eq!(first.pixel, film.pixel(x, y), "{name} pixel {x},{y}");
            assert_eq!(first.aa, aa);
            let count = first.samples;
            assert!((4..=25).contains(&count), "{name} pixel {x},{y}: {count}");
            assert_eq!(first.sample_colors.len(), count as usize);
            explained_pixels += 1;
            corners += count;
            let mut positions = Vec::new();
            for k in [0, count / 2, count - 1] {
                let explained = explain_pixel(&scene, (x, y), k).unwrap();
                assert_eq!(
                    explained.tree.color, first.sample_colors[k as usize],
                    "{name} pixel {x},{y} corner {k}"
                );
                assert_eq!(explained.pixel, first.pixel);
                let p = explained.position;
                let on_the_pixel = (f64::from(x)..=f64::from(x + 1)).contains(&p.x)
                    && (f64::from(y)..=f64::from(y + 1)).contains(&p.y);
                assert!(on_the_pixel, "{name} pixel {x},{y} corner {k} at {p:?}");
                positions.push((p.y, p.x));
            }
            // Row by row: the first corner is the top left, the last the
            // bottom right.
            assert_eq!(positions[0], (f64::from(y), f64::from(x)));
            assert_eq!(positions[2], (f64::from(y + 1), f64::from(x + 1)));
            let error = explain_pixel(&scene, (x, y), count).unwrap_err();
            assert_eq!(
                error.to_string(),
                format!(
                    "sample {count} does not exist: the pixel has {count} (0 to {})",
                    count - 1
                )
            );
        }
    }
    // Some pixel was subdivided, so the corners inside a pixel are covered.
    assert!(corners > 4 * explained_pixels, "{corners} corners");
}

#[test]
fn with_filtered_textures_the_explained_pixel_is_the_rendered_pixel() {
    // The samples' and the corners' ray differentials must be the
    // renderer's, or a filtered texture gives another colour.
    let resolution = (12, 9);
    let adaptive = AntiAliasing::Adaptive(Adaptive {
        threshold: 0.1,
        depth: 2,
        min_depth: 1,
    });
    for path in example_scenes() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        for (aa, spp) in [(AntiAliasing::Stratified, 2), (adaptive, 1)] {
            let mut scene = small(&path, resolution, spp);
            scene.settings.texture_filter = TextureFilter::Mipmap;
            scene.settings.aa = aa;
            let film = render(&scene, &|_| {}).unwrap().image;
            for (x, y) in pixels(&name, resolution, 2) {
                let first = explain_pixel(&scene, (x, y), 0).unwrap();
                assert_eq!(first.pixel, film.pixel(x, y), "{name} {aa:?} pixel {x},{y}");
                let last = first.samples - 1;
                let explained = explain_pixel(&scene, (x, y), last).unwrap();
                assert_eq!(
                    explained.tree.color, first.sample_colors[last as usize],
                    "{name} {aa:?} pixel {x},{y} sample {last}"
                );
            }
        }
    }
}

#[test]
fn every_structure_explains_the_same_tree_at_its_own_cost() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/whitted.toml");
    let mut trees = Vec::new();
    for accel in AccelKind::ALL {
        let mut scene = small(&path, (32, 24), 1);
        scene.settings.accel = accel;
        let mut explained = explain_pixel(&scene, (16, 14), 0).unwrap();
        assert!(explained.tree.cost.nodes + explained.tree.cost.primitives > 0);
        clear_costs(&mut explained.tree);
        trees.push(explained.tree);
    }
    assert!(trees.windows(2).all(|w| w[0] == w[1]));
}

fn clear_costs(node: &mut RayNode) {
    node.cost = Default::default();
    if let Some(hit) = &mut node.hit {
        for light in &mut hit.lights {
            for segment in &mut light.shadow_rays {
                segment.cost = Default::default();
            }
        }
        hit.children.iter_mut().for_each(clear_costs);
    }
}

#[test]
fn a_pixel_or_sample_outside_the_image_is_refused_with_the_range() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/whitted.toml");
    let scene = small(&path, (32, 24), 2);
    let error = explain_pixel(&scene, (32, 0), 0).unwrap_err();
    assert_eq!(
        error.to_string(),
        "the pixel 32,0 is outside the 32x24 image (columns 0 to 31, rows 0 to 23)"
    );
    let error = explain_pixel(&scene, (0, 0), 2).unwrap_err();
    assert_eq!(
        error.to_string(),
        "sample 2 does not exist: the pixel has 2 (0 to 1)"
    );
}

/// Checks that every hit's listed terms add up to the colour it passes
/// up: `α (ke + ka Ia + Σ lights (diffuse + specular) + caustic)` plus each
/// child's `coefficient × colour`. Returns how many hits had a caustic term.
fn terms_sum_to_the_colour(node: &RayNode) -> usize {
    let Some(hit) = &node.hit else {
        return 0;
    };
    let t = &hit.terms;
    let lights = hit
        .lights
        .iter()
        .fold(Color::ZERO, |sum, l| sum + l.diffuse + l.specular);
    let local = t.emission + t.ambient + lights + t.caustic;
    let children = hit
        .children
        .iter()
        .fold(Color::ZERO, |sum, c| sum + c.coefficient * c.color);
    let sum = t.opacity * local + children;
    for (listed, colour) in [
        (sum.r, node.color.r),
        (sum.g, node.color.g),
        (sum.b, node.color.b),
    ] {
        assert!(
            (listed - colour).abs() <= 1e-9 * (1.0 + colour.abs()),
            "the terms add up to {sum:?}, the node passes up {:?} (depth {})",
            node.color,
            node.depth
        );
    }
    let own = usize::from(t.caustic != Color::ZERO);
    own + hit
        .children
        .iter()
        .map(terms_sum_to_the_colour)
        .sum::<usize>()
}

#[test]
fn the_caustic_term_is_listed_and_the_terms_add_up_to_each_rays_colour() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/caustics.toml");
    let resolution = (64, 40);
    let scene = small(&path, resolution, 1);
    let explainer = Explainer::new(&scene).unwrap();
    let mut caustic = 0;
    for y in (0..40).step_by(3) {
        for x in (0..64).step_by(3) {
            let explained = explainer.explain(&scene.camera, (x, y), 0).unwrap();
            caustic += terms_sum_to_the_colour(&explained.tree);
        }
    }
    assert!(caustic > 0, "some pixels see the caustic");
}

/// Rays and light verdicts a tree holds, and the sum of what its hits say
/// they left out.
fn records_and_left_out(node: &RayNode) -> (u64, u64) {
    let Some(hit) = &node.hit else {
        return (1, 0);
    };
    let lights: u64 = hit
        .lights
        .iter()
        .map(|l| 1 + l.shadow_rays.len() as u64)
        .sum();
    let left: u64 = hit
        .stops
        .iter()
        .map(|stop| match stop {
            Stop::TreeLimit { left_out, .. } => *left_out,
            _ => 0,
        })
        .sum();
    hit.children
        .iter()
        .map(records_and_left_out)
        .fold((1 + lights, left), |(a, b), (c, d)| (a + c, b + d))
}

/// Issue 50, item 2: a tree records at most its limit of rays and light
/// verdicts, the first ones traced; what it leaves out is counted at the
/// hits it came from, the two add up to the whole tree, and the colours
/// are the same bits.
#[test]
fn a_tree_holds_at_most_its_limit_and_counts_what_it_leaves_out() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hostile_scenes/glass_in_mirrors.toml");
    let mut scene = load_any(&path).unwrap();
    scene.settings.max_depth = 9;
    let whole = Explainer::new(&scene)
        .unwrap()
        .with_max_tree_rays(u64::MAX)
        .explain(&scene.camera, (4, 4), 0)
        .unwrap();
    assert_eq!(whole.left_out, 0);
    let (all, none) = records_and_left_out(&whole.tree);
    assert_eq!(none, 0);
    assert!(all > 500, "{all}");
    for limit in [1, 2, 7, 50, 499, all - 1, all] {
        let cut = Explainer::new(&scene)
            .unwrap()
            .with_max_tree_rays(limit)
            .explain(&scene.camera, (4, 4), 0)
            .unwrap();
        let (held, left_out) = records_and_left_out(&cut.tree);
        assert_eq!(held, limit, "{limit}");
        assert_eq!(left_out, cut.left_out, "{limit}");
        assert_eq!(held + left_out, all, "{limit}");
        assert_eq!(cut.max_tree_rays, limit);
        assert_eq!(cut.tree.color, whole.tree.color, "{limit}");
        assert_eq!(cut.pixel, whole.pixel);
        assert_eq!(cut.tree.hit.is_some(), whole.tree.hit.is_some());
    }
    // The limit's least is the camera ray.
    let cut = Explainer::new(&scene)
        .unwrap()
        .with_max_tree_rays(0)
        .explain(&scene.camera, (4, 4), 0)
        .unwrap();
    assert_eq!(records_and_left_out(&cut.tree), (1, all - 1));
}
