//! Caustic renders of `scenes/caustics.toml`, the glass ball on a table:
//! they converge as photons are added (issue 19, test 3), do not depend on
//! the thread count, and with photons off are the picture of before.

use std::path::Path;

use whitted::render::{Scene, render};

fn glass_ball_on_a_table(photons: u64) -> Scene {
    let source = include_str!("../../../scenes/caustics.toml");
    let mut scene = whitted::scene::parse_scene(source, Path::new("caustics.toml")).unwrap();
    scene.settings.width = 48;
    scene.settings.height = 30;
    scene.settings.samples_per_pixel = 1;
    scene.settings.photons.count = photons;
    scene
}

fn image(scene: &Scene) -> Vec<f32> {
    render(scene, &|_| {}).unwrap().image.data().to_vec()
}

/// Mean absolute difference per channel.
fn difference(a: &[f32], b: &[f32]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| f64::from((x - y).abs())).sum();
    sum / a.len() as f64
}

#[test]
fn a_caustic_render_converges_as_photons_are_added() {
    let counts = [1_000, 4_000, 16_000];
    let reference = image(&glass_ball_on_a_table(10 * counts[2]));
    let errors: Vec<f64> = counts
        .iter()
        .map(|&n| difference(&image(&glass_ball_on_a_table(n)), &reference))
        .collect();
    // Each fourfold step at least a quarter closer to the reference.
    assert!(errors[1] < 0.75 * errors[0], "{errors:?}");
    assert!(errors[2] < 0.75 * errors[1], "{errors:?}");
    // And the caustic is there at all: the photons change the picture.
    let without = image(&glass_ball_on_a_table(0));
    assert!(
        difference(&without, &reference) > 4.0 * errors[2],
        "{errors:?}"
    );
}

#[test]
fn a_caustic_render_is_the_same_for_any_thread_count() {
    let mut scene = glass_ball_on_a_table(8_000);
    scene.settings.threads = Some(1);
    let one = image(&scene);
    scene.settings.threads = Some(3);
    assert_eq!(one, image(&scene));
}

#[test]
fn photons_off_leave_the_picture_as_it_was() {
    // The scene with its photon keys taken out entirely, against the same
    // scene with them present and switched off.
    let source = include_str!("../../../scenes/caustics.toml");
    let (render_table, rest) = source.split_at(source.find("[camera]").unwrap());
    let mut plain: String = render_table
        .lines()
        .filter(|l| {
            !["photons", "gather", "radius"]
                .iter()
                .any(|k| l.starts_with(k))
        })
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(plain.lines().count() + 3, render_table.lines().count());
    plain.push_str(rest);
    let mut before = whitted::scene::parse_scene(&plain, Path::new("plain.toml")).unwrap();
    before.settings.width = 48;
    before.settings.height = 30;
    before.settings.samples_per_pixel = 1;
    assert_eq!(image(&before), image(&glass_ball_on_a_table(0)));
}
