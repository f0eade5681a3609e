//! Partial images (`.wpart`): the pixels one worker of a split render
//! computed, with what makes them part of one frame (the scene file's
//! SHA-256, the size, the samples, every setting and the camera), so that
//! `whitted merge` can put the frame together and refuse what does not
//! belong. docs/cluster.md describes the format:
//!
//! ```text
//! whitted-part 2
//! whitted-version 0.1.0
//! scene "scenes/whitted.toml"
//! scene-sha256 6f1d...
//! width 640
//! height 480
//! spp 4
//! aovs depth normal
//! color-space linear
//! camera Camera { ... }
//! settings RenderSettings { ... }
//! selection crop 0,0,640,480 tile 1/4
//! pixels 76800
//! data-sha256 9b0c...
//! data
//! ```
//!
//! then the selected pixels, row by row from the top, each as its colour
//! (3 floats) followed by each AOV's channels, as little-endian `f32`:
//! the exact bits the render computed, whose SHA-256 `data-sha256` gives.
//! A part is read back only if its data has that hash and every value is
//! one a render gives (a finite colour of 0 or more; see [`Aov::admits`]).

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::{Aov, PixelSelection, RenderOutput, Scene, Share, Window};
use crate::image::{ColorSpace, ImageError, PendingImage, encode_to_partial};

/// The first line of every part.
const MAGIC: &str = "whitted-part 2";

/// The first line of the parts of whitted 0.1 before their data had a
/// checksum.
const OLD_MAGIC: &str = "whitted-part 1";

/// What the scene hash says for the built-in scene, which has no file.
pub const BUILT_IN_SCENE: &str = "built-in";

/// What makes a part one of a frame, and which pixels it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct PartHeader {
    /// The whitted version that rendered it.
    pub version: String,
    /// The scene file as named on the command line (for messages only).
    pub scene: String,
    /// SHA-256 of the scene file's bytes in hex, or [`BUILT_IN_SCENE`].
    pub scene_sha256: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// The AOVs it holds, in order.
    pub aovs: Vec<Aov>,
    /// What the colour values mean.
    pub color_space: ColorSpace,
    /// The camera, exactly (`Debug` prints each number so that it reads
    /// back to the same bits).
    pub camera: String,
    /// Every render setting but the thread count, exactly.
    pub settings: String,
    /// The pixels it holds.
    pub selection: PixelSelection,
}

/// Why a part could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PartError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The part.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a part, or a damaged one.
    #[error("{path}:{line}: {why}")]
    Malformed {
        /// The part.
        path: PathBuf,
        /// The header line at fault (or the one after the header).
        line: usize,
        /// What was expected.
        why: String,
    },
}

