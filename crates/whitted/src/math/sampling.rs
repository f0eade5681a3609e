//! Turning numbers in `[0, 1)` into samples.
//!
//! - Where the samples of a pixel go: correlated multi-jittered sampling
//!   (Kensler, "Correlated Multi-Jittered Sampling", Pixar technical memo
//!   13-01, 2013). Any number of samples is stratified in both dimensions,
//!   the pattern is chosen by a seed, and one sample is exactly the pixel
//!   centre.
//! - Directions and points for scattering rays and emitting photons: the
//!   uniform sphere, the cosine-weighted hemisphere (a Lambertian surface),
//!   a cone weighted by a power of the cosine (a Warn spot light), and the
//!   uniform disk. Each takes its numbers as an array, so the caller decides
//!   where they come from (a seeded [`crate::math::random::Rng`], a
//!   stratified pattern), and each says its density.

use std::f64::consts::{FRAC_1_PI, TAU};

use crate::math::{DVec2, Vec3};

/// A pseudo-random permutation of `0..len` indexed by `i`, chosen by
/// `pattern` (Kensler's hash with cycle walking).
fn permute(mut i: u32, len: u32, pattern: u32) -> u32 {
    let mut mask = len.wrapping_sub(1);
    mask |= mask >> 1;
    mask |= mask >> 2;
    mask |= mask >> 4;
    mask |= mask >> 8;
    mask |= mask >> 16;
    loop {
        i ^= pattern;
        i = i.wrapping_mul(0xe170_893d);
        i ^= pattern >> 16;
        i ^= (i & mask) >> 4;
        i ^= pattern >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= pattern >> 23;
        i ^= (i & mask) >> 1;
        i = i.wrapping_mul(1 | pattern >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & mask) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & mask) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & mask) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= mask;
        i ^= i >> 5;
        if i < len {
            break;
        }
    }
    (i.wrapping_add(pattern)) % len
}

/// A hashed number in `[0, 1)` from `i` and `pattern`.
fn hashed_unit(mut i: u32, pattern: u32) -> f64 {
    i ^= pattern;
    i ^= i >> 17;
    i ^= i >> 10;
    i = i.wrapping_mul(0xb365_34e5);
    i ^= i >> 12;
    i ^= i >> 21;
    i = i.wrapping_mul(0x93fc_4795);
    i ^= 0xdf6e_307f;
    i ^= i >> 17;
    i = i.wrapping_mul(1 | pattern >> 18);
    f64::from(i) / 4_294_967_296.0
}

/// Sample `index` of `count` inside the unit pixel square, for the pattern
/// `pattern`. With `count == 1` it is the centre `(0.5, 0.5)`.
///
/// Kensler's final form: the samples sit on an `m × n` grid (`m = ⌊√N⌋`
/// columns, `n = ⌈N / m⌉` rows) jittered within it; y is stratified into `N`
/// strata exactly and x into `m` columns with counts differing by at most
/// one, for any `N`; for square `N` x falls into `N` strata too.
pub fn pixel_sample(index: u32, count: u32, pattern: u32) -> DVec2 {
    if count <= 1 {
        return DVec2::splat(0.5);
    }
    let columns = (f64::from(count).sqrt() as u32).max(1);
    let rows = count.div_ceil(columns);
    let s = permute(index, count, pattern.wrapping_mul(0x5163_3e2d));
    let sx = permute(s % columns, columns, pattern.wrapping_mul(0x68bc_21eb));
    let sy = permute(s / columns, rows, pattern.wrapping_mul(0x02e5_be93));
    let jx = hashed_unit(s, pattern.wrapping_mul(0x967a_889b));
    let jy = hashed_unit(s, pattern.wrapping_mul(0x368c_c8b7));
    DVec2::new(
        (f64::from(sx) + (f64::from(sy) + jx) / f64::from(rows)) / f64::from(columns),
        (f64::from(s) + jy) / f64::from(count),
    )
}

