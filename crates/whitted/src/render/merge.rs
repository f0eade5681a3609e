//! Putting a frame together from its parts (`whitted merge`): every part
//! must come from the same render (same scene file, version, settings and
//! camera), and together they must hold every pixel exactly once. The
//! films are then the ones a single render would have made, bit for bit.

use std::path::{Path, PathBuf};

use super::part::{Part, PartError, PartHeader, read_part};
use super::{Aov, Share};
use crate::image::Film;
use crate::limits::{MemoryBudget, MemoryError};

/// A frame merged from its parts.
#[derive(Clone, Debug, PartialEq)]
pub struct Merged {
    /// The first part's header (its selection aside, every part's).
    pub header: PartHeader,
    /// The colour image.
    pub image: Film,
    /// The AOVs the parts hold, in their order.
    pub aovs: Vec<(Aov, Film)>,
}

/// Why parts could not be merged; each names the part at fault.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// No part was given.
    #[error("no parts to merge")]
    NoParts,
    /// A part could not be read.
    #[error(transparent)]
    Part(#[from] PartError),
    /// A part of another render.
    #[error(
        "{path}: not a part of the same render as {first}: its {key} is `{theirs}`, where \
         {first} has `{ours}`"
    )]
    Mismatch {
        /// The part at fault.
        path: PathBuf,
        /// The first part, which the others must match.
        first: PathBuf,
        /// The header line that differs.
        key: &'static str,
        /// The part's value.
        theirs: String,
        /// The first part's value.
        ours: String,
    },
    /// Two parts hold the same pixel.
    #[error(
        "{path}: pixel ({x}, {y}) is also in {other}: each pixel must be in one part only \
         (a tile given twice, or crops that overlap)"
    )]
    Overlap {
        /// The later part.
        path: PathBuf,
        /// The earlier part holding the pixel.
        other: PathBuf,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// Pixels no part holds.
    #[error("{count} pixel(s) are in no part, the first at column {x}, row {y}{hint}")]
    Missing {
        /// How many.
        count: u64,
        /// The first one's column.
        x: u32,
        /// The first one's row.
        y: u32,
        /// Which tiles are missing, when the parts are tiles of one split.
        hint: String,
    },
    /// The merged films would exceed the memory budget.
    #[error(transparent)]
    Memory(#[from] MemoryError),
    /// The system refused the merged films' memory, which the budget
    /// allowed.
    #[error(transparent)]
    FilmAlloc(#[from] crate::image::FilmAllocError),
}

/// Reads the parts at `paths` and merges them into one frame.
pub fn merge_parts(paths: &[PathBuf]) -> Result<Merged, MergeError> {
    let (first_path, rest) = paths.split_first().ok_or(MergeError::NoParts)?;
    let first = read_part(first_path)?;
    let mut merge = Merge::new(&first, first_path)?;
    merge.add(&first, first_path)?;
    drop(first);
    for path in rest {
        let part = read_part(path)?;
        if let Some((key, theirs, ours)) = part.header.render_difference(&merge.header) {
            return Err(MergeError::Mismatch {
                path: path.clone(),
                first: first_path.clone(),
                key,
                theirs,
                ours,
            });
        }
        merge.add(&part, path)?;
    }
    merge.finish()
}

/// A frame being merged.
struct Merge<'a> {
    header: PartHeader,
    image: Film,
    aovs: Vec<(Aov, Film)>,
    /// For each pixel, 1 + the index in `paths` of the part holding it, or
    /// 0.
    owners: Vec<u32>,
    paths: Vec<&'a Path>,
    shares: Vec<(super::Window, Option<Share>)>,
}

impl<'a> Merge<'a> {
    /// Empty films of the size `first` says, checked against the budget.
    fn new(first: &Part, path: &Path) -> Result<Self, MergeError> {
        let header = first.header.clone();
        let (width, height) = (header.width, header.height);
        let pixels = u64::from(width) * u64::from(height);
        let bytes = pixels * (header.floats_per_pixel() as u64 + 1) * 4;
        MemoryBudget::current().check(
            &format!("merging a {width}x{height} image ({})", path.display()),
            bytes,
            "merge on a machine with more memory, or give a larger --max-memory",
        )?;
        Ok(Self {
            image: Film::try_new(width, height, 3)?.with_color_space(header.color_space),
            aovs: header
                .aovs
                .iter()
                .map(|&a| Ok((a, Film::try_new(width, height, a.channels())?)))
                .collect::<Result<_, MergeError>>()?,
            owners: vec![0; pixels as usize],
            paths: Vec::new(),
            shares: Vec::new(),
            header,
        })
    }

    /// Copies a part's pixels in, refusing any pixel already there.
    fn add(&mut self, part: &Part, path: &'a Path) -> Result<(), MergeError> {
        self.paths.push(path);
        let owner = self.paths.len() as u32;
        let selection = part.header.selection;
        self.shares.push((selection.window, selection.share));
        let width = self.header.width as usize;
        let stride = part.header.floats_per_pixel();
        let mut values = part.values.chunks_exact(stride);
        for y in selection.rows() {
            for x in selection.window.x0..selection.window.x1 {
                let i = y as usize * width + x as usize;
                if let Some(other) = self.owners[i].checked_sub(1) {
                    return Err(MergeError::Overlap {
                        path: path.to_path_buf(),
                        other: self.paths[other as usize].to_path_buf(),
                        x,
                        y,
                    });
                }
                self.owners[i] = owner;
                // The part's length was checked against its selection.
                let Some(pixel) = values.next() else {
                    continue;
                };
                let (color, mut rest) = pixel.split_at(3);
                self.image.set_pixel(x, y, color);
                for (aov, film) in &mut self.aovs {
                    let (these, after) = rest.split_at(aov.channels());
                    film.set_pixel(x, y, these);
                    rest = after;
                }
            }
        }
        Ok(())
    }

    /// The merged frame, once every pixel is there.
    fn finish(self) -> Result<Merged, MergeError> {
        let width = self.header.width as usize;
        let mut missing = self.owners.iter().enumerate().filter(|&(_, &o)| o == 0);
        if let Some((first, _)) = missing.next() {
            return Err(MergeError::Missing {
                count: 1 + missing.count() as u64,
                x: (first % width) as u32,
                y: (first / width) as u32,
                hint: self.missing_tiles(),
            });
        }
        Ok(Merged {
            header: self.header,
            image: self.image,
            aovs: self.aovs,
        })
    }

    /// "; missing: tile 2/4, tile 3/4" when every part is a tile of one
    /// split of one window (or, when every tile is there, that the window
    /// is not the whole image), else nothing.
    fn missing_tiles(&self) -> String {
        let Some(&(window, Some(Share { count, .. }))) = self.shares.first() else {
            return String::new();
        };
        let mut seen = Vec::new();
        for &(w, share) in &self.shares {
            match share {
                Some(s) if w == window && s.count == count => seen.push(s.index),
                _ => return String::new(),
            }
        }
        let missing: Vec<String> = (0..count)
            .filter(|i| !seen.contains(i))
            .take(10)
            .map(|i| format!("tile {i}/{count}"))
            .collect();
        if missing.is_empty() {
            let super::Window { x0, y0, x1, y1 } = window;
            return format!(
                "; the parts are every tile of the window {x0},{y0},{x1},{y1}, which is not the \
                 whole image"
            );
        }
        format!(
            "; missing: {} (render them again with --tile and merge all the parts)",
            missing.join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::part::{PartHeader, encode_part, scene_sha256};
    use crate::render::{PixelSelection, Scene, Window, render, render_selected};

    fn scene() -> Scene {
        let mut scene = crate::scene::default_scene();
        scene.settings.width = 23;
        scene.settings.height = 17;
        scene.settings.samples_per_pixel = 2;
        scene.settings.aovs = Aov::ALL.to_vec();
        scene
    }

    fn write_part(scene: &Scene, dir: &Path, name: &str, selection: PixelSelection) -> PathBuf {
        let output = render_selected(scene, &selection, &|_| {}).unwrap();
        let header = PartHeader::new(scene, "s.toml", &scene_sha256(b"s"), selection);
        let path = dir.join(name);
        encode_part(&path, &header, &output)
            .unwrap()
            .commit()
            .unwrap();
        path
    }

    fn tile(index: u32, count: u32) -> PixelSelection {
        PixelSelection {
            window: Window::whole(23, 17),
            share: Some(Share { index, count }),
        }
    }

    #[test]
    fn tiles_merge_into_the_single_render_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let scene = scene();
        let whole = render(&scene, &|_| {}).unwrap();
        let paths: Vec<PathBuf> = (0..4)
            .map(|i| write_part(&scene, dir.path(), &format!("{i}.wpart"), tile(i, 4)))
            .collect();
        let merged = merge_parts(&paths).unwrap();
        let bits = |film: &Film| film.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&merged.image), bits(&whole.image));
        assert_eq!(merged.aovs.len(), Aov::ALL.len());
        for ((aov, mine), (_, theirs)) in merged.aovs.iter().zip(&whole.aovs) {
            assert_eq!(bits(mine), bits(theirs), "{aov:?}");
        }
    }

    #[test]
    fn crops_merge_too_and_overlaps_and_holes_name_their_part() {
        let dir = tempfile::tempdir().unwrap();
        let scene = scene();
        let crop = |x0, y0, x1, y1| PixelSelection {
            window: Window { x0, y0, x1, y1 },
            share: None,
        };
        let top = write_part(&scene, dir.path(), "top.wpart", crop(0, 0, 23, 9));
        let bottom = write_part(&scene, dir.path(), "bottom.wpart", crop(0, 9, 23, 17));
        let middle = write_part(&scene, dir.path(), "middle.wpart", crop(5, 8, 9, 10));
        assert!(merge_parts(&[top.clone(), bottom.clone()]).is_ok());
        let error = merge_parts(&[top.clone(), bottom.clone(), middle])
            .unwrap_err()
            .to_string();
        assert_eq!(
            error,
            format!(
                "{}: pixel (5, 8) is also in {}: each pixel must be in one part only (a tile \
                 given twice, or crops that overlap)",
                dir.path().join("middle.wpart").display(),
                top.display()
            )
        );
        let error = merge_parts(std::slice::from_ref(&bottom))
            .unwrap_err()
            .to_string();
        assert_eq!(
            error,
            "207 pixel(s) are in no part, the first at column 0, row 0"
        );
    }

    #[test]
    fn a_missing_tile_and_a_part_of_another_render_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let scene = scene();
        let paths: Vec<PathBuf> = [0, 2]
            .map(|i| write_part(&scene, dir.path(), &format!("{i}.wpart"), tile(i, 3)))
            .to_vec();
        let error = merge_parts(&paths).unwrap_err().to_string();
        assert!(
            error.starts_with(
                "138 pixel(s) are in no part, the first at column 0, row 1; missing: tile 1/3"
            ),
            "{error}"
        );
        let mut other = scene.clone();
        other.settings.samples_per_pixel = 3;
        let stranger = write_part(&other, dir.path(), "1.wpart", tile(1, 3));
        let error = merge_parts(&[paths[0].clone(), stranger, paths[1].clone()])
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("1.wpart: not a part of the same render as")
                && error.contains("0.wpart: its spp is `3`, where"),
            "{error}"
        );
        assert!(matches!(merge_parts(&[]), Err(MergeError::NoParts)));
    }

    #[test]
    fn every_tile_of_a_window_smaller_than_the_image_is_named_as_such() {
        let dir = tempfile::tempdir().unwrap();
        let scene = scene();
        let paths: Vec<PathBuf> = [0, 1]
            .map(|index| {
                let selection = PixelSelection {
                    window: Window {
                        x0: 0,
                        y0: 0,
                        x1: 23,
                        y1: 8,
                    },
                    share: Some(Share { index, count: 2 }),
                };
                write_part(&scene, dir.path(), &format!("{index}.wpart"), selection)
            })
            .to_vec();
        let error = merge_parts(&paths).unwrap_err().to_string();
        assert_eq!(
            error,
            "207 pixel(s) are in no part, the first at column 0, row 8; the parts are every \
             tile of the window 0,0,23,8, which is not the whole image"
        );
    }
}
