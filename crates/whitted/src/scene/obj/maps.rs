//! Texture maps of MTL materials: `map_Ka`, `map_Kd`, `map_Ks`, the
//! dissolve map `map_d`, bump maps (`bump`, `map_bump`, in any
//! capitalisation) and normal maps (`norm`, `map_Kn`, `map_norm`), with
//! their `-s`, `-o`, `-clamp`, `-bm` and `-imfchan` options, are applied;
//! the other options of the specification and the common extensions
//! (`-colorspace`, `-texres`, `-type`) are read and ignored, and an unknown
//! option is ignored with the words up to the file name (see [`read_map`]).
//!
//! ```text
//! map_Kd -s 2 2 -o 0.5 0 -clamp on textures\wood grain.png
//! map_Bump -bm 0.02 -imfchan l plaster.png
//! ```
//!
//! The file name is the rest of the line after the options (spaces
//! allowed); `\ ` is an escaped space, other backslashes are read as folder
//! separators and the path is relative to the MTL file.

use std::ops::Range;
use std::path::{Path, PathBuf};

use super::file_names::file_path;
use super::text::Line;
use crate::math::DVec2;
use crate::shading::texture::Wrap;

/// What a map applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum MapSlot {
    /// `map_Ka`.
    Ambient,
    /// `map_Kd`.
    Diffuse,
    /// `map_Ks`.
    Specular,
    /// `map_d`.
    Dissolve,
    /// `bump`, `map_bump` (any capitalisation).
    Bump,
    /// `norm`, `map_Kn`, `map_norm` (any capitalisation).
    Normal,
}

impl MapSlot {
    /// The slot of a map statement's keyword, if it is one we apply.
    pub(super) fn of(keyword: &str) -> Option<Self> {
        match keyword {
            "map_Ka" => Some(MapSlot::Ambient),
            "map_Kd" => Some(MapSlot::Diffuse),
            "map_Ks" => Some(MapSlot::Specular),
            "map_d" => Some(MapSlot::Dissolve),
            _ => match keyword.to_ascii_lowercase().as_str() {
                "bump" | "map_bump" => Some(MapSlot::Bump),
                "norm" | "map_kn" | "map_norm" => Some(MapSlot::Normal),
                _ => None,
            },
        }
    }

    /// What the material keeps when the map's file cannot be read.
    pub(super) fn fallback(self) -> &'static str {
        match self {
            MapSlot::Ambient => "`Ka` keeps its constant colour",
            MapSlot::Diffuse => "`Kd` keeps its constant colour",
            MapSlot::Specular => "`Ks` keeps its constant colour",
            MapSlot::Dissolve => "`d` keeps its constant value",
            MapSlot::Bump | MapSlot::Normal => "the surface is shaded without it",
        }
    }
}

/// Which channel of the image a scalar map (`map_d`, a bump map) reads
/// (`-imfchan`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Channel {
    /// Not given: a dissolve map reads alpha when the image has it, a bump
    /// map the luminance.
    Default,
    /// `-imfchan l` (and `r`, `g`, `b`, `z`, read as luminance).
    Luminance,
    /// `-imfchan m`: the matte (alpha) channel.
    Matte,
}

/// One map statement.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MapStatement {
    /// Which slot it fills.
    pub(super) slot: MapSlot,
    /// The image file, relative to the MTL file's folder.
    pub(super) file: PathBuf,
    /// Where the file name is, for warnings.
    pub(super) span: Range<usize>,
    /// `-clamp on` clamps; otherwise the image repeats.
    pub(super) wrap: Wrap,
    /// `-s u v`.
    pub(super) scale: DVec2,
    /// `-o u v`.
    pub(super) offset: DVec2,
    /// `-bm m`: the bump multiplier (strength of a bump or normal map).
    pub(super) bump_multiplier: f64,
    /// `-imfchan c`.
    pub(super) channel: Channel,
    /// Options we do not know, ignored (and warned about).
    pub(super) unknown_options: Vec<UnknownOption>,
}

/// Options and how many words follow each (at most; `-s`, `-o` and `-t`
/// take one to three numbers, `-mm` two). Besides the specification's, the
/// common extensions `-colorspace`, `-texres`, `-imfchan` and `-type`.
fn arguments(option: &str) -> Option<usize> {
    match option {
        "-s" | "-o" | "-t" => Some(3),
        "-clamp" | "-blendu" | "-blendv" | "-cc" | "-bm" | "-boost" | "-texres" | "-imfchan"
        | "-colorspace" | "-type" => Some(1),
        "-mm" => Some(2),
        _ => None,
    }
}

