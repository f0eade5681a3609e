//! Ray files written by the Embree anchor harness (`bench --dump DIR` in
//! `shared/peers/embree`), so that whitted traces bit-identical rays and
//! checks each result against Embree's.
//!
//! Little-endian, no headers, in pixel order:
//! - `{primary,diffuse,shadow}.rays`: 32-byte records: `u32` pixel,
//!   `f32` origin\[3\], `f32` direction\[3\], `f32` t_far (t_near is 0);
//! - `{primary,diffuse}.hits`: 8-byte records: `f32` t (-1 for a miss),
//!   `u32` triangle index;
//! - `shadow.hits`: one byte per ray, 1 when occluded.

use std::path::{Path, PathBuf};

use super::{RayKind, RaySet, TraceResults, ray_set_bytes};
use crate::limits::{MemoryBudget, MemoryError};
use crate::math::{Ray, Vec3, magnitude};

/// Size of one ray record.
const RAY_RECORD: usize = 32;
/// Size of one closest-hit record.
const HIT_RECORD: usize = 8;

/// Relative tolerance on `t` for a result to agree with the reference.
pub const T_TOLERANCE: f64 = 1e-4;

/// Why ray files could not be read.
#[derive(Debug, thiserror::Error)]
pub enum RayFileError {
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// A file holds more rays than the memory budget allows.
    #[error("{}: {source}", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The request and the budget.
        source: MemoryError,
    },
    /// A file's size or contents do not fit the format.
    #[error("{}: {why}", path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
}

/// One kind's rays and the reference results for them.
#[derive(Clone, Debug, PartialEq)]
pub struct RayFile {
    /// The rays.
    pub set: RaySet,
    /// What the reference renderer found for each ray.
    pub reference: TraceResults,
}

