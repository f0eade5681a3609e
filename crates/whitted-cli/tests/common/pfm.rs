//! Reading the PFM files `whitted` writes, for the tests that compare
//! pictures pixel by pixel (shared by the test binaries that include it).

/// The pixels of a PFM file (little-endian, colour), top row first, and
/// its width.
pub(crate) fn read_pfm(bytes: &[u8]) -> (usize, Vec<[f32; 3]>) {
    let mut lines = 0;
    let mut start = 0;
    while lines < 3 {
        if bytes[start] == b'\n' {
            lines += 1;
        }
        start += 1;
    }
    let header = String::from_utf8_lossy(&bytes[..start]).into_owned();
    let size: Vec<usize> = header
        .lines()
        .nth(1)
        .unwrap()
        .split_whitespace()
        .map(|n| n.parse().unwrap())
        .collect();
    let (width, height) = (size[0], size[1]);
    let floats: Vec<f32> = bytes[start..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let mut pixels = vec![[0.0; 3]; width * height];
    for (i, rgb) in floats.chunks_exact(3).enumerate() {
        let (x, row_from_bottom) = (i % width, i / width);
        pixels[(height - 1 - row_from_bottom) * width + x] = [rgb[0], rgb[1], rgb[2]];
    }
    (width, pixels)
}
