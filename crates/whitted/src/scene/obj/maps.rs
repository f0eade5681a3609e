//! Texture maps of MTL materials: `map_Ka`, `map_Kd` and `map_Ks`, with
//! their `-s`, `-o` and `-clamp` options, are applied; other options are
//! read and ignored.
//!
//! ```text
//! map_Kd -s 2 2 -o 0.5 0 -clamp on textures\wood grain.png
//! ```
//!
//! The file name is the rest of the line after the options (spaces
//! allowed); backslashes are read as folder separators and the path is
//! relative to the MTL file.

use std::ops::Range;
use std::path::{Path, PathBuf};

use super::text::Line;
use crate::math::DVec2;
use crate::texture::Wrap;

/// The colour slot a map applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum MapSlot {
    /// `map_Ka`.
    Ambient,
    /// `map_Kd`.
    Diffuse,
    /// `map_Ks`.
    Specular,
}

impl MapSlot {
    /// The slot of a map statement's keyword, if it is one we apply.
    pub(super) fn of(keyword: &str) -> Option<Self> {
        match keyword {
            "map_Ka" => Some(MapSlot::Ambient),
            "map_Kd" => Some(MapSlot::Diffuse),
            "map_Ks" => Some(MapSlot::Specular),
            _ => None,
        }
    }

    /// The MTL name of the colour the map replaces.
    pub(super) fn color_name(self) -> &'static str {
        match self {
            MapSlot::Ambient => "Ka",
            MapSlot::Diffuse => "Kd",
            MapSlot::Specular => "Ks",
        }
    }
}

/// One `map_K?` statement.
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

/// Reads a `map_Ka`, `map_Kd` or `map_Ks` line of an MTL file in folder
/// `folder`; `None` for other lines or a map without a file name.
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
            _ => {}
        }
    }
    let (_, first) = words.next()?;
    let name = line.text[first.start - line.start..].trim();
    statement.span = first.start..first.start + name.len();
    statement.file = folder.join(name.replace('\\', "/"));
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
        assert_eq!(m.span, 41..64);
    }

    #[test]
    fn a_bare_map_repeats_once_over_the_unit_square() {
        let m = map("map_Ks spec.jpg").unwrap();
        assert_eq!(
            (m.slot, m.wrap, m.scale),
            (MapSlot::Specular, Wrap::Repeat, DVec2::ONE)
        );
        assert!(map("map_d alpha.png").is_none());
        assert!(map("map_Kd -clamp on").is_none());
    }
}