fn read(path: &Path) -> Result<Vec<u8>, RayFileError> {
    crate::limits::read_input(path).map_err(|source| RayFileError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// Why a ray cannot be traced, if it cannot: a value that is not a finite
/// number, an origin beyond ±[`magnitude::MAX_COORDINATE`], a direction of
/// zero length (or too short to square), a `t_far` that is not positive
/// (it may be infinite).
fn check_ray(origin: Vec3, dir: Vec3, t_far: f64) -> Result<(), String> {
    if !(origin.is_finite() && dir.is_finite()) || t_far.is_nan() {
        return Err(format!(
            "a value is not a finite number (origin {origin}, direction {dir}, t_far {t_far})"
        ));
    }
    magnitude::point(origin).map_err(|error| format!("the origin is out of range: {error}"))?;
    let length = magnitude::norm(dir);
    if length == 0.0 {
        return Err("the direction has zero length".into());
    }
    magnitude::length(length)
        .map_err(|error| format!("the direction's length is out of range: {error}"))?;
    if t_far <= 0.0 {
        return Err(format!("t_far must be positive, got {t_far}"));
    }
    Ok(())
}

/// Reads the rays and reference results of `kind` from `dir`; a ray that
/// [`check_ray`] refuses is an error naming the file, the ray's index and
/// why.
pub fn read_ray_file(dir: &Path, kind: RayKind) -> Result<RayFile, RayFileError> {
    let rays_path = dir.join(format!("{}.rays", kind.name()));
    let hits_path = dir.join(format!("{}.hits", kind.name()));
    let bytes = read(&rays_path)?;
    if bytes.len() % RAY_RECORD != 0 {
        return Err(RayFileError::Malformed {
            path: rays_path,
            why: format!(
                "{} bytes is not a whole number of {RAY_RECORD}-byte ray records",
                bytes.len()
            ),
        });
    }
    let count = (bytes.len() / RAY_RECORD) as u64;
    MemoryBudget::current()
        .check(
            &format!("tracing its {count} rays"),
            ray_set_bytes(count),
            "use fewer rays",
        )
        .map_err(|source| RayFileError::TooLarge {
            path: rays_path.clone(),
            source,
        })?;
    let rays: Vec<Ray> = bytes
        .chunks_exact(RAY_RECORD)
        .enumerate()
        .map(|(index, r)| {
            let v = |at| {
                Vec3::new(
                    f32_at(r, at).into(),
                    f32_at(r, at + 4).into(),
                    f32_at(r, at + 8).into(),
                )
            };
            let (origin, dir, t_far) = (v(4), v(16), f32_at(r, 28).into());
            check_ray(origin, dir, t_far).map_err(|why| RayFileError::Malformed {
                path: rays_path.clone(),
                why: format!("ray {index}: {why}"),
            })?;
            Ok(Ray::segment(origin, dir, t_far))
        })
        .collect::<Result<_, _>>()?;
    let hits = read(&hits_path)?;
    let record = if kind.is_any_hit() { 1 } else { HIT_RECORD };
    if hits.len() != rays.len() * record {
        return Err(RayFileError::Malformed {
            path: hits_path,
            why: format!(
                "{} bytes for {} rays; expected {}",
                hits.len(),
                rays.len(),
                rays.len() * record
            ),
        });
    }
    let reference = if kind.is_any_hit() {
        TraceResults::Occluded(hits.iter().map(|&b| b != 0).collect())
    } else {
        TraceResults::Closest(
            hits.chunks_exact(HIT_RECORD)
                .map(|h| {
                    let t = f32_at(h, 0);
                    (t >= 0.0).then(|| (f64::from(t), u32_at(h, 4)))
                })
                .collect(),
        )
    };
    Ok(RayFile {
        set: RaySet { kind, rays },
        reference,
    })
}

/// How many results agree with the reference: the same hit or miss (or
/// occlusion), and for hits a `t` within [`T_TOLERANCE`] relative. Returns
/// `(agreeing, total)`.
pub fn agreement(ours: &TraceResults, reference: &TraceResults) -> (usize, usize) {
    match (ours, reference) {
        (TraceResults::Occluded(a), TraceResults::Occluded(b)) => {
            (a.iter().zip(b).filter(|(x, y)| x == y).count(), b.len())
        }
        (TraceResults::Closest(a), TraceResults::Closest(b)) => {
            let agree = a
                .iter()
                .zip(b)
                .filter(|(x, y)| match (x, y) {
                    (None, None) => true,
                    (Some((ta, _)), Some((tb, _))) => (ta - tb).abs() <= T_TOLERANCE * tb.abs(),
                    _ => false,
                })
                .count();
            (agree, b.len())
        }
        (_, b) => (0, b.len()),
    }
}

impl TraceResults {
    /// How many results there are.
    pub fn len(&self) -> usize {
        match self {
            TraceResults::Closest(v) => v.len(),
            TraceResults::Occluded(v) => v.len(),
        }
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray_record(o: [f32; 3], d: [f32; 3], t_far: f32) -> Vec<u8> {
        let mut r = 7u32.to_le_bytes().to_vec();
        for v in o.iter().chain(&d).chain(&[t_far]) {
            r.extend_from_slice(&v.to_le_bytes());
        }
        r
    }

    #[test]
    fn rays_and_hits_are_read_from_the_dump_format() {
        let dir = tempfile::tempdir().unwrap();
        let mut rays = ray_record([0.0, 1.0, 2.0], [0.0, 0.0, -1.0], f32::INFINITY);
        rays.extend(ray_record([1.0, 1.0, 1.0], [1.0, 0.0, 0.0], 5.0));
        std::fs::write(dir.path().join("primary.rays"), &rays).unwrap();
        let mut hits = 2.5f32.to_le_bytes().to_vec();
        hits.extend(9u32.to_le_bytes());
        hits.extend((-1.0f32).to_le_bytes());
        hits.extend(0u32.to_le_bytes());
        std::fs::write(dir.path().join("primary.hits"), &hits).unwrap();
        let file = read_ray_file(dir.path(), RayKind::Primary).unwrap();
        assert_eq!(file.set.rays.len(), 2);
        assert_eq!(file.set.rays[0].origin, Vec3::new(0.0, 1.0, 2.0));
        assert_eq!(file.set.rays[1].t_max, 5.0);
        assert_eq!(
            file.reference,
            TraceResults::Closest(vec![Some((2.5, 9)), None])
        );

        std::fs::write(dir.path().join("shadow.rays"), &rays).unwrap();
        std::fs::write(dir.path().join("shadow.hits"), [1u8, 0]).unwrap();
        let file = read_ray_file(dir.path(), RayKind::Shadow).unwrap();
        assert_eq!(file.reference, TraceResults::Occluded(vec![true, false]));
    }

    #[test]
    fn truncated_or_missing_files_are_reported_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_ray_file(dir.path(), RayKind::Diffuse).unwrap_err();
        assert!(err.to_string().contains("diffuse.rays"));
        std::fs::write(dir.path().join("diffuse.rays"), [0u8; 33]).unwrap();
        let err = read_ray_file(dir.path(), RayKind::Diffuse).unwrap_err();
        assert!(err.to_string().contains("not a whole number"));
        let ray = ray_record([0.0; 3], [0.0, 0.0, 1.0], 1.0);
        std::fs::write(dir.path().join("diffuse.rays"), ray).unwrap();
        std::fs::write(dir.path().join("diffuse.hits"), [0u8; 4]).unwrap();
        let err = read_ray_file(dir.path(), RayKind::Diffuse).unwrap_err();
        assert!(err.to_string().contains("expected 8"));
    }

    #[test]
    fn rays_that_cannot_be_traced_are_refused_with_their_index_and_why() {
        let dir = tempfile::tempdir().unwrap();
        let good = ray_record([0.0; 3], [0.0, 0.0, 1.0], f32::INFINITY);
        for (bad, why) in [
            (
                ray_record([0.0; 3], [0.0; 3], 1.0),
                "ray 1: the direction has zero length",
            ),
            (
                ray_record([f32::NAN, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0),
                "ray 1: a value is not a finite number",
            ),
            (
                ray_record([3e38; 3], [0.0, 0.0, 1.0], 1.0),
                "ray 1: the origin is out of range: 3",
            ),
            (
                ray_record([0.0; 3], [0.0, 0.0, 1.0], 0.0),
                "ray 1: t_far must be positive, got 0",
            ),
        ] {
            let rays = [good.clone(), bad].concat();
            std::fs::write(dir.path().join("primary.rays"), rays).unwrap();
            let err = read_ray_file(dir.path(), RayKind::Primary).unwrap_err();
            let message = err.to_string();
            assert!(message.contains("primary.rays: "), "{message}");
            assert!(message.contains(why), "{message}");
        }
    }

    #[test]
    fn agreement_allows_small_relative_differences_in_t_only() {
        let reference = TraceResults::Closest(vec![Some((100.0, 1)), None, Some((1.0, 2)), None]);
        let ours = TraceResults::Closest(vec![
            Some((100.005, 3)),
            None,
            Some((1.001, 2)),
            Some((4.0, 1)),
        ]);
        assert_eq!(agreement(&ours, &reference), (2, 4));
    }
}