/// SHA-256 of a scene file's bytes, in lowercase hex (as `sha256sum`
/// prints it).
pub fn scene_sha256(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

impl PartHeader {
    /// The header of a part of `scene` holding `selection`; `name` is the
    /// scene file as the user named it, `sha256` its hash
    /// ([`scene_sha256`], or [`BUILT_IN_SCENE`]).
    pub fn new(scene: &Scene, name: &str, sha256: &str, selection: PixelSelection) -> Self {
        // The settings that change the time and never the pixels are left
        // out of the comparison, so parts of one frame may use them as
        // each machine suits.
        let settings = super::RenderSettings {
            threads: None,
            packets: true,
            fast_paths: true,
            ..scene.settings.clone()
        };
        Self {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: format!("{name:?}"),
            scene_sha256: sha256.to_string(),
            width: settings.width,
            height: settings.height,
            spp: settings.samples_per_pixel,
            aovs: settings.aovs.clone(),
            color_space: scene.color_space,
            camera: format!("{:?}", scene.camera),
            settings: format!("{settings:?}"),
            selection,
        }
    }

    /// Floats stored per pixel: the colour's 3 and each AOV's channels.
    pub fn floats_per_pixel(&self) -> usize {
        3 + self.aovs.iter().map(Aov::channels).sum::<usize>()
    }

    /// The header lines, each `key value`, in file order.
    fn lines(&self) -> Vec<(&'static str, String)> {
        let aovs = match self.aovs.as_slice() {
            [] => "-".to_string(),
            aovs => aovs.iter().map(Aov::name).collect::<Vec<_>>().join(" "),
        };
        vec![
            ("whitted-version", self.version.clone()),
            ("scene", self.scene.clone()),
            ("scene-sha256", self.scene_sha256.clone()),
            ("width", self.width.to_string()),
            ("height", self.height.to_string()),
            ("spp", self.spp.to_string()),
            ("aovs", aovs),
            ("color-space", self.color_space.name().to_string()),
            ("camera", self.camera.clone()),
            ("settings", self.settings.clone()),
            ("selection", self.selection.to_string()),
            ("pixels", self.selection.pixel_count().to_string()),
        ]
    }

    /// The first header line on which `self` and `other` differ as renders
    /// (the selection and the scene's name aside): its key and both values.
    pub fn render_difference(&self, other: &Self) -> Option<(&'static str, String, String)> {
        self.lines()
            .into_iter()
            .zip(other.lines())
            .filter(|((key, _), _)| !["scene", "selection", "pixels"].contains(key))
            .find(|((_, mine), (_, theirs))| mine != theirs)
            .map(|((key, mine), (_, theirs))| (key, mine, theirs))
    }
}

/// Encodes the selected pixels of `output` with `header` into a partial
/// file beside `path`, to be renamed into place by
/// [`PendingImage::commit`]: a worker stopped before that leaves no part.
pub fn encode_part(
    path: &Path,
    header: &PartHeader,
    output: &RenderOutput,
) -> Result<PendingImage, ImageError> {
    let mut hash = Sha256::new();
    for_each_value(header, output, |value| hash.update(value.to_le_bytes()));
    let data_sha256 = hex(&hash.finalize());
    encode_to_partial(path, |file| {
        let mut out = BufWriter::new(file);
        writeln!(out, "{MAGIC}")?;
        for (key, value) in header.lines() {
            writeln!(out, "{key} {value}")?;
        }
        writeln!(out, "data-sha256 {data_sha256}")?;
        writeln!(out, "data")?;
        let mut written = Ok(());
        for_each_value(header, output, |value| {
            if written.is_ok() {
                written = out.write_all(&value.to_le_bytes());
            }
        });
        written?;
        out.flush()
    })
}

/// Calls `f` with each value a part of `output` holds, in file order.
fn for_each_value(header: &PartHeader, output: &RenderOutput, mut f: impl FnMut(f32)) {
    let window = header.selection.window;
    for y in header.selection.rows() {
        for x in window.x0..window.x1 {
            let films = std::iter::once(&output.image).chain(output.aovs.iter().map(|(_, f)| f));
            for &value in films.flat_map(|film| film.pixel(x, y)) {
                f(value);
            }
        }
    }
}

/// Bytes in lowercase hex, as `sha256sum` prints a hash.
fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A part read back: its header and its pixels' floats, in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// What it belongs to and which pixels it holds.
    pub header: PartHeader,
    /// [`PartHeader::floats_per_pixel`] floats for each selected pixel.
    pub values: Vec<f32>,
}

