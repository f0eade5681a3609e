//! Which pixels a render computes: a window of the image (`--crop`) and,
//! within it, one worker's share of the rows (`--tile I/N`), so that a
//! frame can be split over machines and merged back (docs/cluster.md).
//!
//! A share is every N-th row of the window, starting at row I: interleaved
//! rows, not N bands, so that each worker gets as much of the cheap sky
//! and of the costly glass as the others.

use std::fmt;
use std::ops::Range;

/// A rectangle of pixels: columns `x0..x1`, rows `y0..y1` (ends excluded).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

/// Worker `index` of `count`: rows `y0 + index`, `y0 + index + count`, ...
/// of the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Share {
    /// Which worker, from 0.
    pub index: u32,
    /// How many workers.
    pub count: u32,
}

/// The pixels a render computes; the others are left black.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelSelection {
    /// The window.
    pub window: Window,
    /// One worker's rows of the window, or all of them.
    pub share: Option<Share>,
}

/// Why a selection does not fit the image.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SelectionError {
    /// The window is empty or reaches past the image.
    #[error(
        "the window {x0},{y0},{x1},{y1} does not fit the {width}x{height} image: expected \
         X0,Y0,X1,Y1 with X0 < X1 <= {width} and Y0 < Y1 <= {height} (the ends are excluded)"
    )]
    BadWindow {
        /// First column.
        x0: u32,
        /// First row.
        y0: u32,
        /// Column end.
        x1: u32,
        /// Row end.
        y1: u32,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// More workers than rows, or a worker index out of range.
    #[error(
        "tile {index}/{count} does not fit: expected I/N with I from 0 to N-1 and N at most \
         {rows}, the rows to share"
    )]
    BadShare {
        /// Worker index.
        index: u32,
        /// Workers.
        count: u32,
        /// Rows in the window.
        rows: u32,
    },
}

impl Window {
    /// Every pixel of a `width` × `height` image.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }
}

impl PixelSelection {
    /// Every pixel of a `width` × `height` image.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            window: Window::whole(width, height),
            share: None,
        }
    }

    /// Checks that the selection fits a `width` × `height` image and
    /// gives every worker at least one row.
    pub fn check(&self, width: u32, height: u32) -> Result<(), SelectionError> {
        let Window { x0, y0, x1, y1 } = self.window;
        if x0 >= x1 || y0 >= y1 || x1 > width || y1 > height {
            return Err(SelectionError::BadWindow {
                x0,
                y0,
                x1,
                y1,
                width,
                height,
            });
        }
        if let Some(Share { index, count }) = self.share
            && (count == 0 || index >= count || count > y1 - y0)
        {
            return Err(SelectionError::BadShare {
                index,
                count,
                rows: y1 - y0,
            });
        }
        Ok(())
    }

    /// Whether row `y` has selected pixels.
    pub fn has_row(&self, y: u32) -> bool {
        let w = self.window;
        (w.y0..w.y1).contains(&y) && self.share.is_none_or(|s| (y - w.y0) % s.count == s.index)
    }

    /// Whether pixel (`x`, `y`) is selected.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        self.columns().contains(&x) && self.has_row(y)
    }

    /// The columns selected in every selected row.
    pub fn columns(&self) -> Range<u32> {
        self.window.x0..self.window.x1
    }

    /// The selected rows, top to bottom.
    pub fn rows(&self) -> impl Iterator<Item = u32> + '_ {
        let w = self.window;
        let (start, step) = match self.share {
            Some(s) => (w.y0 + s.index, s.count),
            None => (w.y0, 1),
        };
        (start..w.y1).step_by(step as usize)
    }

    /// How many pixels are selected.
    pub fn pixel_count(&self) -> u64 {
        let w = self.window;
        u64::from(w.x1 - w.x0) * self.rows().count() as u64
    }

    /// Whether the selection is the whole `width` × `height` image.
    pub fn is_whole(&self, width: u32, height: u32) -> bool {
        *self == Self::whole(width, height)
    }
}

impl fmt::Display for PixelSelection {
    /// `crop X0,Y0,X1,Y1` and `tile I/N`, as the command line spells them.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Window { x0, y0, x1, y1 } = self.window;
        write!(f, "crop {x0},{y0},{x1},{y1}")?;
        if let Some(Share { index, count }) = self.share {
            write!(f, " tile {index}/{count}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile(index: u32, count: u32) -> PixelSelection {
        PixelSelection {
            window: Window::whole(7, 10),
            share: Some(Share { index, count }),
        }
    }

    #[test]
    fn the_tiles_of_a_frame_cover_every_pixel_once() {
        for count in 1..=10 {
            let mut owners = vec![0; 70];
            for index in 0..count {
                let t = tile(index, count);
                assert!(t.check(7, 10).is_ok());
                for y in t.rows() {
                    for x in 0..7 {
                        assert!(t.contains(x, y));
                        owners[(y * 7 + x) as usize] += 1;
                    }
                }
                let counted = (0..10)
                    .flat_map(|y| (0..7).map(move |x| (x, y)))
                    .filter(|&(x, y)| t.contains(x, y))
                    .count() as u64;
                assert_eq!(t.pixel_count(), counted);
            }
            assert!(owners.iter().all(|&n| n == 1), "{count}: {owners:?}");
        }
    }

    #[test]
    fn tiles_interleave_rows_instead_of_cutting_bands() {
        let rows: Vec<u32> = tile(1, 4).rows().collect();
        assert_eq!(rows, [1, 5, 9]);
        let cropped = PixelSelection {
            window: Window {
                x0: 2,
                y0: 3,
                x1: 5,
                y1: 9,
            },
            share: Some(Share { index: 0, count: 2 }),
        };
        assert_eq!(cropped.rows().collect::<Vec<_>>(), [3, 5, 7]);
        assert!(!cropped.contains(1, 3) && !cropped.contains(2, 4));
        assert_eq!(cropped.pixel_count(), 9);
        assert_eq!(cropped.to_string(), "crop 2,3,5,9 tile 0/2");
    }

    #[test]
    fn selections_that_do_not_fit_are_refused() {
        let window = |x0, y0, x1, y1| PixelSelection {
            window: Window { x0, y0, x1, y1 },
            share: None,
        };
        assert!(window(0, 0, 7, 10).check(7, 10).is_ok());
        for bad in [window(0, 0, 8, 10), window(3, 0, 3, 10), window(0, 5, 7, 4)] {
            assert!(matches!(
                bad.check(7, 10),
                Err(SelectionError::BadWindow { .. })
            ));
        }
        for (index, count) in [(4, 4), (0, 0), (0, 11)] {
            let error = tile(index, count).check(7, 10).unwrap_err();
            assert!(matches!(error, SelectionError::BadShare { .. }), "{error}");
        }
    }
}