/// True for a word that is an option we do not know: a `-` and a name, not
/// a negative number.
fn is_unknown_option(word: &str) -> bool {
    word.len() > 1 && word.starts_with('-') && word.parse::<f64>().is_err()
}

/// An option of a map statement that we do not know, ignored.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct UnknownOption {
    /// The option, as written (`-foo`).
    pub(super) name: String,
    /// Where it is, for the warning.
    pub(super) span: Range<usize>,
    /// The words taken as its arguments, between spaces.
    pub(super) arguments: String,
}

impl MapStatement {
    /// Applies a known option `option` with the words after it.
    fn apply(&mut self, option: &str, values: &[&str]) {
        let numbers: Vec<f64> = values.iter().filter_map(|w| w.parse().ok()).collect();
        match (option, numbers.as_slice(), values.first()) {
            ("-s", &[u], _) => self.scale = DVec2::splat(u),
            ("-s", &[u, v, ..], _) => self.scale = DVec2::new(u, v),
            ("-o", &[u], _) => self.offset = DVec2::new(u, 0.0),
            ("-o", &[u, v, ..], _) => self.offset = DVec2::new(u, v),
            ("-clamp", _, Some(&"on")) => self.wrap = Wrap::Clamp,
            ("-clamp", _, Some(&"off")) => self.wrap = Wrap::Repeat,
            ("-bm", &[m], _) => self.bump_multiplier = m,
            ("-imfchan", _, Some(&"m")) => self.channel = Channel::Matte,
            ("-imfchan", _, Some(_)) => self.channel = Channel::Luminance,
            _ => {}
        }
    }
}

/// The longest path a file may have on the systems we run on (Linux's
/// `PATH_MAX`): a longer rest of a line names no file.
const MAX_PATH_BYTES: usize = 4096;

/// Reads a map line of an MTL file in folder `folder` (one whose keyword
/// [`MapSlot::of`] knows); `None` for other lines or a map without a file
/// name.
///
/// An option we do not know takes the words up to the next option we know;
/// when none follows, the file is the longest end of the line that names
/// an existing file, or else the last word, and the words between are the
/// unknown option's.
pub(super) fn read_map(line: Line<'_>, folder: &Path) -> Option<MapStatement> {
    let words: Vec<(&str, Range<usize>)> = line.words().collect();
    let slot = MapSlot::of(words.first()?.0)?;
    let mut statement = MapStatement {
        slot,
        file: PathBuf::new(),
        span: 0..0,
        wrap: Wrap::Repeat,
        scale: DVec2::ONE,
        offset: DVec2::ZERO,
        bump_multiplier: 1.0,
        channel: Channel::Default,
        unknown_options: Vec::new(),
    };
    // The rest of the line from word `i`: a file name may hold spaces.
    let tail = |i: usize| line.text[words[i].1.start - line.start..].trim();
    let mut at = 1;
    while let Some((option, span)) = words.get(at) {
        at += 1;
        if let Some(count) = arguments(option) {
            // A one-word option takes its word; number lists take numbers only.
            let mut values = Vec::new();
            while let Some((word, _)) = words.get(at).filter(|(word, _)| {
                values.len() < count && (count == 1 || word.parse::<f64>().is_ok())
            }) {
                values.push(*word);
                at += 1;
            }
            statement.apply(option, &values);
        } else if is_unknown_option(option) {
            let rest = &words[at..];
            let taken = match rest.iter().position(|(word, _)| arguments(word).is_some()) {
                Some(next_option) => next_option,
                // Only the tails short enough to be a path are tried, so a
                // long line costs time in proportion to its length.
                None => (at..words.len())
                    .position(|i| {
                        tail(i).len() <= MAX_PATH_BYTES && folder.join(file_path(tail(i))).is_file()
                    })
                    .unwrap_or(rest.len().saturating_sub(1)),
            };
            let arguments: Vec<&str> = rest[..taken].iter().map(|(word, _)| *word).collect();
            statement.unknown_options.push(UnknownOption {
                name: (*option).to_string(),
                span: span.clone(),
                arguments: arguments.join(" "),
            });
            at += taken;
        } else {
            at -= 1;
            break;
        }
    }
    let (_, first) = words.get(at)?;
    let name = tail(at);
    statement.span = first.start..first.start + name.len();
    statement.file = folder.join(file_path(name));
    Some(statement)
}

