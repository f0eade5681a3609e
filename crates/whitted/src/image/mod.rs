//! The film (a grid of float pixels) and its writers: PNG (8-bit, encoded
//! as the film's [`ColorSpace`] says), EXR and PFM (32-bit float, the values
//! as computed: linear light for a linear scene, display values for a
//! display-referred one).
//!
//! Files are written whole or not at all: the bytes go to a partial file
//! in the destination folder ([`partial`](self) files, removed on a
//! signal by [`remove_partial_files`]), which is renamed over the
//! destination only once complete. What may be replaced, and how, is the
//! job of [`check_destination`] and its module.

use std::io::{BufWriter, Write};

use rayon::prelude::*;
use std::path::{Path, PathBuf};

mod color_space;
mod destination;
mod heat_map;
mod partial;

pub use color_space::{ColorSpace, encode_display8, encode_srgb8};
pub use destination::{Destination, check_destination, check_text_destination};
pub use heat_map::{heat_map, ramp};
pub use partial::{PartialFilesRemoved, remove_partial_files, remove_partial_files_now};

use destination::{existing_file, folder_of, keep_attributes, resolve};
use partial::{IN_FLIGHT, PartialFile};

/// A `width` × `height` grid of pixels with `channels` float values each,
/// row 0 at the top, and what its values mean.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    channels: usize,
    color_space: ColorSpace,
    data: Vec<f32>,
}

/// The image file formats whitted writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit PNG (values clamped to [0, 1]): linear values through the
    /// sRGB curve, display values as they are.
    Png,
    /// OpenEXR, 32-bit float, the values as they are.
    Exr,
    /// Portable float map, 32-bit float, the values as they are.
    Pfm,
    /// A partial image of a render split over machines (`.wpart`, see
    /// `render::part`), merged into one of the others by `whitted merge`.
    Part,
}

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file name's extension names no format whitted writes.
    #[error("{path}: unknown image format; use a .png, .exr or .pfm file name")]
    UnknownFormat {
        /// The destination.
        path: PathBuf,
    },
    /// The destination may not be written, or its name names no file.
    #[error("{path}: {why}")]
    Refused {
        /// The destination as given.
        path: PathBuf,
        /// Why, in words.
        why: String,
    },
    /// The data can't be stored in that format.
    #[error("{path}: {why}")]
    Unsupported {
        /// The destination.
        path: PathBuf,
        /// What is not possible.
        why: String,
    },
    /// The file system refused.
    #[error("{path}: {source}{}", io_hint(source))]
    Io {
        /// The destination.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// What a user can do about a write error, when its cause says more
/// than its OS text: the file size limit a shell sets (`ulimit -f`).
fn io_hint(error: &std::io::Error) -> &'static str {
    if error.kind() == std::io::ErrorKind::FileTooLarge {
        ": the image is larger than this process may write (`ulimit -f`); raise the limit or \
         make the image smaller"
    } else {
        ""
    }
}