/// Reads the part at `path`, checking its header and that it holds
/// exactly the pixels it says.
pub fn read_part(path: &Path) -> Result<Part, PartError> {
    let bytes = crate::limits::read_input(path).map_err(|source| PartError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_part(&bytes, path)
}

/// Reads a part from its bytes; `path` names it in errors.
pub fn parse_part(bytes: &[u8], path: &Path) -> Result<Part, PartError> {
    let mut reader = HeaderReader {
        bytes,
        at: 0,
        line: 0,
        path,
    };
    let magic = reader.line()?;
    if magic == OLD_MAGIC {
        return Err(reader.error(
            "a part written by an older whitted, without a checksum of its data: render it \
             again with this one"
                .to_string(),
        ));
    }
    if magic != MAGIC {
        return Err(reader.error(format!(
            "not a whitted part: expected the first line `{MAGIC}` (a file written by \
             `whitted render --tile` or `--crop` with a .wpart output)"
        )));
    }
    let version = reader.value("whitted-version")?.to_string();
    let scene = reader.value("scene")?.to_string();
    let scene_sha256 = reader.value("scene-sha256")?.to_string();
    let width = reader.number("width")?;
    let height = reader.number("height")?;
    crate::render::check_image_size(width, height).map_err(|e| reader.error(e.to_string()))?;
    let spp = reader.number("spp")?;
    if spp == 0 {
        return Err(reader.error(
            "`spp 0`: a render takes at least one sample per pixel; the part is damaged"
                .to_string(),
        ));
    }
    let aovs = reader.value("aovs")?;
    let aovs = match aovs {
        "-" => Vec::new(),
        names => names
            .split(' ')
            .map(|name| {
                Aov::from_name(name).ok_or_else(|| reader.error(format!("unknown AOV `{name}`")))
            })
            .collect::<Result<Vec<_>, _>>()?,
    };
    let color_space = reader.value("color-space")?;
    let color_space = ColorSpace::from_name(color_space)
        .ok_or_else(|| reader.error(format!("unknown colour space `{color_space}`")))?;
    let camera = reader.value("camera")?.to_string();
    let settings = reader.value("settings")?.to_string();
    let selection = reader.value("selection")?;
    let selection = parse_selection(selection).ok_or_else(|| {
        reader.error(format!(
            "`{selection}` is not a selection: expected `crop X0,Y0,X1,Y1` and optionally \
             ` tile I/N`"
        ))
    })?;
    selection
        .check(width, height)
        .map_err(|e| reader.error(e.to_string()))?;
    let pixels: u64 = reader.number("pixels")?;
    if pixels != selection.pixel_count() {
        return Err(reader.error(format!(
            "{pixels} pixels said, but the selection holds {}",
            selection.pixel_count()
        )));
    }
    let data_sha256 = reader.value("data-sha256")?;
    if reader.line()? != "data" {
        return Err(reader.error("expected the line `data` after the header".to_string()));
    }
    let header = PartHeader {
        version,
        scene,
        scene_sha256,
        width,
        height,
        spp,
        aovs,
        color_space,
        camera,
        settings,
        selection,
    };
    let data = &bytes[reader.at..];
    let expected = pixels * header.floats_per_pixel() as u64 * 4;
    if data.len() as u64 != expected {
        return Err(reader.error(format!(
            "the pixel data is {} bytes, but {pixels} pixels of {} floats take {expected}: \
             the file is truncated or damaged; render this part again",
            data.len(),
            header.floats_per_pixel()
        )));
    }
    let found = hex(&Sha256::digest(data));
    if found != data_sha256 {
        return Err(reader.error(format!(
            "the pixel data's SHA-256 is {found}, but the header says {data_sha256}: the \
             data is damaged; render this part again"
        )));
    }
    let values: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    check_values(&header, &values).map_err(|why| reader.error(why))?;
    Ok(Part { header, values })
}

/// Refuses a value no render gives (see the module's doc), naming its
/// pixel, what it is and the value.
fn check_values(header: &PartHeader, values: &[f32]) -> Result<(), String> {
    // Each value's AOV in a pixel's order; `None` for the colour.
    let channels: Vec<Option<Aov>> = [None; 3]
        .into_iter()
        .chain(
            header
                .aovs
                .iter()
                .flat_map(|&aov| std::iter::repeat_n(Some(aov), aov.channels())),
        )
        .collect();
    let admits = |i: usize, v: f32| match channels[i % channels.len()] {
        None => v >= 0.0 && v.is_finite(),
        Some(aov) => aov.admits(v),
    };
    let Some(at) = (0..values.len()).find(|&i| !admits(i, values[i])) else {
        return Ok(());
    };
    let what = channels[at % channels.len()].map_or("colour", |aov| aov.name());
    let window = header.selection.window;
    let pixel = at / channels.len();
    let columns = (window.x1 - window.x0) as usize;
    let x = window.x0 as usize + pixel % columns;
    let y = header.selection.rows().nth(pixel / columns).unwrap_or(0);
    Err(format!(
        "pixel ({x}, {y}) holds the {what} value {}, which no render gives: the part is \
         damaged; render it again",
        values[at]
    ))
}

/// `crop X0,Y0,X1,Y1` with an optional ` tile I/N`.
fn parse_selection(text: &str) -> Option<PixelSelection> {
    let mut words = text.split(' ');
    let numbers = |text: &str, separator: char| -> Option<Vec<u32>> {
        text.split(separator).map(|n| n.parse().ok()).collect()
    };
    if words.next()? != "crop" {
        return None;
    }
    let [x0, y0, x1, y1] = numbers(words.next()?, ',')?[..] else {
        return None;
    };
    let share = match (words.next(), words.next()) {
        (None, _) => None,
        (Some("tile"), Some(share)) => {
            let [index, count] = numbers(share, '/')?[..] else {
                return None;
            };
            Some(Share { index, count })
        }
        _ => return None,
    };
    if words.next().is_some() {
        return None;
    }
    Some(PixelSelection {
        window: Window { x0, y0, x1, y1 },
        share,
    })
}

/// Reads a part's header line by line.
struct HeaderReader<'a> {
    bytes: &'a [u8],
    at: usize,
    line: usize,
    path: &'a Path,
}

