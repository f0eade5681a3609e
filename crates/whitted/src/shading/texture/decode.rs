//! Reading PNG and JPEG files into linear RGB texels, each file once.
//!
//! PNG is decoded by the `png` crate, JPEG by `zune-jpeg`. How samples
//! become texels is the [`Decoding`] the file is read with: colours are
//! taken as sRGB-encoded (the PNG default and what JPEG cameras and editors
//! write), every 8- or 16-bit sample going through the sRGB transfer curve
//! to linear light; data (normal and height maps) is read as stored, scaled
//! to [0, 1]; opacity is the alpha channel. A file read two ways is decoded
//! once per way.
//!
//! Before anything is decoded, the size the header declares is checked: a
//! PNG claiming more data than its compressed bytes can hold, or any image
//! whose texels would exceed the memory budget
//! ([`MemoryBudget::current`]), is refused with the reason.

use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::image::{ImageData, LARGE_TEXTURE_BYTES, Texels};
use crate::limits::{Charge, MemoryBudget, MemoryError};

/// Why an image file gave no texture.
#[derive(Debug, thiserror::Error)]
pub enum ImageLoadError {
    /// The file could not be read.
    #[error("cannot read the image `{}`: {source}", path.display())]
    Io {
        /// The file as named.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// The file is not a PNG or JPEG image we can decode.
    #[error("cannot decode the image `{}`: {reason}", path.display())]
    Decode {
        /// The file as named.
        path: PathBuf,
        /// What the decoder said.
        reason: String,
    },
}

/// How an image's samples become texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Decoding {
    /// A colour: sRGB-encoded samples converted to linear RGB; alpha is
    /// ignored.
    #[default]
    Color,
    /// Data, such as a normal or height map: the samples as stored, scaled
    /// to [0, 1], with no transfer curve; alpha is ignored.
    Data,
    /// Opacity: the alpha channel, as stored, in all three components; an
    /// image without alpha is read as [`Decoding::Data`].
    Opacity,
}

/// Decoded images by canonical path and decoding, so that every material
/// naming a file shares one copy of its texels.
#[derive(Debug)]
pub struct ImageCache {
    images: HashMap<(PathBuf, Decoding), Arc<ImageData>>,
    /// Textures taking more bytes are noted when first decoded.
    note_above: u64,
}

impl Default for ImageCache {
    /// A cache that notes textures over [`LARGE_TEXTURE_BYTES`].
    fn default() -> Self {
        Self {
            images: HashMap::new(),
            note_above: LARGE_TEXTURE_BYTES,
        }
    }
}

impl ImageCache {
    /// A cache that notes textures over `bytes`, for tests of the note.
    #[cfg(test)]
    pub(crate) fn noting_above(bytes: u64) -> Self {
        Self {
            note_above: bytes,
            ..Self::default()
        }
    }

    /// [`ImageCache::load`], with a note when this call decoded the file
    /// into a texture of more than 1 GiB ([`LARGE_TEXTURE_BYTES`]), which
    /// calls `name` as the scene names it.
    pub fn load_noting(
        &mut self,
        path: &Path,
        name: &str,
        decoding: Decoding,
    ) -> Result<(Arc<ImageData>, Option<String>), ImageLoadError> {
        let decoded = self.images.len();
        let image = self.load(path, decoding)?;
        let note = if self.images.len() > decoded {
            image.large_texture_note(name, self.note_above)
        } else {
            None
        };
        Ok((image, note))
    }

    /// The texels of the file at `path` read as `decoding`, decoded on
    /// first use.
    pub fn load(
        &mut self,
        path: &Path,
        decoding: Decoding,
    ) -> Result<Arc<ImageData>, ImageLoadError> {
        let io = |source| ImageLoadError::Io {
            path: path.to_path_buf(),
            source,
        };
        let key = (path.canonicalize().map_err(io)?, decoding);
        if let Some(image) = self.images.get(&key) {
            return Ok(Arc::clone(image));
        }
        let bytes = crate::limits::read_input(&key.0).map_err(io)?;
        let image =
            Arc::new(
                decode_image(&bytes, decoding).map_err(|reason| ImageLoadError::Decode {
                    path: path.to_path_buf(),
                    reason,
                })?,
            );
        self.images.insert(key, Arc::clone(&image));
        Ok(image)
    }

    /// How many distinct files (and decodings of one file) were decoded.
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// True when no file was decoded.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }
}

