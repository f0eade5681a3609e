//! What the page shows of a render: the colour image, or one AOV made
//! visible (depth as grey, normals as colours, ids as distinct colours,
//! the cost as the library's heat map), and the files it saves.

use whitted::image::{Film, heat_map};
use whitted::render::{Aov, RenderOutput};

/// The film of `output` the view shows: the colour image, or the AOV's
/// raw values (what an EXR or PFM save holds).
pub fn raw_film(output: &RenderOutput, aov: Option<Aov>) -> &Film {
    aov.and_then(|aov| output.aovs.iter().find(|(a, _)| *a == aov))
        .map_or(&output.image, |(_, film)| film)
}

/// The picture the page shows of `output` (what a PNG save holds).
pub fn display_film(output: &RenderOutput, aov: Option<Aov>) -> Film {
    let film = raw_film(output, aov);
    match aov {
        None => film.clone(),
        Some(Aov::Cost) => heat_map(film),
        Some(Aov::Depth) => depth_picture(film),
        Some(Aov::Normal) => map_pixels(film, |n| n.map(|v| 0.5 * v + 0.5)),
        Some(Aov::Id | Aov::Instance) => map_pixels(film, |id| id_color(id[0])),
    }
}

/// A film of three channels whose pixels are `f` of `film`'s.
fn map_pixels(film: &Film, f: impl Fn([f32; 3]) -> [f32; 3]) -> Film {
    let mut out = Film::new(film.width(), film.height(), 3);
    for y in 0..film.height() {
        for x in 0..film.width() {
            let p = film.pixel(x, y);
            let value = std::array::from_fn(|c| p.get(c).copied().unwrap_or(p[0]));
            out.set_pixel(x, y, &f(value));
        }
    }
    out
}

/// Depth as grey: the nearest hit white, the farthest dark, misses black.
fn depth_picture(film: &Film) -> Film {
    let finite = film.data().iter().copied().filter(|d| d.is_finite());
    let (near, far) = finite.fold((f32::INFINITY, 0.0f32), |(lo, hi), d| {
        (lo.min(d), hi.max(d))
    });
    let span = (far - near).max(f32::MIN_POSITIVE);
    map_pixels(film, |d| {
        let d = d[0];
        let grey = if d.is_finite() {
            1.0 - 0.85 * (d - near) / span
        } else {
            0.0
        };
        [grey; 3]
    })
}

/// A colour of its own for each id (-1, nothing, is black).
fn id_color(id: f32) -> [f32; 3] {
    if id < 0.0 {
        return [0.0; 3];
    }
    let mut h = (id as u64)
        .wrapping_add(1)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h ^= h >> 29;
    std::array::from_fn(|c| 0.15 + 0.85 * ((h >> (16 * c)) & 0xffff) as f32 / 65535.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_is_white_near_dark_far_and_black_for_misses() {
        let mut film = Film::new(3, 1, 1);
        film.set_pixel(0, 0, &[2.0]);
        film.set_pixel(1, 0, &[4.0]);
        film.set_pixel(2, 0, &[f32::INFINITY]);
        let picture = depth_picture(&film);
        assert_eq!(picture.pixel(0, 0), &[1.0; 3]);
        assert!((picture.pixel(1, 0)[0] - 0.15).abs() < 1e-6);
        assert_eq!(picture.pixel(2, 0), &[0.0; 3]);
    }

    #[test]
    fn ids_have_distinct_colours_and_nothing_is_black() {
        assert_eq!(id_color(-1.0), [0.0; 3]);
        assert_ne!(id_color(0.0), id_color(1.0));
        assert!(id_color(7.0).iter().all(|&c| (0.15..=1.0).contains(&c)));
    }
}
