//! Texture filtering in whole renders: the grazing checkerboard of
//! `scenes/grazing-checker.toml` at one sample per pixel comes much closer
//! to its supersampled reference with `texture_filter = "mipmap"` than
//! without, and the filtered picture is the same with every acceleration
//! structure and for any thread count.

use std::path::Path;

use whitted::accel::AccelKind;
use whitted::image::Film;
use whitted::render::{Scene, render};
use whitted::scene::load_scene;
use whitted::shading::TextureFilter;

fn grazing_checker(width: u32, height: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/grazing-checker.toml");
    let mut scene = load_scene(&path).unwrap();
    scene.settings.width = width;
    scene.settings.height = height;
    scene
}

fn picture(scene: &Scene, spp: u32, filter: TextureFilter) -> Film {
    let mut scene = scene.clone();
    scene.settings.samples_per_pixel = spp;
    scene.settings.texture_filter = filter;
    render(&scene, &|_| {}).unwrap().image
}

/// Mean absolute difference per channel, in linear units.
fn mean_error(a: &Film, b: &Film) -> f64 {
    let mut sum = 0.0;
    for y in 0..a.height() {
        for x in 0..a.width() {
            let (p, q) = (a.pixel(x, y), b.pixel(x, y));
            sum += (0..3).map(|c| f64::from((p[c] - q[c]).abs())).sum::<f64>();
        }
    }
    sum / f64::from(3 * a.width() * a.height())
}

#[test]
fn the_filtered_grazing_checker_is_much_closer_to_the_reference() {
    let scene = grazing_checker(120, 90);
    let reference = picture(&scene, 64, TextureFilter::None);
    let plain = mean_error(&picture(&scene, 1, TextureFilter::None), &reference);
    let filtered = mean_error(&picture(&scene, 1, TextureFilter::Mipmap), &reference);
    assert!(
        filtered < plain / 3.0,
        "filtered {filtered}, unfiltered {plain}"
    );
}

#[test]
fn the_filtered_picture_is_the_same_with_every_structure_and_thread_count() {
    let scene = grazing_checker(48, 36);
    let first = picture(&scene, 1, TextureFilter::Mipmap);
    for accel in [AccelKind::KdTree, AccelKind::Grid, AccelKind::Linear] {
        let mut other = scene.clone();
        other.settings.accel = accel;
        other.settings.threads = Some(3);
        assert!(
            picture(&other, 1, TextureFilter::Mipmap) == first,
            "{accel:?}"
        );
    }
}
