//! Golden images: every example scene in `scenes/` rendered small and
//! compared with `tests/golden/NAME.png`.
//!
//! Tolerance: 8-bit sRGB codes; at most 0.5% of the pixels may differ by more
//! than 2 codes in some channel, and the mean difference must stay under 0.5
//! codes. On failure the actual picture and an amplified difference are
//! written beside the golden as `NAME.actual.png` and `NAME.diff.png`.
//!
//! Goldens change only on purpose: `WHITTED_UPDATE_GOLDEN=1 cargo test
//! --test golden_images` rewrites them; look at them before committing.

use std::path::{Path, PathBuf};

use whitted::image::Film;
use whitted::image::encode_srgb8;
use whitted::render::render;
use whitted::scene::load_scene;

const SIZE: u32 = 64;

fn scenes_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn golden_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

fn to_srgb8(film: &Film) -> Vec<u8> {
    film.data().iter().map(|&v| encode_srgb8(v)).collect()
}

fn read_png(path: &Path) -> Option<(u32, u32, Vec<u8>)> {
    let file = std::fs::File::open(path).ok()?;
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .ok()?;
    let mut buf = vec![0; reader.output_buffer_size()?];
    let info = reader.next_frame(&mut buf).ok()?;
    buf.truncate(info.buffer_size());
    Some((info.width, info.height, buf))
}

/// Compares two 8-bit images; `Err` says how they differ.
fn compare(actual: &[u8], golden: &[u8]) -> Result<(), String> {
    if actual.len() != golden.len() {
        return Err(format!(
            "sizes differ: {} vs {} bytes",
            actual.len(),
            golden.len()
        ));
    }
    let pixels = actual.len() / 3;
    let mut far = 0;
    let mut total = 0u64;
    for (a, g) in actual.chunks(3).zip(golden.chunks(3)) {
        let d = a
            .iter()
            .zip(g)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        total += u64::from(d);
        if d > 2 {
            far += 1;
        }
    }
    let mean = total as f64 / pixels as f64;
    if far * 200 > pixels || mean > 0.5 {
        Err(format!(
            "{far} of {pixels} pixels differ by more than 2 codes; mean difference {mean:.3}"
        ))
    } else {
        Ok(())
    }
}

fn write_diff(actual: &[u8], golden: &[u8], path: &Path) {
    let mut diff = Film::new(SIZE, SIZE, 3);
    for (i, (a, g)) in actual.chunks(3).zip(golden.chunks(3)).enumerate() {
        let d: Vec<f32> = a
            .iter()
            .zip(g)
            .map(|(x, y)| (f32::from(x.abs_diff(*y)) * 8.0 / 255.0).min(1.0))
            .collect();
        diff.set_pixel(i as u32 % SIZE, i as u32 / SIZE, &d);
    }
    diff.write(path).unwrap();
}

#[test]
fn example_scenes_match_their_golden_images() {
    let update = std::env::var_os("WHITTED_UPDATE_GOLDEN").is_some();
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(scenes_folder())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(!scenes.is_empty());
    let mut failures = Vec::new();
    for scene_path in &scenes {
        let name = scene_path
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let mut scene = load_scene(scene_path).unwrap();
        scene.settings.width = SIZE;
        scene.settings.height = SIZE;
        let film = render(&scene, &|_| {}).unwrap().image;
        let actual = to_srgb8(&film);
        let golden_path = golden_folder().join(format!("{name}.png"));
        if update {
            film.write(&golden_path).unwrap();
            continue;
        }
        let result = match read_png(&golden_path) {
            None => Err(format!("no golden image at {}", golden_path.display())),
            Some((w, h, _)) if (w, h) != (SIZE, SIZE) => {
                Err(format!("golden image is {w}x{h}, expected {SIZE}x{SIZE}"))
            }
            Some((_, _, golden)) => compare(&actual, &golden).inspect_err(|_| {
                write_diff(
                    &actual,
                    &golden,
                    &golden_folder().join(format!("{name}.diff.png")),
                );
            }),
        };
        if let Err(why) = result {
            film.write(&golden_folder().join(format!("{name}.actual.png")))
                .unwrap();
            failures.push(format!("{name}: {why}"));
        }
    }
    assert!(
        failures.is_empty(),
        "golden images differ (see tests/golden/*.actual.png and *.diff.png; \
         WHITTED_UPDATE_GOLDEN=1 rewrites them on purpose):\n{}",
        failures.join("\n")
    );
}

#[test]
fn comparison_accepts_noise_and_rejects_real_changes() {
    let golden = vec![100u8; 64 * 64 * 3];
    let mut noisy = golden.clone();
    noisy[0] = 102;
    noisy[300] = 110;
    assert!(compare(&noisy, &golden).is_ok());
    let changed: Vec<u8> = golden.iter().map(|v| v + 10).collect();
    assert!(compare(&changed, &golden).is_err());
}
