//! Texture maps of MTL materials: `map_Ka`, `map_Kd`, `map_Ks`, the
//! dissolve map `map_d`, bump maps (`bump`, `map_bump`, in any
//! capitalisation) and normal maps (`norm`, `map_Kn`, `map_norm`), with
//! their `-s`, `-o`, `-clamp`, `-bm` and `-imfchan` options, are applied;
//! other options are read and ignored.
//!
//! ```text
//! map_Kd -s 2 2 -o 0.5 0 -clamp on textures\wood grain.png
//! map_Bump -bm 0.02 -imfchan l plaster.png
//! ```
//!
//! The file name is the rest of the line after the options (spaces
//! allowed); backslashes are read as folder separators and the path is
//! relative to the MTL file.

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
}

/// Options and how many words follow each (at most; `-s`, `-o` and `-t`
/// take one to three numbers).
fn arguments(option: &str) -> Option<usize> {
    match option {
        "-s" | "-o" | "-t" => Some(3),
        "-clamp" | "-blendu" | "-blendv" | "-cc" | "-bm" | "-boost" | "-texres" | "-imfchan" => {
            Some(1)
        }
        "-mm" => Some(2),
        _ => None,
    }
}

/// Reads a map line of an MTL file in folder `folder` (one whose keyword
/// [`MapSlot::of`] knows); `None` for other lines or a map without a file
/// name.
pub(super) fn read_map(line: Line<'_>, folder: &Path) -> Option<MapStatement> {
    let mut words = line.words().peekable();
    let slot = MapSlot::of(words.next()?.0)?;
    let mut statement = MapStatement {
        slot,
        file: PathBuf::new(),
        span: 0..0,
        wrap: Wrap::Repeat,
        scale: DVec2::ONE,
        offset: DVec2::ZERO,
        bump_multiplier: 1.0,
        channel: Channel::Default,
    };
    while let Some((option, _)) = words.next_if(|(word, _)| arguments(word).is_some()) {
        let count = arguments(option).unwrap_or(0);
        let mut values = Vec::new();
        // A one-word option takes its word; number lists take numbers only.
        while let Some((word, _)) = words.next_if(|(word, _)| {
            values.len() < count && (count == 1 || word.parse::<f64>().is_ok())
        }) {
            values.push(word);
        }
        let numbers: Vec<f64> = values.iter().filter_map(|w| w.parse().ok()).collect();
        match (option, numbers.as_slice(), values.first()) {
            ("-s", &[u], _) => statement.scale = DVec2::splat(u),
            ("-s", &[u, v, ..], _) => statement.scale = DVec2::new(u, v),
            ("-o", &[u], _) => statement.offset = DVec2::new(u, 0.0),
            ("-o", &[u, v, ..], _) => statement.offset = DVec2::new(u, v),
            ("-clamp", _, Some(&"on")) => statement.wrap = Wrap::Clamp,
            ("-clamp", _, Some(&"off")) => statement.wrap = Wrap::Repeat,
            ("-bm", &[m], _) => statement.bump_multiplier = m,
            ("-imfchan", _, Some(&"m")) => statement.channel = Channel::Matte,
            ("-imfchan", _, Some(_)) => statement.channel = Channel::Luminance,
            _ => {}
        }
    }
    let (_, first) = words.next()?;
    let name = line.text[first.start - line.start..].trim();
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
    fn a_bare_map_repeats_once_over_the_unit_square() {
        let m = map("map_Ks spec.jpg").unwrap();
        assert_eq!(
            (m.slot, m.wrap, m.scale),
            (MapSlot::Specular, Wrap::Repeat, DVec2::ONE)
        );
        assert!(map("map_Kd -clamp on").is_none());
    }
}