#[cfg(test)]
mod tests {
    use super::super::text::lines;
    use super::*;

    fn map(text: &str) -> Option<MapStatement> {
        read_map(lines(text).next()?, Path::new("models"))
    }

    #[test]
    fn options_are_read_and_the_rest_is_the_file() {
        let m = map("map_Kd -s 2 3 1 -o 0.5 -clamp on -bm 0.2 textures\\wood grain.png").unwrap();
        assert_eq!(m.slot, MapSlot::Diffuse);
        assert_eq!(m.file, Path::new("models/textures/wood grain.png"));
        assert_eq!(
            (m.scale, m.offset),
            (DVec2::new(2.0, 3.0), DVec2::new(0.5, 0.0))
        );
        assert_eq!(m.wrap, Wrap::Clamp);
        assert_eq!(m.bump_multiplier, 0.2);
        assert_eq!(m.span, 41..64);
    }

    #[test]
    fn bump_normal_and_dissolve_maps_are_recognised_in_exporters_spellings() {
        for (line, slot) in [
            ("bump h.png", MapSlot::Bump),
            ("map_bump h.png", MapSlot::Bump),
            ("map_Bump h.png", MapSlot::Bump),
            ("BUMP h.png", MapSlot::Bump),
            ("norm n.png", MapSlot::Normal),
            ("map_Kn n.png", MapSlot::Normal),
            ("map_d a.png", MapSlot::Dissolve),
        ] {
            assert_eq!(map(line).map(|m| m.slot), Some(slot), "{line}");
        }
        let m = map("map_Bump -bm 0.05 -imfchan m -clamp on h.png").unwrap();
        assert_eq!(
            (m.bump_multiplier, m.channel, m.wrap),
            (0.05, Channel::Matte, Wrap::Clamp)
        );
        assert_eq!(
            map("map_d -imfchan l a.png").unwrap().channel,
            Channel::Luminance
        );
        assert_eq!(map("map_d a.png").unwrap().channel, Channel::Default);
        assert!(map("disp d.png").is_none() && map("map_Ns n.png").is_none());
    }

    #[test]
    fn common_extensions_are_read_and_unknown_options_never_become_the_file() {
        let m = map("map_Kd -colorspace sRGB -o 0.1 -texres 512 -type sphere diffuse.jpg").unwrap();
        assert_eq!(m.file, Path::new("models/diffuse.jpg"));
        assert_eq!(m.offset, DVec2::new(0.1, 0.0));
        assert!(m.unknown_options.is_empty());
        // An unknown option takes the words up to the next known one...
        let m = map("map_Kd -foo 1 2 -s 2 texture 01.png").unwrap();
        assert_eq!(m.file, Path::new("models/texture 01.png"));
        assert_eq!(m.scale, DVec2::splat(2.0));
        assert_eq!(
            m.unknown_options,
            [UnknownOption {
                name: "-foo".into(),
                span: 7..11,
                arguments: "1 2".into()
            }]
        );
        // ... or, last, all but the file: the last word unless a longer end
        // of the line names an existing file.
        let m = map("map_Kd -bar on texture 01.png").unwrap();
        assert_eq!(m.file, Path::new("models/01.png"));
        assert_eq!(m.unknown_options[0].arguments, "on texture");
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("texture 01.png"), "").unwrap();
        let line = lines("map_Kd -bar on texture 01.png").next().unwrap();
        let m = read_map(line, dir.path()).unwrap();
        assert_eq!(m.file, dir.path().join("texture 01.png"));
        assert_eq!(m.unknown_options[0].arguments, "on");
        let m = map("map_Kd -flip a.png").unwrap();
        assert_eq!(
            (m.file.as_path(), m.unknown_options[0].arguments.as_str()),
            (Path::new("models/a.png"), "")
        );
        assert!(map("map_Kd -flip").is_none());
        // A negative number is an argument, not an option.
        let m = map("map_Kd -o -0.5 -0.25 a\\ b.png").unwrap();
        assert_eq!(m.offset, DVec2::new(-0.5, -0.25));
        assert_eq!(m.file, Path::new("models/a b.png"));
    }

    #[test]
    fn a_bare_map_repeats_once_over_the_unit_square() {
        let m = map("map_Ks spec.jpg").unwrap();
        assert_eq!(
            (m.slot, m.wrap, m.scale),
            (MapSlot::Specular, Wrap::Repeat, DVec2::ONE)
        );
        assert!(map("map_Kd -clamp on").is_none());
    }
}