/// Decodes a PNG or JPEG file's bytes, told apart by their signature.
pub fn decode_image(bytes: &[u8], decoding: Decoding) -> Result<ImageData, String> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        decode_png(bytes, decoding)
    } else if bytes.starts_with(&[0xff, 0xd8]) {
        decode_jpeg(bytes, decoding)
    } else {
        Err("not a PNG or JPEG file".to_string())
    }
}

/// The texel value of a sample `encoded` in [0, 1].
fn texel_value(encoded: f32, decoding: Decoding) -> f32 {
    match decoding {
        Decoding::Color => srgb_to_linear(encoded),
        Decoding::Data | Decoding::Opacity => encoded,
    }
}

/// [`texel_value`] of every 8-bit sample.
fn eight_bit_table(decoding: Decoding) -> [f32; 256] {
    std::array::from_fn(|i| texel_value(i as f32 / 255.0, decoding))
}

fn decode_png(bytes: &[u8], decoding: Decoding) -> Result<ImageData, String> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    let info = reader.info();
    let (width, height) = (info.width, info.height);
    let raw = info.raw_bytes() as u64 + u64::from(height);
    if raw > MAX_DEFLATE_RATIO * bytes.len() as u64 {
        return Err(claims_too_much(width, height, bytes.len()));
    }
    let size = reader
        .output_buffer_size()
        .ok_or("the image is too large")?;
    let sample_bytes = if info.bit_depth == png::BitDepth::Sixteen {
        2
    } else {
        1
    };
    let (charge, decoding_charge) =
        charge_texel_memory(width, height, size as u64, 3 * sample_bytes)?;
    let mut buffer = reserved::<u8>(size, "the decoder's buffer")?;
    buffer.resize(size, 0);
    let info = reader.next_frame(&mut buffer).map_err(|e| e.to_string())?;
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => return Err("unexpanded palette".to_string()),
    };
    let (width, height) = (width as usize, height as usize);
    let wide = info.bit_depth == png::BitDepth::Sixteen;
    let sample_bytes = if wide { 2 } else { 1 };
    let alpha = (decoding == Decoding::Opacity && channels % 2 == 0).then_some(channels - 1);
    // Each texel's three samples: the alpha channel's three times, grey's
    // three times, or red, green and blue.
    let samples = |pixel: &[u8], read: &dyn Fn(&[u8]) -> u16| -> [u16; 3] {
        let value = |channel: usize| read(&pixel[channel * sample_bytes..]);
        match alpha {
            Some(channel) => [value(channel); 3],
            None if channels < 3 => [value(0); 3],
            None => [value(0), value(1), value(2)],
        }
    };
    let pixels = || {
        buffer
            .chunks(info.line_size)
            .take(height)
            .flat_map(|row| row.chunks_exact(channels * sample_bytes).take(width))
    };
    let texels = if wide {
        let mut words = reserved(width * height, "its texels")?;
        words.extend(pixels().map(|p| samples(p, &|at| u16::from_be_bytes([at[0], at[1]]))));
        let table: Arc<[f32]> = (0..=u16::MAX)
            .map(|v| texel_value(f32::from(v) / 65535.0, decoding))
            .collect();
        Texels::Words(words, table)
    } else {
        let mut bytes = reserved(width * height, "its texels")?;
        bytes.extend(pixels().map(|p| samples(p, &|at| u16::from(at[0])).map(|v| v as u8)));
        Texels::Bytes(bytes, Arc::new(eight_bit_table(decoding)))
    };
    drop((buffer, decoding_charge));
    ImageData::stored(width, height, texels)
        .map(|data| data.holding(charge))
        .ok_or_else(|| "the image data is truncated".to_string())
}

/// An empty vector with room for `count` items, or the message for the
/// system's refusal of that memory (which the budget allowed: a budget
/// given above what the process may use), naming it as `what`, so that a
/// server reading a new scene stays up.
fn reserved<T>(count: usize, what: &str) -> Result<Vec<T>, String> {
    let mut items = Vec::new();
    items.try_reserve_exact(count).map_err(|_| {
        let bytes = (count as u64).saturating_mul(std::mem::size_of::<T>() as u64);
        format!(
            "the system refused {} for {what}; free memory, raise the process's \
             limit (ulimit -v), or use a smaller image",
            crate::limits::format_bytes(bytes)
        )
    })?;
    Ok(items)
}

/// The most bytes deflate (PNG's compression) can expand one byte into
/// (RFC 1951: a 258-byte match in as little as two bits, about 1032 to 1).
const MAX_DEFLATE_RATIO: u64 = 1032;