impl<'a> HeaderReader<'a> {
    fn error(&self, why: String) -> PartError {
        PartError::Malformed {
            path: self.path.to_path_buf(),
            line: self.line,
            why,
        }
    }

    /// The next line, without its line feed.
    fn line(&mut self) -> Result<&'a str, PartError> {
        self.line += 1;
        let rest = &self.bytes[self.at..];
        let Some(end) = rest.iter().take(1 << 16).position(|&b| b == b'\n') else {
            return Err(self.error(
                "expected a header line ending in a line feed: the file is not a whitted part \
                 or is truncated"
                    .to_string(),
            ));
        };
        self.at += end + 1;
        std::str::from_utf8(&rest[..end])
            .map_err(|_| self.error("the header line is not UTF-8 text".to_string()))
    }

    /// The value of the next line, which must be `key value`.
    fn value(&mut self, key: &str) -> Result<&'a str, PartError> {
        let line = self.line()?;
        line.strip_prefix(key)
            .and_then(|rest| rest.strip_prefix(' '))
            .ok_or_else(|| self.error(format!("expected `{key} ...`, found `{line}`")))
    }

    /// The whole number on the next line, `key N`.
    fn number<T: std::str::FromStr>(&mut self, key: &str) -> Result<T, PartError> {
        let value = self.value(key)?;
        value
            .parse()
            .map_err(|_| self.error(format!("`{value}` is not a valid {key}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::render_selected;

    fn small_scene() -> Scene {
        let mut scene = crate::scene::default_scene();
        scene.settings.width = 20;
        scene.settings.height = 9;
        scene.settings.aovs = vec![Aov::Depth, Aov::Normal];
        scene
    }

    fn part_bytes(selection: PixelSelection) -> (PartHeader, Vec<u8>) {
        let scene = small_scene();
        let output = render_selected(&scene, &selection, &|_| {}).unwrap();
        let header = PartHeader::new(&scene, "s.toml", &scene_sha256(b"scene"), selection);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.wpart");
        encode_part(&path, &header, &output)
            .unwrap()
            .commit()
            .unwrap();
        (header, std::fs::read(&path).unwrap())
    }

    #[test]
    fn a_part_reads_back_as_written_with_the_exact_bits() {
        let selection = PixelSelection {
            window: Window::whole(20, 9),
            share: Some(Share { index: 1, count: 4 }),
        };
        let (header, bytes) = part_bytes(selection);
        let part = parse_part(&bytes, Path::new("p.wpart")).unwrap();
        assert_eq!(part.header, header);
        assert_eq!(part.values.len(), 2 * 20 * 7);
        let whole = crate::render::render(&small_scene(), &|_| {}).unwrap();
        // The first pixel of the part is (0, 1): colour, depth, normal.
        let mut expected = whole.image.pixel(0, 1).to_vec();
        expected.extend_from_slice(whole.aovs[0].1.pixel(0, 1));
        expected.extend_from_slice(whole.aovs[1].1.pixel(0, 1));
        assert_eq!(part.values[..7], expected[..]);
    }

    #[test]
    fn a_damaged_part_is_refused_naming_the_line() {
        let (_, bytes) = part_bytes(PixelSelection::whole(20, 9));
        let text_end = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        let truncated = &bytes[..bytes.len() - 4];
        let error = parse_part(truncated, Path::new("p.wpart"))
            .unwrap_err()
            .to_string();
        assert!(
            error.starts_with("p.wpart:15: the pixel data is"),
            "{error}"
        );
        let header = String::from_utf8(bytes[..text_end].to_vec()).unwrap();
        for (from, to, says) in [
            (
                "whitted-part 2",
                "whitted-part 3",
                "p.wpart:1: not a whitted part",
            ),
            (
                "whitted-part 2",
                "whitted-part 1",
                "p.wpart:1: a part written by an older whitted, without a checksum",
            ),
            (
                "spp 1",
                "spp 0",
                "p.wpart:7: `spp 0`: a render takes at least one sample",
            ),
            (
                "width 20",
                "width 0",
                "p.wpart:6: the image size 0x9 is not valid",
            ),
            ("spp 1", "spp x", "p.wpart:7: `x` is not a valid spp"),
            (
                "aovs depth",
                "aovs albedo",
                "p.wpart:8: unknown AOV `albedo`",
            ),
            (
                "crop 0,0,20,9",
                "crop 0,0,21,9",
                "p.wpart:12: the window 0,0,21,9",
            ),
            ("crop 0,0,20,9", "crop 0,0,20", "is not a selection"),
            ("pixels 180", "pixels 181", "181 pixels said"),
        ] {
            let mut changed = header.replace(from, to).into_bytes();
            changed.extend_from_slice(&bytes[text_end..]);
            let error = parse_part(&changed, Path::new("p.wpart"))
                .unwrap_err()
                .to_string();
            assert!(error.contains(says), "{from} -> {to}: {error}");
        }
    }

    #[test]
    fn damaged_data_is_refused_by_its_checksum_and_values_no_render_gives_by_their_pixel() {
        let (_, bytes) = part_bytes(PixelSelection {
            window: Window {
                x0: 2,
                y0: 0,
                x1: 20,
                y1: 9,
            },
            share: Some(Share { index: 1, count: 2 }),
        });
        let data_at = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        let mut flipped = bytes.clone();
        flipped[data_at + 9] ^= 0x10;
        let error = parse_part(&flipped, Path::new("p.wpart"))
            .unwrap_err()
            .to_string();
        assert!(
            error.starts_with("p.wpart:15: the pixel data's SHA-256 is")
                && error.ends_with("the data is damaged; render this part again"),
            "{error}"
        );
        // The same values with a hash that matches them: only the values'
        // rule is left to refuse them. A pixel is colour, depth, normal.
        let with_value = |index: usize, value: f32| {
            let mut data = bytes[data_at..].to_vec();
            data[index * 4..index * 4 + 4].copy_from_slice(&value.to_le_bytes());
            let header = String::from_utf8(bytes[..data_at].to_vec()).unwrap();
            let old_hash = header
                .lines()
                .find_map(|l| l.strip_prefix("data-sha256 "))
                .unwrap();
            let mut changed = header
                .replace(old_hash, &hex(&Sha256::digest(&data)))
                .into_bytes();
            changed.extend_from_slice(&data);
            parse_part(&changed, Path::new("p.wpart")).map(|_| ())
        };
        let stride = 7;
        for (index, value, says) in [
            (0, f32::NAN, "pixel (2, 1) holds the colour value NaN"),
            (1, -0.5, "pixel (2, 1) holds the colour value -0.5"),
            (
                stride + 2,
                f32::INFINITY,
                "pixel (3, 1) holds the colour value inf",
            ),
            (
                18 * stride + 3,
                -1.0,
                "pixel (2, 3) holds the depth value -1",
            ),
            (3, f32::NAN, "pixel (2, 1) holds the depth value NaN"),
            (
                5,
                f32::NEG_INFINITY,
                "pixel (2, 1) holds the normal value -inf",
            ),
        ] {
            let error = with_value(index, value).unwrap_err().to_string();
            assert!(
                error.starts_with("p.wpart:15: ")
                    && error.contains(says)
                    && error
                        .ends_with("which no render gives: the part is damaged; render it again"),
                "{index} {value}: {error}"
            );
        }
        // What a render does give is read: a miss's depth, a bright colour.
        with_value(3, f32::INFINITY).unwrap();
        with_value(0, 3e38).unwrap();
        with_value(4, -1.0).unwrap();
    }

    #[test]
    fn every_aov_admits_what_a_render_gives_and_nothing_else() {
        let gives = [
            (Aov::Depth, vec![0.0, 2.5, f32::INFINITY]),
            (Aov::Normal, vec![-1.0, 0.0, 0.6]),
            (Aov::Id, vec![-1.0, 0.0, 16_777_216.0]),
            (Aov::Cost, vec![0.0, 17.0]),
            (Aov::Instance, vec![-1.0, 3.0]),
        ];
        let never = [
            (Aov::Depth, vec![-0.1, f32::NAN, f32::NEG_INFINITY]),
            (Aov::Normal, vec![f32::NAN, f32::INFINITY]),
            (Aov::Id, vec![-2.0, 0.5, f32::NAN, f32::INFINITY]),
            (Aov::Cost, vec![-1.0, 1.5, f32::NAN, f32::INFINITY]),
            (Aov::Instance, vec![-2.0, 0.25, f32::NAN]),
        ];
        assert_eq!(gives.len(), Aov::ALL.len());
        for (aov, values) in gives {
            assert!(values.iter().all(|&v| aov.admits(v)), "{aov:?}");
        }
        for (aov, values) in never {
            assert!(values.iter().all(|&v| !aov.admits(v)), "{aov:?}");
        }
    }

    #[test]
    fn renders_that_differ_are_told_apart_by_their_first_differing_line_and_time_settings_are_not()
    {
        let scene = small_scene();
        let whole = PixelSelection::whole(20, 9);
        let header = PartHeader::new(&scene, "a.toml", "aa", whole);
        let mut threads = scene.clone();
        threads.settings.threads = Some(3);
        let renamed = PartHeader::new(&threads, "b.toml", "aa", whole);
        assert_eq!(header.render_difference(&renamed), None);
        let mut single_rays = scene.clone();
        single_rays.settings.packets = false;
        let single_rays = PartHeader::new(&single_rays, "a.toml", "aa", whole);
        assert_eq!(header.render_difference(&single_rays), None);
        let mut deeper = scene.clone();
        deeper.settings.max_depth = 2;
        let (key, _, _) = header
            .render_difference(&PartHeader::new(&deeper, "a.toml", "aa", whole))
            .unwrap();
        assert_eq!(key, "settings");
        let other_file = PartHeader::new(&scene, "a.toml", "bb", whole);
        assert_eq!(
            header.render_difference(&other_file),
            Some(("scene-sha256", "aa".to_string(), "bb".to_string()))
        );
    }
}