impl ImageFormat {
    /// The format named by a path's extension (case-insensitive). A path
    /// that names no file (empty, ending in `/`, `.` or `..`) or whose
    /// name is an extension alone (`.png`, a hidden file without one) is
    /// refused as such.
    pub fn from_path(path: &Path) -> Result<Self, ImageError> {
        let refused = |why: String| ImageError::Refused {
            path: path.to_path_buf(),
            why,
        };
        let Some(name) = path.file_name() else {
            return Err(refused(
                "this names no file; give a file name such as image.png".to_string(),
            ));
        };
        if path.as_os_str().as_encoded_bytes().ends_with(b"/") {
            return Err(refused(
                "the name ends with /, so it names a folder; give a file name such as image.png"
                    .to_string(),
            ));
        }
        let name = name.to_string_lossy();
        if path.extension().is_none()
            && let Some(ext) = name.strip_prefix('.')
            && ["png", "exr", "pfm"].contains(&ext.to_ascii_lowercase().as_str())
        {
            return Err(refused(format!(
                "`{name}` is a hidden file's name with no extension (a leading dot does not \
                 start an extension); give the file a name, such as image{name}"
            )));
        }
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            Some("pfm") => Ok(Self::Pfm),
            Some("wpart") => Ok(Self::Part),
            _ => Err(ImageError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// `count` zeros, or `None` when the system refuses their memory. Asked
/// of the allocator as zeroed memory, as `vec![0.0; count]` does, so that
/// no page is touched here ([`Film::map_pages`] maps them, in parallel and
/// in huge pages where it can).
fn zeroed_values(count: usize) -> Option<Vec<f32>> {
    if count == 0 {
        return Some(Vec::new());
    }
    let layout = std::alloc::Layout::array::<f32>(count).ok()?;
    // SAFETY: `layout` has a non-zero size (`count > 0`).
    let pointer = unsafe { std::alloc::alloc_zeroed(layout) }.cast::<f32>();
    if pointer.is_null() {
        return None;
    }
    // SAFETY: `pointer` was allocated by the global allocator with the
    // layout of `count` `f32`s, all of them initialised (zero bits are
    // `0.0`), and is owned by nothing else.
    Some(unsafe { Vec::from_raw_parts(pointer, count, count) })
}

/// The system refused the memory of a film (a limit such as `ulimit -v`,
/// or memory taken by others), though the budget allowed it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the system refused the {} of a {width}x{height} film ({channels} values a pixel); \
     free memory, raise the process's limit (ulimit -v), or render a smaller image",
    crate::limits::format_bytes(*bytes)
)]
pub struct FilmAllocError {
    /// The film's width.
    pub width: u32,
    /// The film's height.
    pub height: u32,
    /// Its values per pixel.
    pub channels: usize,
    /// The bytes asked for.
    pub bytes: u64,
}

impl Film {
    /// [`Film::new`], with a refusal of the memory by the system an error
    /// rather than an abort.
    pub fn try_new(width: u32, height: u32, channels: usize) -> Result<Self, FilmAllocError> {
        let values = width as usize * height as usize * channels;
        let refused = FilmAllocError {
            width,
            height,
            channels,
            bytes: (values as u64).saturating_mul(4),
        };
        let data = zeroed_values(values).ok_or(refused)?;
        Ok(Self {
            width,
            height,
            channels,
            color_space: ColorSpace::Linear,
            data,
        })
    }

    /// A black film of linear values.
    pub fn new(width: u32, height: u32, channels: usize) -> Self {
        Self {
            width,
            height,
            channels,
            color_space: ColorSpace::Linear,
            data: vec![0.0; width as usize * height as usize * channels],
        }
    }

    /// The same film, its values taken to be in `color_space`.
    pub fn with_color_space(self, color_space: ColorSpace) -> Self {
        Self {
            color_space,
            ..self
        }
    }