/// A uniform point on the unit disk (polar mapping, `r = √u₀`): the
/// origin of a parallel ray from a disk of light. Density `1 / π`.
pub fn uniform_disk(u: [f64; 2]) -> DVec2 {
    let r = u[0].sqrt();
    let phi = TAU * u[1];
    DVec2::new(r * phi.cos(), r * phi.sin())
}

/// A uniformly distributed unit vector: the direction of a photon leaving
/// a point light. Density `1 / 4π` per steradian.
pub fn uniform_sphere(u: [f64; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A unit vector in the hemisphere around +z with density
/// [`cosine_hemisphere_pdf`] `= cos θ / π` (Malley's method: a uniform
/// point on the disk lifted onto the hemisphere). Sampling a Lambertian
/// surface this way makes the weight of a scattered ray its albedo. Place
/// it around a normal with [`about_axis`].
pub fn cosine_hemisphere(u: [f64; 2]) -> Vec3 {
    let d = uniform_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// The density per steradian of [`cosine_hemisphere`] for a direction at
/// `cos_theta` from the axis: `cos θ / π`, and zero below the horizon.
pub fn cosine_hemisphere_pdf(cos_theta: f64) -> f64 {
    if cos_theta > 0.0 {
        cos_theta * FRAC_1_PI
    } else {
        0.0
    }
}

/// A unit vector around +z inside the cone `cos θ ≥ cos_max`, with density
/// proportional to `cos^exponent θ` (the intensity of a Warn spot light):
/// `cos^exponent θ / power_cosine_cone_integral(cos_max, exponent)`.
///
/// Needs `exponent ≥ 0`, and `cos_max ≥ 0` unless `exponent` is 0 (a
/// power of a negative cosine is not defined); `cos_max` 1 gives the axis.
pub fn power_cosine_cone(u: [f64; 2], cos_max: f64, exponent: f64) -> Vec3 {
    let k = exponent + 1.0;
    let low = cos_max.powf(k);
    // The inverse of the cumulative distribution of cos θ on [cos_max, 1],
    // (c^k - low) / (1 - low).
    let cos = (low + u[0] * (1.0 - low)).powf(1.0 / k).clamp(-1.0, 1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = TAU * u[1];
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

/// The integral of `cos^exponent θ` over the solid angle of the cone
/// `cos θ ≥ cos_max`: `2π (1 - cos_max^(exponent+1)) / (exponent + 1)`.
/// Times a spot light's axial intensity, it is the light's flux. Same
/// domain as [`power_cosine_cone`].
pub fn power_cosine_cone_integral(cos_max: f64, exponent: f64) -> f64 {
    let k = exponent + 1.0;
    TAU * (1.0 - cos_max.powf(k)) / k
}

/// `local`, given in a frame whose +z is `axis` (unit), turned into world
/// coordinates; the frame's x and y are an arbitrary orthonormal pair
/// around the axis (fine for samples that are symmetric about it).
pub fn about_axis(local: Vec3, axis: Vec3) -> Vec3 {
    let (x, y) = axis.any_orthonormal_pair();
    local.x * x + local.y * y + local.z * axis
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    fn uniform_pair(rng: &mut Rng) -> [f64; 2] {
        [rng.uniform(), rng.uniform()]
    }

    #[test]
    fn permute_is_a_permutation() {
        for len in [1, 2, 3, 7, 16, 100] {
            for pattern in [0, 1, 12345, 0xdead_beef] {
                let mut seen: Vec<u32> = (0..len).map(|i| permute(i, len, pattern)).collect();
                seen.sort_unstable();
                assert_eq!(seen, (0..len).collect::<Vec<_>>());
            }
        }
    }

    #[test]
    fn one_sample_is_the_pixel_centre() {
        assert_eq!(pixel_sample(0, 1, 99), DVec2::splat(0.5));
    }

    #[test]
    fn samples_are_stratified_in_rows_columns_and_fine_strata() {
        for count in [4u32, 9, 16, 64] {
            for pattern in [1u32, 77, 4242] {
                let n = (count as f64).sqrt() as usize;
                let mut columns = vec![0; n];
                let mut rows = vec![0; n];
                let mut fine_x = vec![0; count as usize];
                let mut fine_y = vec![0; count as usize];
                for i in 0..count {
                    let s = pixel_sample(i, count, pattern);
                    assert!((0.0..1.0).contains(&s.x) && (0.0..1.0).contains(&s.y));
                    columns[(s.x * n as f64) as usize] += 1;
                    rows[(s.y * n as f64) as usize] += 1;
                    fine_x[(s.x * count as f64) as usize] += 1;
                    fine_y[(s.y * count as f64) as usize] += 1;
                }
                assert!(columns.iter().chain(&rows).all(|&c| c == n));
                assert!(fine_x.iter().chain(&fine_y).all(|&c| c == 1));
            }
        }
    }

    #[test]
    fn any_count_is_stratified_and_unbiased() {
        for count in [2u32, 3, 5, 7, 8, 10, 12, 15] {
            let columns = (count as f64).sqrt() as usize;
            let mut mean = DVec2::ZERO;
            let patterns = 2000u32;
            for pattern in 0..patterns {
                let mut fine_y = vec![0; count as usize];
                let mut column_counts = vec![0; columns];
                for i in 0..count {
                    let s = pixel_sample(i, count, pattern.wrapping_mul(2_654_435_761));
                    assert!((0.0..1.0).contains(&s.x) && (0.0..1.0).contains(&s.y));
                    fine_y[(s.y * count as f64) as usize] += 1;
                    column_counts[(s.x * columns as f64) as usize] += 1;
                    mean += s;
                }
                assert!(fine_y.iter().all(|&c| c == 1), "count {count}");
                let (lo, hi) = (
                    column_counts.iter().min().unwrap(),
                    column_counts.iter().max().unwrap(),
                );
                assert!(hi - lo <= 1, "count {count}: columns {column_counts:?}");
            }
            mean /= f64::from(count * patterns);
            assert!(
                (mean - DVec2::splat(0.5)).abs().max_element() < 0.01,
                "count {count}: mean {mean:?}"
            );
        }
    }

    #[test]
    fn patterns_differ() {
        assert_ne!(pixel_sample(0, 16, 1), pixel_sample(0, 16, 2));
    }

    #[test]
    fn disk_points_are_inside_and_uniform_by_area() {
        let mut rng = Rng::new(11);
        let n = 100_000;
        let mut inner = 0;
        let mut mean = DVec2::ZERO;
        for _ in 0..n {
            let p = uniform_disk(uniform_pair(&mut rng));
            assert!(p.length() <= 1.0);
            inner += usize::from(p.length() < 0.5);
            mean += p;
        }
        // The disk of radius 1/2 holds a quarter of the area.
        let fraction = inner as f64 / n as f64;
        assert!((fraction - 0.25).abs() < 0.01, "{fraction}");
        assert!((mean / n as f64).length() < 0.01);
    }

    #[test]
    fn sphere_directions_are_unit_and_uniform() {
        let mut rng = Rng::new(12);
        let n = 100_000;
        let (mut mean, mut z2, mut upper) = (Vec3::ZERO, 0.0, 0);
        for _ in 0..n {
            let d = uniform_sphere(uniform_pair(&mut rng));
            assert!((d.length() - 1.0).abs() < 1e-12);
            mean += d;
            z2 += d.z * d.z;
            upper += usize::from(d.z > 0.5);
        }
        let n = n as f64;
        assert!((mean / n).length() < 0.01);
        // Uniform on the sphere: E[z²] = 1/3, and z is uniform on [-1, 1].
        assert!((z2 / n - 1.0 / 3.0).abs() < 0.01);
        assert!((upper as f64 / n - 0.25).abs() < 0.01);
    }

    #[test]
    fn cosine_hemisphere_has_the_lambertian_moments() {
        let mut rng = Rng::new(13);
        let n = 100_000;
        let (mut cos, mut cos2, mut xy) = (0.0, 0.0, DVec2::ZERO);
        for _ in 0..n {
            let d = cosine_hemisphere(uniform_pair(&mut rng));
            assert!((d.length() - 1.0).abs() < 1e-12 && d.z >= 0.0);
            cos += d.z;
            cos2 += d.z * d.z;
            xy += DVec2::new(d.x, d.y);
        }
        let n = n as f64;
        // With density cos θ / π: E[cos θ] = 2/3 and E[cos² θ] = 1/2.
        assert!((cos / n - 2.0 / 3.0).abs() < 0.005, "{}", cos / n);
        assert!((cos2 / n - 0.5).abs() < 0.005, "{}", cos2 / n);
        assert!((xy / n).length() < 0.01);
        assert_eq!(cosine_hemisphere_pdf(-0.1), 0.0);
        assert!((cosine_hemisphere_pdf(1.0) - 1.0 / std::f64::consts::PI).abs() < 1e-15);
    }

    #[test]
    fn power_cosine_cone_stays_in_its_cone_with_the_right_distribution() {
        let mut rng = Rng::new(14);
        for (cos_max, exponent) in [(0.5, 0.0), (0.0, 1.0), (0.8, 5.0), (0.3, 20.0)] {
            let n = 100_000;
            // Check the fraction inside the narrower cone cos θ ≥ c.
            let c = (1.0 + cos_max) / 2.0;
            let mut inside = 0;
            for _ in 0..n {
                let d = power_cosine_cone(uniform_pair(&mut rng), cos_max, exponent);
                assert!((d.length() - 1.0).abs() < 1e-12);
                assert!(d.z >= cos_max - 1e-12, "{d:?} outside cos {cos_max}");
                inside += usize::from(d.z >= c);
            }
            let expected = power_cosine_cone_integral(c, exponent)
                / power_cosine_cone_integral(cos_max, exponent);
            let fraction = inside as f64 / n as f64;
            assert!(
                (fraction - expected).abs() < 0.01,
                "cos_max {cos_max}, exponent {exponent}: {fraction} vs {expected}"
            );
        }
        assert_eq!(power_cosine_cone([0.3, 0.7], 1.0, 3.0), Vec3::Z);
    }

    #[test]
    fn power_cosine_cone_integral_matches_quadrature() {
        for (cos_max, exponent) in [(0.0, 0.0), (-1.0, 0.0), (0.5, 2.0), (0.9, 7.5)] {
            // Midpoint rule over cos θ: ∫ cos^e dω = 2π ∫ μ^e dμ.
            let steps = 100_000;
            let h = (1.0 - cos_max) / steps as f64;
            let sum: f64 = (0..steps)
                .map(|i| (cos_max + (i as f64 + 0.5) * h).powf(exponent) * h)
                .sum();
            let exact = power_cosine_cone_integral(cos_max, exponent);
            assert!(
                (TAU * sum - exact).abs() < 1e-6 * exact,
                "{cos_max} {exponent}"
            );
        }
        let hemisphere = power_cosine_cone_integral(0.0, 0.0);
        assert!((hemisphere - TAU).abs() < 1e-12);
    }

    #[test]
    fn about_axis_puts_z_on_the_axis_and_keeps_lengths_and_angles() {
        let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
        assert!((about_axis(Vec3::Z, axis) - axis).length() < 1e-12);
        let local = Vec3::new(0.6, 0.0, 0.8);
        let world = about_axis(local, axis);
        assert!((world.length() - 1.0).abs() < 1e-12);
        assert!((world.dot(axis) - 0.8).abs() < 1e-12);
    }
}
