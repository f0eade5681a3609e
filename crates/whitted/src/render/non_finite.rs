//! The render's last guard, pixels whose colour came out infinite or NaN,
//! counted tile by tile by the worker that traced the tile (its colours
//! still in cache, outside the lock that gathers the tiles) rather than by
//! one scan of the whole film after the trace, on one thread while the
//! others waited (measured: docs/performance-log.md, "The films' fixed
//! cost").

use super::RenderError;

/// The pixels of some tiles whose colour is not finite: how many, and the
/// first of them in the image's row order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct NonFinite {
    count: u64,
    /// Row and column of the first.
    first: Option<(u32, u32)>,
}

impl NonFinite {
    /// Those of a tile `width` pixels wide whose top-left pixel is
    /// (`x0`, `y0`), with colours `color` (three values a pixel, row after
    /// row).
    pub(super) fn of_tile(x0: u32, y0: u32, width: u32, color: &[f32]) -> Self {
        // Folded without stopping early, so that it runs over whole
        // registers; most tiles have no such pixel.
        if color.iter().fold(true, |all, v| all & v.is_finite()) {
            return Self::default();
        }
        let mut bad = color
            .chunks_exact(3)
            .enumerate()
            .filter(|(_, pixel)| pixel.iter().any(|v| !v.is_finite()))
            .map(|(i, _)| i as u32);
        let first = bad.next().map(|i| (y0 + i / width, x0 + i % width));
        Self {
            count: first.map_or(0, |_| 1 + bad.count() as u64),
            first,
        }
    }

    /// Adds those of other tiles: the same whatever the order the tiles
    /// come in.
    pub(super) fn add(&mut self, other: Self) {
        self.count += other.count;
        self.first = match (self.first, other.first) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
    }

    /// An error naming the first pixel and how many there are, if any.
    pub(super) fn check(self) -> Result<(), RenderError> {
        match self.first {
            None => Ok(()),
            Some((y, x)) => Err(RenderError::NotFinite {
                count: self.count,
                x,
                y,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Film;
    use crate::math::random::Rng;

    /// The whole film's scan, as the render made it before: the count and
    /// the first pixel in row order.
    fn scan(film: &Film) -> Option<(u64, u32, u32)> {
        let width = film.width() as usize;
        let mut bad = film
            .data()
            .chunks_exact(3)
            .enumerate()
            .filter(|(_, pixel)| pixel.iter().any(|v| !v.is_finite()))
            .map(|(i, _)| i);
        let first = bad.next()?;
        Some((
            1 + bad.count() as u64,
            (first % width) as u32,
            (first / width) as u32,
        ))
    }

    #[test]
    fn tiles_added_in_any_order_find_what_a_scan_of_the_film_finds() {
        let mut rng = Rng::new(20);
        let (width, height, side) = (37u32, 29u32, 8u32);
        for case in 0..200 {
            let mut film = Film::new(width, height, 3);
            // From none to many pixels, of each kind of value.
            for _ in 0..case % 7 * (case % 5) {
                let (x, y) = (rng.below(width), rng.below(height));
                let value = [f32::INFINITY, f32::NEG_INFINITY, f32::NAN][rng.below(3) as usize];
                let mut pixel = [0.5; 3];
                pixel[rng.below(3) as usize] = value;
                film.set_pixel(x, y, &pixel);
            }
            let mut tiles: Vec<NonFinite> = (0..height.div_ceil(side))
                .flat_map(|ty| (0..width.div_ceil(side)).map(move |tx| (tx * side, ty * side)))
                .map(|(x0, y0)| {
                    let (w, h) = (side.min(width - x0), side.min(height - y0));
                    let mut color = Vec::new();
                    for y in y0..y0 + h {
                        for x in x0..x0 + w {
                            color.extend_from_slice(film.pixel(x, y));
                        }
                    }
                    NonFinite::of_tile(x0, y0, w, &color)
                })
                .collect();
            for i in (1..tiles.len()).rev() {
                tiles.swap(i, rng.below(i as u32 + 1) as usize);
            }
            let mut found = NonFinite::default();
            tiles.into_iter().for_each(|t| found.add(t));
            let got = match found.check() {
                Ok(()) => None,
                Err(RenderError::NotFinite { count, x, y }) => Some((count, x, y)),
                Err(other) => panic!("{other}"),
            };
            assert_eq!(got, scan(&film), "case {case}");
        }
    }

    #[test]
    fn a_tile_names_its_first_bad_pixel_and_counts_them_all() {
        let mut color = vec![1.0; 3 * 12];
        color[3 * 5 + 2] = f32::NAN;
        color[3 * 9] = f32::INFINITY;
        color[3 * 9 + 1] = f32::NEG_INFINITY;
        let found = NonFinite::of_tile(16, 32, 4, &color);
        assert_eq!(
            found,
            NonFinite {
                count: 2,
                first: Some((33, 17)),
            }
        );
        assert_eq!(
            NonFinite::of_tile(0, 0, 4, &[0.0; 36]),
            NonFinite::default()
        );
    }
}