/// The message for a header claiming more pixels than the file can hold.
fn claims_too_much(width: u32, height: u32, file_bytes: usize) -> String {
    format!(
        "the header claims {width}x{height} pixels, far more than {file_bytes} bytes can hold: \
         the file is truncated or corrupt"
    )
}

/// Bytes of the mipmap's levels per texel of the image: a third of a
/// linear RGB texel (12 bytes), at most.
const MIPMAP_BYTES_PER_TEXEL: u64 = 4;

/// Charges the memory ledger for an image of `width` × `height` kept at
/// `texel_bytes` a texel (3 for 8-bit samples, 6 for 16-bit): what it keeps
/// with its mipmap ([`MIPMAP_BYTES_PER_TEXEL`] more), and apart, the
/// `decoded` bytes the decoder fills first, given back once the texels are
/// made. Refused when they do not fit beside what the run holds.
fn charge_texel_memory(
    width: u32,
    height: u32,
    decoded: u64,
    texel_bytes: u64,
) -> Result<(Charge, Charge), String> {
    let texels = u64::from(width) * u64::from(height);
    let budget = MemoryBudget::current();
    let what = format!("decoding its {width}x{height} texels");
    let kept = texels.saturating_mul(texel_bytes + MIPMAP_BYTES_PER_TEXEL);
    let refused = |e: MemoryError| e.to_string();
    budget
        .check(&what, kept.saturating_add(decoded), "use a smaller image")
        .map_err(refused)?;
    let kept = budget
        .charge(&what, kept, "use a smaller image")
        .map_err(refused)?;
    let decoding = budget
        .charge(&what, decoded, "use a smaller image")
        .map_err(refused)?;
    Ok((kept, decoding))
}

/// Pixels any JPEG may claim, whatever its length.
const FREE_PIXELS: u64 = 1 << 20;

/// Beyond [`FREE_PIXELS`], the most pixels a JPEG may claim per byte of
/// its entropy-coded data ([`entropy_coded_bytes`]: the compressed
/// pixels, not the comments, thumbnails or other segments that can pad a
/// file). zune-jpeg fills what a truncated file lacks, so without this a
/// file of a few hundred bytes is decoded into as many texels as its
/// header claims, taking the time and memory of a real image that size
/// (figures in docs/performance-log.md, figures moved out of doc
/// comments). Baseline JPEG needs at least two bits per 8×8 block and
/// channel (about 256 pixels per byte); only a progressive file of nearly
/// one flat colour could exceed this, and such a texture can be smaller.
const MAX_PIXELS_PER_BYTE: u64 = 4096;

fn decode_jpeg(bytes: &[u8], decoding: Decoding) -> Result<ImageData, String> {
    use zune_jpeg::zune_core::bytestream::ZCursor;
    use zune_jpeg::zune_core::colorspace::ColorSpace;
    use zune_jpeg::zune_core::options::DecoderOptions;
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::RGB);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    decoder.decode_headers().map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions().ok_or("no image size")?;
    let claimed = width as u64 * height as u64;
    let coded = entropy_coded_bytes(bytes);
    if claimed > FREE_PIXELS + MAX_PIXELS_PER_BYTE * coded {
        return Err(format!(
            "{} ({coded} of its bytes are compressed pixels)",
            claims_too_much(width as u32, height as u32, bytes.len())
        ));
    }
    let (charge, decoding_charge) =
        charge_texel_memory(width as u32, height as u32, claimed * 3, 3)?;
    let size = decoder
        .output_buffer_size()
        .ok_or("the image is too large")?;
    let mut pixels = reserved::<u8>(size, "the decoder's buffer")?;
    pixels.resize(size, 0);
    decoder
        .decode_into(&mut pixels)
        .map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions().ok_or("no image size")?;
    let mut texels = reserved(pixels.len() / 3, "its texels")?;
    texels.extend(pixels.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
    drop((pixels, decoding_charge));
    let texels = Texels::Bytes(texels, Arc::new(eight_bit_table(decoding)));
    ImageData::stored(width, height, texels)
        .map(|data| data.holding(charge))
        .ok_or_else(|| "the image data is truncated".to_string())
}