    /// What the values mean, which decides how a PNG encodes them.
    pub fn color_space(&self) -> ColorSpace {
        self.color_space
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Values per pixel.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// All values, row by row from the top, pixel by pixel, channel by
    /// channel.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The values of pixel (`x`, `y`).
    pub fn pixel(&self, x: u32, y: u32) -> &[f32] {
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        &self.data[i..i + self.channels]
    }

    /// Sets the values of pixel (`x`, `y`).
    pub fn set_pixel(&mut self, x: u32, y: u32, values: &[f32]) {
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        self.data[i..i + self.channels].copy_from_slice(values);
    }

    /// Sets the values of a run of pixels of row `y` from column `x` on:
    /// `values` holds the run's pixels one after the other.
    pub fn set_row(&mut self, x: u32, y: u32, values: &[f32]) {
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        self.data[i..i + values.len()].copy_from_slice(values);
    }

    /// Writes every value once, as zero, on the threads of the current
    /// rayon pool. A new film's memory is mapped page by page on its first
    /// write; a render maps it here, before the trace and on all its
    /// threads, rather than at each tile's first write, which is made
    /// under the lock that gathers the tiles (see docs/performance-log.md,
    /// `Film::map_pages`). Where the system has them, the film asks for
    /// 2 MiB pages first ([`advise_huge_pages`]).
    pub fn map_pages(&mut self) {
        /// One 4 KiB page of values.
        const PAGE: usize = 4096 / size_of::<f32>();
        #[cfg(target_os = "linux")]
        advise_huge_pages(&mut self.data);
        self.data
            .par_chunks_mut(16 * PAGE)
            .for_each(|chunk| chunk.fill(0.0));
    }

    /// Writes the film in the format its extension names, whole or not at
    /// all.
    pub fn write(&self, path: &Path) -> Result<(), ImageError> {
        self.encode(path)?.commit()
    }

    /// Encodes the film into a partial file beside `path` (beside its
    /// target if `path` is a symbolic link), to be renamed into place by
    /// [`PendingImage::commit`]. Nothing at `path` changes until then;
    /// dropping the result removes the partial file.
    pub fn encode(&self, path: &Path) -> Result<PendingImage, ImageError> {
        let format = ImageFormat::from_path(path)?;
        let encoder: Encoder = match format {
            ImageFormat::Png => |film, out| film.encode_png(out),
            ImageFormat::Pfm => Self::encode_pfm,
            ImageFormat::Exr => Self::encode_exr,
            ImageFormat::Part => {
                return Err(ImageError::Unsupported {
                    path: path.to_path_buf(),
                    why: "a .wpart file holds a part of a render, not a film".to_string(),
                });
            }
        };
        if format == ImageFormat::Png && self.channels != 1 && self.channels != 3 {
            return Err(ImageError::Unsupported {
                path: path.to_path_buf(),
                why: format!("PNG holds 1 or 3 channels, not {}", self.channels),
            });
        }
        encode_to_partial(path, |out| encoder(self, out))
    }

    /// The film encoded as PNG, in memory (to embed in another file).
    pub fn png_bytes(&self) -> Result<Vec<u8>, ImageError> {
        let mut bytes = Vec::new();
        self.encode_png(&mut bytes)
            .map_err(|source| ImageError::Io {
                path: PathBuf::from("(memory)"),
                source,
            })?;
        Ok(bytes)
    }

    fn encode_png(&self, out: impl std::io::Write) -> std::io::Result<()> {
        let mut encoder = png::Encoder::new(BufWriter::new(out), self.width, self.height);
        encoder.set_color(if self.channels == 1 {
            png::ColorType::Grayscale
        } else {
            png::ColorType::Rgb
        });
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let bytes: Vec<u8> = self
            .data
            .iter()
            .map(|&v| self.color_space.encode8(v))
            .collect();
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(&bytes)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    }

    /// PFM: a text header, then little-endian floats, bottom row first.
    fn encode_pfm(&self, out: &mut std::fs::File) -> std::io::Result<()> {
        let mut out = BufWriter::new(out);
        let (magic, channels) = match self.channels {
            1 => ("Pf", 1),
            _ => ("PF", 3),
        };
        write!(out, "{magic}\n{} {}\n-1.0\n", self.width, self.height)?;
        for y in (0..self.height).rev() {
            for x in 0..self.width {
                let p = self.pixel(x, y);
                for c in 0..channels {
                    let v = p.get(c).copied().unwrap_or(0.0);
                    out.write_all(&v.to_le_bytes())?;
                }
            }
        }
        out.flush()
    }

    fn encode_exr(&self, out: &mut std::fs::File) -> std::io::Result<()> {
        use exr::prelude::*;
        let names: &[&str] = match self.channels {
            1 => &["Y"],
            3 => &["R", "G", "B"],
            _ => &["R", "G", "B", "A"],
        };
        let pixels = self.width as usize * self.height as usize;
        let channels: Vec<AnyChannel<FlatSamples>> = names
            .iter()
            .enumerate()
            .map(|(c, name)| {
                let samples = (0..pixels)
                    .map(|i| self.data.get(i * self.channels + c).copied().unwrap_or(0.0))
                    .collect();
                AnyChannel::new(*name, FlatSamples::F32(samples))
            })
            .collect();
        let layer = Layer::new(
            (self.width as usize, self.height as usize),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(channels)),
        );
        Image::from_layer(layer)
            .write()
            .non_parallel()
            .to_buffered(BufWriter::new(out))
            .map_err(exr_io_error)
    }
}

/// The I/O error an EXR encoding failed with, as itself (a full disk stays
/// a full disk); its other errors as "other".
fn exr_io_error(error: exr::error::Error) -> std::io::Error {
    match error {
        exr::error::Error::Io(io) => io,
        other => std::io::Error::other(other),
    }
}

/// `error` without the partial file's name that some errors carry: the
/// system's error, named and numbered, where it is one ("No space left on
/// device (os error 28)"), else its kind.
fn without_partial_name(error: &std::io::Error) -> std::io::Error {
    match error.raw_os_error() {
        Some(code) => std::io::Error::from_raw_os_error(code),
        None => std::io::Error::new(error.kind(), error.kind().to_string()),
    }
}

/// A film's encoder into one format.
type Encoder = fn(&Film, &mut std::fs::File) -> std::io::Result<()>;

/// An encoded image waiting in a partial file beside its destination.
#[derive(Debug)]
pub struct PendingImage {
    partial: PartialFile,
    path: PathBuf,
    target: PathBuf,
}

impl PendingImage {
    /// Renames the finished file over its destination, after checking
    /// again that whatever is there may be replaced; the new file keeps the
    /// old one's permissions (and owner and group where allowed).
    pub fn commit(self) -> Result<(), ImageError> {
        let Self {
            mut partial,
            path,
            target,
        } = self;
        let io = |source: std::io::Error| ImageError::Io {
            path: path.clone(),
            source,
        };
        if let Some(existing) = existing_file(&path, &target)? {
            keep_attributes(partial.file(), &existing).map_err(io)?;
        }
        partial.persist(&target).map_err(io)
    }
}

/// Writes `text` into a partial file beside `path`, to be renamed into
/// place by [`PendingImage::commit`] like an image (for drawings and
/// reports written beside the pictures).
pub fn encode_text(path: &Path, text: &str) -> Result<PendingImage, ImageError> {
    encode_to_partial(path, |out| std::io::Write::write_all(out, text.as_bytes()))
}

/// Encodes into a new partial file in the folder of `path`'s target, to
/// be renamed into place by [`PendingImage::commit`]: the way to write any
/// output file whole or not at all.
pub fn encode_to_partial(
    path: &Path,
    encode: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> Result<PendingImage, ImageError> {
    let io = |source: std::io::Error| ImageError::Io {
        path: path.to_path_buf(),
        source: without_partial_name(&source),
    };
    let (target, _) = resolve(path)?;
    let mut partial = PartialFile::create_in(folder_of(&target), &IN_FLIGHT).map_err(io)?;
    encode(partial.file()).map_err(io)?;
    partial.file().sync_all().map_err(io)?;
    Ok(PendingImage {
        partial,
        path: path.to_path_buf(),
        target,
    })
}

/// Asks Linux to back the part of `values` that covers whole 2 MiB pages
/// with such pages (transparent huge pages, where the system lets a
/// program ask for them), so that mapping a film takes fewer page faults
/// (measured: docs/performance-log.md, "The films' fixed cost"). Only
/// advice: where the system refuses, the pages are the usual ones and
/// nothing else changes.
#[cfg(target_os = "linux")]
fn advise_huge_pages(values: &mut [f32]) {
    const HUGE_PAGE: usize = 2 << 20;
    let start = values.as_mut_ptr() as usize;
    let end = start + size_of_val(values);
    let (first, last) = (
        start.next_multiple_of(HUGE_PAGE),
        end / HUGE_PAGE * HUGE_PAGE,
    );
    if first < last {
        // A system without huge pages refuses: the film is then mapped as
        // before, so the answer is not needed.
        // SAFETY: `first..last` lies within `values`, which this function
        // borrows mutably; the advice changes how its pages are backed,
        // never what they hold.
        let _ = unsafe {
            rustix::mm::madvise(
                first as *mut std::ffi::c_void,
                last - first,
                rustix::mm::Advice::LinuxHugepage,
            )
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient() -> Film {
        let mut f = Film::new(3, 2, 3);
        for y in 0..2 {
            for x in 0..3 {
                f.set_pixel(x, y, &[x as f32 * 0.5, y as f32, 0.25]);
            }
        }
        f
    }

    #[test]
    fn a_row_of_pixels_lands_where_its_pixels_would_one_by_one() {
        for channels in [1, 3] {
            let mut by_pixel = Film::new(5, 3, channels);
            let mut by_row = Film::new(5, 3, channels);
            by_row.map_pages();
            let values: Vec<f32> = (0..3 * channels).map(|v| v as f32 + 1.0).collect();
            for (i, pixel) in values.chunks(channels).enumerate() {
                by_pixel.set_pixel(1 + i as u32, 2, pixel);
            }
            by_row.set_row(1, 2, &values);
            assert_eq!(by_row, by_pixel);
            assert_eq!(by_row.pixel(0, 2), vec![0.0; channels].as_slice());
            assert_eq!(by_row.pixel(4, 2), vec![0.0; channels].as_slice());
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn asking_for_huge_pages_keeps_every_value() {
        // Seven pages' worth, so that whole 2 MiB pages lie inside
        // wherever the allocator puts it.
        let mut values: Vec<f32> = (0..7 << 19).map(|i| i as f32).collect();
        advise_huge_pages(&mut values);
        assert!(values.iter().enumerate().all(|(i, &v)| v == i as f32));
        let mut film = Film::new(1024, 1024, 3);
        film.map_pages();
        assert!(film.data().iter().all(|&v| v == 0.0));
    }

    #[test]
    fn pfm_is_written_bottom_row_first_with_a_little_endian_scale() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.pfm");
        gradient().write(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let header = b"PF\n3 2\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let floats: Vec<f32> = bytes[header.len()..]
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(floats.len(), 18);
        // First stored pixel is the bottom-left one: (0, 1).
        assert_eq!(&floats[..3], &[0.0, 1.0, 0.25]);
    }

    #[test]
    fn a_full_disk_is_named_whatever_the_format() {
        let full = std::io::Error::from_raw_os_error(28);
        let from_exr = exr_io_error(exr::error::Error::Io(full));
        assert_eq!(from_exr.raw_os_error(), Some(28));
        let shown = without_partial_name(&from_exr).to_string();
        assert_eq!(shown, "No space left on device (os error 28)");
        let other = std::io::Error::new(std::io::ErrorKind::InvalidData, "/x/.whitted-1.partial");
        assert_eq!(without_partial_name(&other).to_string(), "invalid data");
    }

    #[test]
    fn png_and_exr_round_trip_through_their_decoders() {
        let dir = tempfile::tempdir().unwrap();
        let png_path = dir.path().join("g.png");
        gradient().write(&png_path).unwrap();
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&png_path).unwrap(),
        ));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(&buf[3..6], &[188, 0, 137]);

        let exr_path = dir.path().join("g.exr");
        gradient().write(&exr_path).unwrap();
        let image = exr::prelude::read_first_flat_layer_from_file(&exr_path).unwrap();
        assert_eq!(image.layer_data.size, exr::prelude::Vec2(3, 2));
        assert_eq!(image.layer_data.channel_data.list.len(), 3);
    }

    /// The 8-bit codes of a PNG file.
    fn png_codes(path: &Path) -> Vec<u8> {
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        buf
    }

    #[test]
    fn a_film_made_fallibly_is_the_black_film() {
        for (w, h, c) in [(0, 5, 3), (7, 0, 1), (1, 1, 1), (640, 480, 3), (33, 17, 4)] {
            assert_eq!(Film::try_new(w, h, c).unwrap(), Film::new(w, h, c));
        }
    }

    #[test]
    fn a_display_film_writes_its_values_without_the_curve_and_its_floats_unchanged() {
        let dir = tempfile::tempdir().unwrap();
        let film = gradient().with_color_space(ColorSpace::Display);
        assert_eq!(film.color_space(), ColorSpace::Display);
        let png_path = dir.path().join("g.png");
        film.write(&png_path).unwrap();
        // Pixel (1, 0) is (0.5, 0, 0.25); linear it would be (188, 0, 137).
        assert_eq!(&png_codes(&png_path)[3..6], &[128, 0, 64]);
        let pfm_path = dir.path().join("g.pfm");
        film.write(&pfm_path).unwrap();
        let linear_path = dir.path().join("linear.pfm");
        gradient().write(&linear_path).unwrap();
        assert_eq!(
            std::fs::read(&pfm_path).unwrap(),
            std::fs::read(&linear_path).unwrap()
        );
    }

    #[test]
    fn unknown_extensions_are_refused_and_nothing_is_left_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.bmp");
        assert!(matches!(
            gradient().write(&path),
            Err(ImageError::UnknownFormat { .. })
        ));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn an_encoder_failing_midway_leaves_the_old_file_intact_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.png");
        std::fs::write(&path, b"old").unwrap();
        let failed = encode_to_partial(&path, |out| {
            out.write_all(b"half an image")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(matches!(failed, Err(ImageError::Io { .. })));
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn nothing_changes_until_an_encoded_image_is_committed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.pfm");
        std::fs::write(&path, b"old").unwrap();
        let pending = gradient().encode(&path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        pending.commit().unwrap();
        assert!(std::fs::read(&path).unwrap().starts_with(b"PF\n"));
        drop(gradient().encode(&path).unwrap());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn destinations_are_checked_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(
            check_destination(&dir.path().join("a.exr"))
                .unwrap()
                .format(),
            Some(ImageFormat::Exr)
        );
        let missing = check_destination(Path::new("/no/such/folder/a.png")).unwrap_err();
        assert!(
            missing
                .to_string()
                .contains("the folder /no/such/folder does not exist")
        );
        assert!(check_destination(dir.path()).is_err());
        assert!(check_destination(Path::new("a.gif")).is_err());
    }

    #[test]
    fn names_that_are_no_file_or_an_extension_alone_say_so() {
        for (name, says) in [
            (".png", "`.png` is a hidden file's name with no extension"),
            (
                "out/.EXR",
                "`.EXR` is a hidden file's name with no extension",
            ),
            ("", "this names no file"),
            ("out/..", "this names no file"),
            ("x.png/", "the name ends with /, so it names a folder"),
            (".gif", "unknown image format"),
        ] {
            let error = ImageFormat::from_path(Path::new(name))
                .unwrap_err()
                .to_string();
            assert!(error.contains(says), "{name}: {error}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_replaced_file_keeps_its_mode_and_a_link_is_written_through() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let private = dir.path().join("private.pfm");
        std::fs::write(&private, b"old").unwrap();
        std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o600)).unwrap();
        gradient().write(&private).unwrap();
        let mode = std::fs::metadata(&private).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o600);

        let link = dir.path().join("link.pfm");
        std::os::unix::fs::symlink("private.pfm", &link).unwrap();
        std::fs::write(&private, b"old").unwrap();
        gradient().write(&link).unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert!(std::fs::read(&private).unwrap().starts_with(b"PF\n"));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[cfg(unix)]
    #[test]
    fn written_files_get_the_permissions_of_any_new_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain");
        std::fs::write(&plain, b"x").unwrap();
        let image = dir.path().join("g.png");
        gradient().write(&image).unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&image), mode(&plain));
    }

    #[test]
    fn writing_into_a_missing_folder_is_an_io_error() {
        let err = gradient()
            .write(Path::new("/nonexistent-folder/x.png"))
            .unwrap_err();
        assert!(matches!(err, ImageError::Refused { .. }));
        assert_eq!(
            err.to_string(),
            "/nonexistent-folder/x.png: the folder /nonexistent-folder does not exist"
        );
    }
}
