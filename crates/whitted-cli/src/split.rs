//! `whitted render --tile I/N`, `--crop X0,Y0,X1,Y1` and `.wpart`
//! outputs: rendering one part of a frame split over machines
//! (docs/cluster.md), to be put together by `whitted merge`.

use std::path::Path;

use whitted::image::ImageFormat;
use whitted::render::{
    Aov, BUILT_IN_SCENE, PartHeader, PixelSelection, RenderOutput, Scene, Share, Window,
    encode_part, scene_sha256,
};

/// `I/N`: worker I (from 0) of N.
pub fn tile(text: &str) -> Result<Share, String> {
    let expected = "expected I/N, worker I (from 0 to N-1) of N, like 0/4";
    let numbers = whole_numbers(text, '/', 2).map_err(|cause| format!("{cause}; {expected}"))?;
    let [index, count] = numbers[..] else {
        return Err(expected.to_string());
    };
    if count == 0 || index >= count {
        return Err(format!("{index}/{count} names no worker; {expected}"));
    }
    Ok(Share { index, count })
}

/// `X0,Y0,X1,Y1`: the window's first column and row, and the column and
/// row just past it.
pub fn crop(text: &str) -> Result<Window, String> {
    let expected = "expected X0,Y0,X1,Y1 with X0 < X1 and Y0 < Y1 (the ends excluded), \
                    like 0,0,320,240";
    let numbers = whole_numbers(text, ',', 4).map_err(|cause| format!("{cause}; {expected}"))?;
    let [x0, y0, x1, y1] = numbers[..] else {
        return Err(expected.to_string());
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!("{text} is an empty window; {expected}"));
    }
    Ok(Window { x0, y0, x1, y1 })
}

/// `count` whole numbers separated by `separator`.
fn whole_numbers(text: &str, separator: char, count: usize) -> Result<Vec<u32>, String> {
    let parts: Vec<&str> = text.split(separator).collect();
    if parts.len() != count {
        return Err(format!("{} number(s) given, not {count}", parts.len()));
    }
    parts
        .iter()
        .map(|part| {
            let part = part.trim();
            part.parse::<u32>()
                .map_err(|_| format!("`{part}` is not a whole number from 0 to {}", u32::MAX))
        })
        .collect()
}

/// A render of one part: which pixels, and the AOVs the part holds.
#[derive(Debug)]
pub struct PartRender {
    tile: Option<Share>,
    crop: Option<Window>,
    /// The AOVs to keep in the part.
    pub aovs: Vec<Aov>,
}

impl PartRender {
    /// The part asked for, if the output is a `.wpart` file; `--tile` and
    /// `--crop` ask for one, so they need that. A part holds its AOVs, so
    /// `--aov` names them alone.
    pub fn from_args(
        output: &Path,
        tile: Option<Share>,
        crop: Option<Window>,
        aov_specs: &[String],
    ) -> Result<Option<Self>, String> {
        if ImageFormat::from_path(output).ok() != Some(ImageFormat::Part) {
            return match (tile, crop) {
                (None, None) => Ok(None),
                _ => Err(format!(
                    "-o {}: --tile and --crop write a part of the image, to be merged by \
                     `whitted merge`; name the output NAME.wpart",
                    output.display()
                )),
            };
        }
        let names = Aov::ALL.map(|a| a.name()).join(", ");
        let aovs = aov_specs
            .iter()
            .map(|spec| match Aov::from_name(spec) {
                Some(aov) => Ok(aov),
                None if spec.contains('=') => Err(format!(
                    "--aov {spec}: a part keeps its AOVs inside; give the name alone (--aov \
                     {}) here, and NAME=FILE to `whitted merge`",
                    spec.split('=').next().unwrap_or_default()
                )),
                None => Err(format!(
                    "--aov {spec}: unknown AOV `{spec}`; expected one of {names}"
                )),
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Some(Self { tile, crop, aovs }))
    }

    /// The pixels of a `width` × `height` image this part holds.
    pub fn selection(&self, width: u32, height: u32) -> Result<PixelSelection, String> {
        let selection = PixelSelection {
            window: self.crop.unwrap_or(Window::whole(width, height)),
            share: self.tile,
        };
        selection.check(width, height).map_err(|e| {
            let option = match (self.tile, self.crop) {
                (Some(Share { index, count }), None) => format!("--tile {index}/{count}"),
                (_, Some(Window { x0, y0, x1, y1 })) => format!("--crop {x0},{y0},{x1},{y1}"),
                (None, None) => "-o".to_string(),
            };
            format!("{option}: {e}")
        })?;
        Ok(selection)
    }

    /// Writes the part, whole or not at all: its header names the scene
    /// file (its SHA-256 read from `scene_file`, or the built-in scene).
    pub fn write(
        output_path: &Path,
        scene: &Scene,
        scene_file: Option<&Path>,
        selection: PixelSelection,
        output: &RenderOutput,
    ) -> Result<(), String> {
        let (name, sha256) = match scene_file {
            Some(path) => {
                let bytes = whitted::limits::read_input(path)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                (path.display().to_string(), scene_sha256(&bytes))
            }
            None => (BUILT_IN_SCENE.to_string(), BUILT_IN_SCENE.to_string()),
        };
        let header = PartHeader::new(scene, &name, &sha256, selection);
        encode_part(output_path, &header, output)
            .and_then(|pending| pending.commit())
            .map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_and_crops_are_read_and_bad_ones_say_why() {
        assert_eq!(tile("3/4"), Ok(Share { index: 3, count: 4 }));
        assert_eq!(
            crop("1,2,3,4"),
            Ok(Window {
                x0: 1,
                y0: 2,
                x1: 3,
                y1: 4
            })
        );
        for (got, says) in [
            (tile("4/4").map(drop), "4/4 names no worker"),
            (tile("0/0").map(drop), "0/0 names no worker"),
            (tile("-1/4").map(drop), "`-1` is not a whole number"),
            (tile("2").map(drop), "1 number(s) given, not 2"),
            (crop("0,0,0,4").map(drop), "0,0,0,4 is an empty window"),
            (crop("0,0,4").map(drop), "3 number(s) given, not 4"),
        ] {
            let error = got.unwrap_err();
            assert!(error.starts_with(says), "{error}");
        }
    }

    #[test]
    fn parts_need_a_wpart_output_and_name_their_aovs_alone() {
        let share = Some(Share { index: 0, count: 2 });
        assert!(
            PartRender::from_args(Path::new("a.png"), share, None, &[])
                .unwrap_err()
                .contains("name the output NAME.wpart")
        );
        assert!(
            PartRender::from_args(Path::new("a.png"), None, None, &[])
                .unwrap()
                .is_none()
        );
        let part = PartRender::from_args(Path::new("a.wpart"), None, None, &["depth".into()])
            .unwrap()
            .unwrap();
        assert_eq!(part.aovs, [Aov::Depth]);
        assert!(part.selection(4, 3).unwrap().is_whole(4, 3));
        let error = PartRender::from_args(Path::new("a.wpart"), share, None, &["id=i.pfm".into()])
            .unwrap_err();
        assert!(error.contains("give the name alone (--aov id)"), "{error}");
        let tall = PartRender::from_args(
            Path::new("a.wpart"),
            Some(Share { index: 0, count: 9 }),
            None,
            &[],
        )
        .unwrap()
        .unwrap();
        let error = tall.selection(4, 3).unwrap_err();
        assert!(
            error.starts_with("--tile 0/9: tile 0/9 does not fit"),
            "{error}"
        );
    }
}