/// The bytes of a JPEG's entropy-coded data: what follows each start of
/// scan (`FFDA`) up to the next marker other than a restart (`FFD0` to
/// `FFD7`) or a stuffed byte (`FF00`), summed over the scans. Segments are
/// walked by their lengths; where the file is damaged the count stops
/// there (the decoder then says what is wrong).
fn entropy_coded_bytes(bytes: &[u8]) -> u64 {
    let mut coded = 0;
    let mut at = 2; // after SOI
    while at + 1 < bytes.len() {
        if bytes[at] != 0xff {
            break;
        }
        let marker = bytes[at + 1];
        match marker {
            // Fill bytes before a marker.
            0xff => {
                at += 1;
                continue;
            }
            // Markers without a length.
            0x01 | 0xd0..=0xd8 => {
                at += 2;
                continue;
            }
            0xd9 => break,
            _ => {}
        }
        let Some(length) = bytes.get(at + 2..at + 4) else {
            break;
        };
        let end = at + 2 + usize::from(u16::from_be_bytes([length[0], length[1]]));
        if marker != 0xda {
            at = end;
            continue;
        }
        // The scan's data, to the next marker that is not a restart.
        let mut i = end;
        while i + 1 < bytes.len()
            && (bytes[i] != 0xff || matches!(bytes[i + 1], 0x00 | 0xd0..=0xd7))
        {
            i += 1;
        }
        coded += i.saturating_sub(end) as u64;
        at = i;
    }
    coded
}

