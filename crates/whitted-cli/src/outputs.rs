//! Writing a render's films: the image and each AOV to its file, all
//! encoded first and renamed into place only when every one is ready, so
//! a failure leaves every destination as it was.

use std::path::{Path, PathBuf};

use whitted::image::{Film, ImageFormat, heat_map};
use whitted::render::Aov;

/// Writes `image` to `output` and each AOV film to its file (the cost AOV
/// as a heat map when its file is a .png).
pub fn write_films(
    image: &Film,
    output: &Path,
    aovs: &[(Aov, &Film, &PathBuf)],
) -> Result<(), String> {
    let mut pending = vec![image.encode(output)];
    for (aov, film, path) in aovs {
        pending.push(match ImageFormat::from_path(path) {
            Ok(ImageFormat::Png) if *aov == Aov::Cost => heat_map(film).encode(path),
            _ => film.encode(path),
        });
    }
    let pending = pending
        .into_iter()
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    for file in pending {
        file.commit().map_err(|e| e.to_string())?;
    }
    Ok(())
}
