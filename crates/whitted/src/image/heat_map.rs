//! Turns a one-channel film of non-negative values (the traversal cost per
//! pixel) into a colour picture with a legend, so a user sees at a glance
//! where an acceleration structure works hard.
//!
//! Values map linearly from 0 (black) through blue, magenta, orange and
//! yellow to white at the film's largest value. Below the picture a strip
//! shows the colour ramp with `0` at its left end and the largest value at
//! its right.

use crate::image::Film;

/// Colour stops of the ramp, evenly spaced from 0 to 1.
const RAMP: [[f32; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [0.10, 0.05, 0.55],
    [0.65, 0.10, 0.60],
    [0.95, 0.45, 0.10],
    [1.0, 0.85, 0.15],
    [1.0, 1.0, 1.0],
];

/// The ramp's colour at `x` in [0, 1] (linear RGB).
pub fn ramp(x: f32) -> [f32; 3] {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let scaled = x * (RAMP.len() - 1) as f32;
    let i = (scaled as usize).min(RAMP.len() - 2);
    let f = scaled - i as f32;
    let (a, b) = (RAMP[i], RAMP[i + 1]);
    // The stops are chosen in sRGB; interpolate there, return linear.
    std::array::from_fn(|c| srgb_to_linear(a[c] + (b[c] - a[c]) * f))
}

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Glyphs 3 pixels wide and 5 high, one row per `u8` (bit 2 = left).
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        'e' => [0, 7, 7, 4, 7],
        '+' => [0, 2, 7, 2, 0],
        _ => [0; 5],
    }
}

/// Draws `text` with its top-left corner at (`x`, `y`), each glyph pixel a
/// `scale` × `scale` square, clipped to the film.
fn draw_text(film: &mut Film, text: &str, x: u32, y: u32, scale: u32, color: [f32; 3]) {
    for (k, c) in text.chars().enumerate() {
        let rows = glyph(c);
        let x0 = x + k as u32 * 4 * scale;
        for (row, bits) in rows.iter().enumerate() {
            for col in 0..3u32 {
                if bits & (4 >> col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let (px, py) = (x0 + col * scale + dx, y + row as u32 * scale + dy);
                        if px < film.width() && py < film.height() {
                            film.set_pixel(px, py, &color);
                        }
                    }
                }
            }
        }
    }
}

/// Width in pixels of `text` drawn at `scale`.
fn text_width(text: &str, scale: u32) -> u32 {
    (text.chars().count() as u32 * 4).saturating_sub(1) * scale
}

/// A short label for the legend's maximum.
fn label(value: f32) -> String {
    if value >= 1e6 {
        format!("{value:.1e}").replace("e", "e+")
    } else if value >= 100.0 || value.fract() == 0.0 {
        format!("{value:.0}")
    } else {
        format!("{value:.1}")
    }
}

/// The colour picture of a one-channel `film`, with a legend strip below it.
pub fn heat_map(film: &Film) -> Film {
    let (width, height) = (film.width(), film.height());
    let max = film
        .data()
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f32, f32::max);
    let scale = (width / 160).clamp(1, 4);
    let strip = 14 * scale;
    let mut out = Film::new(width, height + strip, 3);
    for y in 0..height {
        for x in 0..width {
            let v = film.pixel(x, y)[0];
            let x01 = if max > 0.0 { v / max } else { 0.0 };
            out.set_pixel(x, y, &ramp(x01));
        }
    }
    let bar_top = height + scale;
    let bar_height = 4 * scale;
    for y in bar_top..bar_top + bar_height {
        for x in 0..width {
            let x01 = x as f32 / (width.max(2) - 1) as f32;
            out.set_pixel(x, y, &ramp(x01));
        }
    }
    let text_y = bar_top + bar_height + scale;
    let white = [1.0; 3];
    let right = label(max);
    if text_width("0", scale) + text_width(&right, scale) + 2 * scale < width {
        draw_text(&mut out, "0", scale, text_y, scale, white);
        let x = width - scale - text_width(&right, scale);
        draw_text(&mut out, &right, x, text_y, scale, white);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_runs_from_black_to_white_and_gets_brighter() {
        assert_eq!(ramp(0.0), [0.0; 3]);
        assert_eq!(ramp(1.0), [1.0; 3]);
        assert_eq!(ramp(f32::NAN), [0.0; 3]);
        let luminance = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        let mut last = -1.0;
        for i in 0..=100 {
            let l = luminance(ramp(i as f32 / 100.0));
            assert!(l >= last, "{i}");
            last = l;
        }
    }

    #[test]
    fn heat_map_adds_a_legend_and_maps_the_maximum_to_white() {
        let mut film = Film::new(200, 50, 1);
        film.set_pixel(10, 10, &[42.0]);
        let map = heat_map(&film);
        assert_eq!(map.width(), 200);
        assert!(map.height() > 50);
        assert_eq!(map.pixel(10, 10), &[1.0, 1.0, 1.0]);
        assert_eq!(map.pixel(0, 0), &[0.0, 0.0, 0.0]);
        // The legend's bar is the ramp from left to right.
        assert_eq!(map.pixel(0, 52), &[0.0, 0.0, 0.0]);
        assert_eq!(map.pixel(199, 52), &[1.0, 1.0, 1.0]);
        // Some white label pixels under the bar, at the right end.
        let labels = (56..map.height())
            .flat_map(|y| (150..200).map(move |x| (x, y)))
            .filter(|&(x, y)| map.pixel(x, y) == [1.0, 1.0, 1.0])
            .count();
        assert!(labels > 5);
    }

    #[test]
    fn labels_stay_short() {
        assert_eq!(label(42.0), "42");
        assert_eq!(label(3.25), "3.2");
        assert_eq!(label(1234.6), "1235");
        assert_eq!(label(2.5e7), "2.5e+7");
    }

    #[test]
    fn an_all_zero_film_is_black_not_nan() {
        let map = heat_map(&Film::new(4, 4, 1));
        assert!(map.data()[..48].iter().all(|&v| v == 0.0));
    }
}