/// The sRGB transfer curve, from an encoded value in [0, 1] to linear light.
pub(crate) fn srgb_to_linear(encoded: f32) -> f32 {
    if encoded <= 0.04045 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An 8-bit RGB PNG of `width × height` texels, row by row from the top.
    pub(crate) fn png_bytes(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
        encode_png(width, height, png::ColorType::Rgb, rgb)
    }

    /// An 8-bit RGBA PNG of `width × height` texels, row by row from the top.
    pub(crate) fn rgba_png_bytes(width: u32, height: u32, rgba: &[u8]) -> Vec<u8> {
        encode_png(width, height, png::ColorType::Rgba, rgba)
    }

    fn encode_png(width: u32, height: u32, color: png::ColorType, samples: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(color);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(samples).unwrap();
        writer.finish().unwrap();
        out
    }

    #[test]
    fn a_png_header_claiming_more_than_its_data_can_hold_is_refused_before_decoding() {
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, 40000, 40000);
            encoder.set_color(png::ColorType::Rgb);
            let mut writer = encoder.write_header().unwrap();
            // A zlib stream of one stored empty block: far from 4.8 GB.
            let idat = [
                0x78, 0x01, 0x01, 0x00, 0x00, 0xff, 0xff, 0x00, 0x00, 0x00, 0x01,
            ];
            writer.write_chunk(png::chunk::IDAT, &idat).unwrap();
        }
        let error = decode_image(&bytes, Decoding::Color).unwrap_err();
        assert_eq!(
            error,
            format!(
                "the header claims 40000x40000 pixels, far more than {} bytes can hold: the \
                 file is truncated or corrupt",
                bytes.len()
            )
        );
    }

    #[test]
    fn eight_bit_samples_are_srgb_decoded() {
        let image = decode_image(
            &png_bytes(2, 1, &[0, 128, 255, 188, 188, 188]),
            Decoding::Color,
        )
        .unwrap();
        let t = |x| {
            super::super::ImageTexture::new(Arc::new(image.clone()))
                .at(crate::math::DVec2::new((f64::from(x) + 0.5) / 2.0, 0.5))
        };
        // sRGB 128 is 0.2158605 linear; 188 is 0.5028865.
        let left = t(0);
        assert_eq!(left.r, 0.0);
        assert!((left.g - 0.215_860_5).abs() < 1e-6, "{left}");
        assert!((left.b - 1.0).abs() < 1e-6);
        assert!(
            (t(1) - crate::shading::Color::splat(0.502_886_5))
                .abs()
                .max_element()
                < 1e-6
        );
    }

    #[test]
    fn jpeg_is_decoded_and_srgb_linearised() {
        // 16 x 8: the left half sRGB (200, 100, 50), the right half 128 grey.
        let bytes = include_bytes!("../../../tests/textures/two_blocks.jpg");
        let image = decode_image(bytes, Decoding::Color).unwrap();
        assert_eq!((image.width(), image.height()), (16, 8));
        let t = super::super::ImageTexture::new(Arc::new(image));
        let left = t.at(crate::math::DVec2::new(0.25, 0.5));
        let right = t.at(crate::math::DVec2::new(0.75, 0.5));
        // JPEG is lossy: allow about one 8-bit step.
        let expected = [200, 100, 50].map(|c| f64::from(srgb_to_linear(c as f32 / 255.0)));
        assert!(
            (left - crate::shading::Color::from(expected))
                .abs()
                .max_element()
                < 0.01,
            "{left}"
        );
        assert!(
            (right - crate::shading::Color::splat(0.215_860_5))
                .abs()
                .max_element()
                < 0.01
        );
    }

    #[test]
    fn a_short_jpeg_claiming_a_huge_size_is_refused_before_decoding() {
        let mut bytes = include_bytes!("../../../tests/textures/two_blocks.jpg").to_vec();
        let sof = bytes
            .windows(2)
            .position(|w| w == [0xff, 0xc0] || w == [0xff, 0xc2])
            .unwrap();
        // Marker, length, precision, then height and width.
        for at in [sof + 5, sof + 7] {
            bytes[at..at + 2].copy_from_slice(&16000u16.to_be_bytes());
        }
        let error = decode_image(&bytes, Decoding::Color).unwrap_err();
        assert_eq!(
            error,
            format!(
                "the header claims 16000x16000 pixels, far more than {} bytes can hold: \
                 the file is truncated or corrupt ({} of its bytes are compressed pixels)",
                bytes.len(),
                entropy_coded_bytes(&bytes)
            )
        );
        // A size within the allowance still decodes (the missing data filled).
        for at in [sof + 5, sof + 7] {
            bytes[at..at + 2].copy_from_slice(&1000u16.to_be_bytes());
        }
        let data = decode_image(&bytes, Decoding::Color).unwrap();
        assert_eq!((data.width(), data.height()), (1000, 1000));
    }

    /// Issue 50, item 8: a comment segment padding a small JPEG does not
    /// buy it pixels: only its compressed data counts.
    #[test]
    fn a_jpeg_padded_with_a_comment_is_refused_as_its_compressed_data_says() {
        let plain = include_bytes!("../../../tests/textures/two_blocks.jpg").to_vec();
        let coded = entropy_coded_bytes(&plain);
        assert!(coded > 0 && coded < plain.len() as u64 / 2, "{coded}");
        // 60 kB of comments after SOI, in segments of at most 65533 bytes.
        let mut padded = plain[..2].to_vec();
        for _ in 0..3 {
            padded.extend_from_slice(&[0xff, 0xfe]);
            padded.extend_from_slice(&20_002u16.to_be_bytes());
            padded.extend(std::iter::repeat_n(b'x', 20_000));
        }
        padded.extend_from_slice(&plain[2..]);
        assert_eq!(entropy_coded_bytes(&padded), coded);
        assert_eq!(
            decode_image(&padded, Decoding::Color).unwrap(),
            decode_image(&plain, Decoding::Color).unwrap()
        );
        let sof = padded
            .windows(2)
            .position(|w| w == [0xff, 0xc0] || w == [0xff, 0xc2])
            .unwrap();
        // 9000² pixels: within 4096 per byte of the padded file, not of
        // its compressed pixels.
        for at in [sof + 5, sof + 7] {
            padded[at..at + 2].copy_from_slice(&9000u16.to_be_bytes());
        }
        let error = decode_image(&padded, Decoding::Color).unwrap_err();
        assert!(
            error.starts_with("the header claims 9000x9000 pixels"),
            "{error}"
        );
    }

    /// Issue 50, item 5: 8-bit and 16-bit samples are kept as such, each
    /// read through the table of its value: the values the decoder made
    /// before, when it stored them as 32-bit floats, in a quarter or half
    /// of the memory.
    #[test]
    fn samples_are_kept_at_their_precision_and_read_as_the_same_values() {
        let rgb: Vec<u8> = (0..=255u8).flat_map(|v| [v, 255 - v, v / 2]).collect();
        let eight = decode_image(&png_bytes(16, 16, &rgb), Decoding::Color).unwrap();
        let table = eight_bit_table(Decoding::Color);
        let mut words = Vec::new();
        let mut encoder = png::Encoder::new(&mut words, 256, 1);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        let samples: Vec<u16> = (0..256u16).map(|i| i * 257 - i % 7).collect();
        let data: Vec<u8> = samples.iter().flat_map(|v| v.to_be_bytes()).collect();
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(&data).unwrap();
        writer.finish().unwrap();
        let sixteen = decode_image(&words, Decoding::Color).unwrap();
        for i in 0..256 {
            let (x, y) = (i % 16, i / 16);
            let expected =
                [rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]].map(|v| table[usize::from(v)]);
            assert_eq!(eight.texel_values(x, y), expected, "8-bit texel {i}");
            let value = texel_value(f32::from(samples[i]) / 65535.0, Decoding::Color);
            assert_eq!(sixteen.texel_values(i, 0), [value; 3], "16-bit texel {i}");
        }
        assert_eq!(eight.bytes_per_texel(), 3);
        assert_eq!(sixteen.bytes_per_texel(), 6);
    }

    #[test]
    fn sixteen_bit_grey_png_gives_grey_texels() {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, 1, 1);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(&65535u16.to_be_bytes()).unwrap();
        writer.finish().unwrap();
        let image = decode_image(&out, Decoding::Color).unwrap();
        let t = super::super::ImageTexture::new(Arc::new(image));
        assert_eq!(
            t.at(crate::math::DVec2::splat(0.5)),
            crate::shading::Color::ONE
        );
    }

    #[test]
    fn data_is_read_as_stored_and_opacity_from_alpha_or_else_as_data() {
        let texel = |bytes: &[u8], decoding| {
            let image = decode_image(bytes, decoding).unwrap();
            super::super::ImageTexture::new(Arc::new(image)).at(crate::math::DVec2::splat(0.5))
        };
        let rgb = png_bytes(1, 1, &[0, 51, 255]);
        let expected = crate::shading::Color::new(0.0, 0.2, 1.0);
        assert!((texel(&rgb, Decoding::Data) - expected).abs().max_element() < 1e-7);
        assert!(
            (texel(&rgb, Decoding::Opacity) - expected)
                .abs()
                .max_element()
                < 1e-7
        );
        let rgba = rgba_png_bytes(1, 1, &[255, 255, 255, 102]);
        let alpha = texel(&rgba, Decoding::Opacity);
        assert!(
            (alpha - crate::shading::Color::splat(0.4))
                .abs()
                .max_element()
                < 1e-7,
            "{alpha}"
        );
        assert_eq!(texel(&rgba, Decoding::Color), crate::shading::Color::ONE);
        let jpeg = include_bytes!("../../../tests/textures/two_blocks.jpg");
        let grey = decode_image(jpeg, Decoding::Data).unwrap();
        let right =
            super::super::ImageTexture::new(Arc::new(grey)).at(crate::math::DVec2::new(0.75, 0.5));
        assert!(
            (right - crate::shading::Color::splat(128.0 / 255.0))
                .abs()
                .max_element()
                < 0.01
        );
    }

    #[test]
    fn a_file_read_as_colour_and_as_data_is_decoded_once_each_way() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.png"), png_bytes(1, 1, &[128, 128, 255])).unwrap();
        let mut cache = ImageCache::default();
        let color = cache
            .load(&dir.path().join("a.png"), Decoding::Color)
            .unwrap();
        let data = cache
            .load(&dir.path().join("a.png"), Decoding::Data)
            .unwrap();
        let again = cache
            .load(&dir.path().join("a.png"), Decoding::Data)
            .unwrap();
        assert!(!Arc::ptr_eq(&color, &data) && Arc::ptr_eq(&data, &again));
        assert_eq!(cache.len(), 2);
    }

    #[test]
    fn a_file_named_twice_is_decoded_once() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.png"), png_bytes(1, 1, &[10, 20, 30])).unwrap();
        let mut cache = ImageCache::default();
        let first = cache
            .load(&dir.path().join("a.png"), Decoding::Color)
            .unwrap();
        let second = cache
            .load(&dir.path().join(".").join("a.png"), Decoding::Color)
            .unwrap();
        assert!(Arc::ptr_eq(&first, &second));
        assert_eq!(cache.len(), 1);
    }

    #[test]
    fn missing_and_foreign_files_say_why() {
        let dir = tempfile::tempdir().unwrap();
        let mut cache = ImageCache::default();
        let missing = cache
            .load(&dir.path().join("none.png"), Decoding::Color)
            .unwrap_err();
        assert!(matches!(missing, ImageLoadError::Io { .. }));
        std::fs::write(dir.path().join("text.png"), "hello").unwrap();
        let text = cache
            .load(&dir.path().join("text.png"), Decoding::Data)
            .unwrap_err();
        assert!(
            text.to_string()
                .ends_with("text.png`: not a PNG or JPEG file")
        );
    }
}
