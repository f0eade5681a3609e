//! Where the samples of a pixel go: correlated multi-jittered sampling
//! (Kensler, "Correlated Multi-Jittered Sampling", Pixar technical memo
//! 13-01, 2013). Any number of samples is stratified in both dimensions, the
//! pattern is chosen by a seed, and one sample is exactly the pixel centre.

use crate::math::DVec2;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
