//! Output pixels: float, 16-bit and dithered 8-bit RGBA, and PNG files.

use crate::error::{Error, ErrorKind};
use std::io::Write;

/// A channel type the renderer can write: `f32`, `u16` or `u8`.
///
/// Buffers hold RGBA with straight (non-premultiplied) alpha and sRGB-encoded colour, four
/// channels per pixel, rows top to bottom.
pub trait OutputPixel: Copy + Send + Sync + 'static {
    /// Whether this type is coarse enough to be dithered (8-bit).
    const DITHERED: bool;
    /// Whether [`OutputPixel::encode`] gives values below 0 (and NaN) the code of 0, and values
    /// above 1 that of 1, so that callers need not clamp first.
    const SATURATES: bool;

    /// Encodes a value in `0..=1`. `noise` (in `-1..1`, units of one output step) is added
    /// before rounding by types that dither; values exactly 0 or 1 are never dithered, so flat
    /// white, black, opaque and transparent areas stay exact.
    fn encode(v: f32, noise: f32) -> Self;

    /// [`OutputPixel::encode`] without noise, bit for bit, in a form without branches that
    /// loops over whole rows vectorise.
    fn encode_plain(v: f32) -> Self {
        Self::encode(v, 0.0)
    }

    /// [`OutputPixel::encode`], bit for bit, in a form without branches.
    fn encode_branchless(v: f32, noise: f32) -> Self {
        Self::encode(v, noise)
    }
}

impl OutputPixel for f32 {
    const DITHERED: bool = false;
    const SATURATES: bool = false;
    #[inline(always)]
    fn encode(v: f32, _noise: f32) -> Self {
        v
    }
}

impl OutputPixel for u16 {
    const DITHERED: bool = false;
    const SATURATES: bool = true;
    #[inline(always)]
    fn encode(v: f32, _noise: f32) -> Self {
        (v.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16
    }
}

impl OutputPixel for u8 {
    const DITHERED: bool = true;
    const SATURATES: bool = true;
    #[inline(always)]
    fn encode(v: f32, noise: f32) -> Self {
        if v <= 0.0 {
            0
        } else if v >= 1.0 {
            255
        } else {
            // Above -1, a saturating cast is floor-then-clamp (v > 0 and |noise| < 1 keep
            // the sum above -0.5), without the library call `floor` is on baseline x86-64.
            (v * 255.0 + 0.5 + noise) as u8
        }
    }
    #[inline(always)]
    fn encode_plain(v: f32) -> Self {
        // `(v * 255.0 + 0.5) as u8`, whose saturating cast does not vectorise.
        floor_to_u8(v * 255.0 + 0.5)
    }
    #[inline(always)]
    fn encode_branchless(v: f32, noise: f32) -> Self {
        // The extremes chosen by selects, not branches.
        let y = v * 255.0 + 0.5 + noise;
        let y = if v <= 0.0 { 0.0 } else { y };
        floor_to_u8(if v >= 1.0 { 255.0 } else { y })
    }
}

/// `y as u8` (the floor of `y`, 0 below 0 and for NaN, 255 above 255) without the saturating
/// cast, which does not vectorise: rounding with 2^23 leaves the nearest integer in the low
/// byte, less one where that rounded up.
#[inline(always)]
// `max` then `min`, not `clamp`: `clamp` keeps NaN, which must give 0.
#[allow(clippy::manual_clamp)]
fn floor_to_u8(y: f32) -> u8 {
    const ROUND: f32 = 8_388_608.0;
    let y = y.max(0.0).min(255.0);
    let r = y + ROUND;
    ((r.to_bits() & 0xff) - u32::from(r - ROUND > y)) as u8
}

/// Deterministic triangular (TPDF) dither noise in `-1..1` for the four channels of pixel
/// `(x, y)`: each the sum of two uniform bytes of one 64-bit hash of the position, so
/// quantisation error is independent of the signal and smooth gradients show no bands. No
/// pattern repeats at a small period, unlike a Bayer matrix. One hash serves the whole pixel
/// (eight bytes of noise at 1/256 of an output step are plenty).
#[inline(always)]
pub(crate) fn dither_noise(x: u32, y: u32) -> [f32; 4] {
    noise_of_hash(dither_hash(x, y))
}

/// The hash of pixel `(x, y)` that [`dither_noise`] is made of: splitmix64's finaliser of the
/// position.
#[inline(always)]
pub(crate) fn dither_hash(x: u32, y: u32) -> u64 {
    let mut v = ((y as u64) << 32 | x as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    v = (v ^ (v >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    v = (v ^ (v >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    v ^ (v >> 31)
}

/// [`dither_noise`] from the pixel's [`dither_hash`].
#[inline(always)]
pub(crate) fn noise_of_hash(v: u64) -> [f32; 4] {
    let b = v.to_le_bytes();
    // Written out: `[_; 4].map` with a closure was left as a call per pixel.
    let tpdf = |lo: u8, hi: u8| (lo as f32 + hi as f32 + 1.0) / 256.0 - 1.0;
    [
        tpdf(b[0], b[1]),
        tpdf(b[2], b[3]),
        tpdf(b[4], b[5]),
        tpdf(b[6], b[7]),
    ]
}

/// [`dither_noise`] of `N` pixels of row `y` from column `x`, channel `ch` of pixel `k` at
/// `4 k + ch`, with the same bits: each channel's two bytes are a 16-bit word of the hash,
/// summed in lanes (vectorised) rather than byte by byte.
#[inline(always)]
pub(crate) fn dither_noise_block<const N: usize, const C: usize>(x: u32, y: u32) -> [f32; C] {
    const { assert!(C == 4 * N) };
    let mut hashes = [0u64; N];
    for (k, h) in hashes.iter_mut().enumerate() {
        *h = dither_hash(x + k as u32, y);
    }
    // Each channel's two bytes summed in 16-bit lanes of the hash (no carry crosses lanes).
    const LOW: u64 = 0x00ff_00ff_00ff_00ff;
    let mut sums = [0u32; C];
    for (w, &h) in sums.chunks_exact_mut(4).zip(&hashes) {
        let s = (h & LOW) + ((h >> 8) & LOW);
        for (ch, w) in w.iter_mut().enumerate() {
            *w = ((s >> (16 * ch)) & 0xffff) as u32;
        }
    }
    let mut noise = [0.0f32; C];
    for (n, &w) in noise.iter_mut().zip(&sums) {
        // `tpdf` of `noise_of_hash`: the sum of two bytes is exact in `f32`.
        *n = (w as f32 + 1.0) / 256.0 - 1.0;
    }
    noise
}

/// An RGBA image with `f32` channels: straight (non-premultiplied) alpha, sRGB-encoded colour
/// in `0..=1`, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `4 * width * height` channels.
    pub data: Vec<f32>,
}

impl Image {
    /// A transparent image.
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            data: vec![0.0; 4 * width as usize * height as usize],
        }
    }

    /// The RGBA channels of pixel `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        let i = 4 * (y as usize * self.width as usize + x as usize);
        [
            self.data[i],
            self.data[i + 1],
            self.data[i + 2],
            self.data[i + 3],
        ]
    }

    /// The channels quantised to 8 bits (with optional dithering).
    pub fn to_u8(&self, dither: bool) -> Vec<u8> {
        self.quantise(dither)
    }

    /// The channels quantised to 16 bits.
    pub fn to_u16(&self) -> Vec<u16> {
        self.quantise(false)
    }

    fn quantise<P: OutputPixel>(&self, dither: bool) -> Vec<P> {
        use rayon::prelude::*;
        let w = self.width as usize;
        let mut out = vec![P::encode(0.0, 0.0); self.data.len()];
        if w == 0 {
            return out;
        }
        // Each pixel depends only on its own values and position: any split gives the same.
        out.par_chunks_mut(4 * w)
            .zip(self.data.par_chunks(4 * w))
            .enumerate()
            .for_each(|(y, (row_out, row))| {
                let pixels = row_out.chunks_exact_mut(4).zip(row.chunks_exact(4));
                for (x, (px, v)) in pixels.enumerate() {
                    let noise = if dither && P::DITHERED {
                        dither_noise(x as u32, y as u32)
                    } else {
                        [0.0; 4]
                    };
                    for c in 0..4 {
                        px[c] = P::encode(v[c], noise[c]);
                    }
                }
            });
        out
    }
}

/// The channel depth of a PNG made from an [`Image`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PngDepth {
    /// 8 bits per channel; `dither` adds blue-noise dither before rounding, so that slow
    /// gradients show no bands.
    Eight {
        /// Whether to dither.
        dither: bool,
    },
    /// 16 bits per channel.
    Sixteen,
}

/// Encodes an image as an RGBA PNG, marked as sRGB (an `sRGB` chunk, perceptual intent, with
/// the fallback `gAMA` and `cHRM` the PNG specification recommends). [`write_png`] writes it
/// to a file (or any writer) as it is encoded instead.
pub fn encode_png(image: &Image, depth: PngDepth) -> Result<Vec<u8>, Error> {
    let mut out = Vec::new();
    write_png(&mut out, image, depth)?;
    Ok(out)
}

/// Encodes 8-bit RGBA (as [`crate::render::render_document_into`] writes it: straight alpha,
/// sRGB-encoded, rows top to bottom) as a PNG marked as sRGB. Rendering straight into bytes
/// skips the `f32` image, four times the memory of the output.
pub fn encode_png_rgba8(width: u32, height: u32, data: &[u8]) -> Result<Vec<u8>, Error> {
    let mut out = Vec::new();
    write_png_rgba8(&mut out, width, height, data)?;
    Ok(out)
}

/// [`encode_png_rgba8`] for 16-bit channels.
pub fn encode_png_rgba16(width: u32, height: u32, data: &[u16]) -> Result<Vec<u8>, Error> {
    let mut out = Vec::new();
    write_png_rgba16(&mut out, width, height, data)?;
    Ok(out)
}

/// [`encode_png`], written to `out` as it is encoded, so that the caller holds no copy of the
/// file (for 8 bits the compressed stream is held until the end; 16-bit rows are
/// converted and compressed a band at a time). The bytes are those [`encode_png`] returns.
pub fn write_png(out: impl Write, image: &Image, depth: PngDepth) -> Result<(), Error> {
    match depth {
        PngDepth::Eight { dither } => {
            write_png_rgba8(out, image.width, image.height, &image.to_u8(dither))
        }
        PngDepth::Sixteen => write_png_rgba16(out, image.width, image.height, &image.to_u16()),
    }
}

/// [`encode_png_rgba8`], written to `out` as it is encoded.
pub fn write_png_rgba8(out: impl Write, width: u32, height: u32, data: &[u8]) -> Result<(), Error> {
    write_png_rgba8_with(out, width, height, data, PngCompression::Fast)
}

/// How hard an 8-bit PNG is compressed. The pixels are the same.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PngCompression {
    /// Every row with the Sub filter and fdeflate's fixed code, on every core: a megapixel of
    /// a gradient mesh in a few milliseconds, about a fifth of its raw size.
    #[default]
    Fast,
    /// The filter chosen row by row and zlib's best level, on one thread: some ten times the
    /// time of [`PngCompression::Fast`] for a smaller file.
    Best,
}

/// [`write_png_rgba8`] with the compression `compression`.
pub fn write_png_rgba8_with(
    out: impl Write,
    width: u32,
    height: u32,
    data: &[u8],
    compression: PngCompression,
) -> Result<(), Error> {
    check_len(width, height, data.len())?;
    let mut writer = png_writer(out, width, height, png::BitDepth::Eight, compression)?;
    match compression {
        PngCompression::Fast => {
            // Compressed in segments in parallel, one `IDAT` chunk each (see `png_deflate`).
            for segment in super::png_deflate::compress_rgba8(data, 4 * width as usize) {
                writer
                    .write_chunk(png::chunk::IDAT, &segment.bytes)
                    .map_err(png_error)?;
            }
        }
        // The whole image at once: `png` then compresses it in one stream.
        PngCompression::Best => writer.write_image_data(data).map_err(png_error)?,
    }
    writer.finish().map_err(png_error)
}

/// [`encode_png_rgba16`], written to `out` as it is encoded.
pub fn write_png_rgba16(
    out: impl Write,
    width: u32,
    height: u32,
    data: &[u16],
) -> Result<(), Error> {
    use rayon::prelude::*;
    check_len(width, height, data.len())?;
    let mut writer = png_writer(
        out,
        width,
        height,
        png::BitDepth::Sixteen,
        PngCompression::Fast,
    )?;
    // Row by row, so that the image is never held as PNG's big-endian bytes (twice the
    // 8-bit image): converted a band of rows at a time, a row per task, and streamed in IDAT
    // chunks of 256 KiB (the default 4 KiB made encoding a tenth slower).
    let mut rows = writer.stream_writer_with_size(1 << 18).map_err(png_error)?;
    let row = (4 * width as usize).max(1);
    let mut bytes = vec![0u8; 2 * row * 64];
    for band in data.chunks(row * 64) {
        let bytes = &mut bytes[..2 * band.len()];
        bytes
            .par_chunks_mut(2 * row)
            .zip(band.par_chunks(row))
            .for_each(|(out, values)| {
                for (b, v) in out.chunks_exact_mut(2).zip(values) {
                    b.copy_from_slice(&v.to_be_bytes());
                }
            });
        rows.write_all(bytes)
            .map_err(|e| png_error(png::EncodingError::from(e)))?;
    }
    rows.finish().map_err(png_error)?;
    writer.finish().map_err(png_error)
}

fn check_len(width: u32, height: u32, len: usize) -> Result<(), Error> {
    let need = 4 * width as u64 * height as u64;
    if len as u64 != need {
        return Err(ErrorKind::Invalid {
            what: "pixels".into(),
            message: format!(
                "{len} channels for a {width}x{height} RGBA image, which needs {need}"
            ),
        }
        .into());
    }
    Ok(())
}

fn png_error(e: png::EncodingError) -> Error {
    ErrorKind::Io(format!("PNG encoding: {e}")).into()
}

/// A PNG writer of RGBA at `depth`, marked as sRGB, its header written.
fn png_writer<W: Write>(
    out: W,
    width: u32,
    height: u32,
    depth: png::BitDepth,
    compression: PngCompression,
) -> Result<png::Writer<W>, Error> {
    let mut enc = png::Encoder::new(out, width, height);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(depth);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    // The fast deflate (fdeflate): several times faster than the default level for a few
    // percent more bytes. Every row with the Sub filter: the adaptive choice (which tries
    // all five filters on each row) is much slower to encode for files only slightly
    // smaller. The pixels are the same.
    match compression {
        PngCompression::Fast => {
            enc.set_compression(png::Compression::Fast);
            enc.set_filter(png::Filter::Sub);
        }
        PngCompression::Best => {
            enc.set_compression(png::Compression::High);
            enc.set_filter(png::Filter::Adaptive);
        }
    }
    enc.write_header().map_err(png_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The types that say they saturate encode any value as its clamped value.
    #[test]
    fn saturating_types_need_no_clamp() {
        fn check<P: OutputPixel + PartialEq + std::fmt::Debug>() {
            assert!(P::SATURATES);
            let values = [
                f32::NAN,
                f32::NEG_INFINITY,
                -3.0,
                -1e-7,
                -0.0,
                0.0,
                0.3,
                1.0,
            ];
            let values = values.iter().chain(&[1.0 + 1e-7, 1.5, f32::INFINITY]);
            for &v in values {
                for noise in [-0.99, 0.0, 0.5] {
                    let clamped = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
                    assert_eq!(
                        P::encode(v, noise),
                        P::encode(clamped, noise),
                        "{v} {noise}"
                    );
                }
            }
        }
        check::<u8>();
        check::<u16>();
    }

    /// Values for checking encodings: the extremes and NaN, `steps + 1` even steps from 0 to 1,
    /// and the 8-bit rounding boundaries, each also just below and just above.
    fn encoding_test_values(steps: u32) -> Vec<f32> {
        let mut values = vec![f32::NAN, f32::NEG_INFINITY, f32::INFINITY, -1.0, 2.0];
        let steps = (0..=steps).map(|k| k as f32 / steps as f32);
        let boundaries = (0..=255).map(|k| (k as f32 + 0.5) / 255.0);
        for v in steps.chain(boundaries) {
            values.extend([v, v * (1.0 - f32::EPSILON), v * (1.0 + f32::EPSILON)]);
        }
        values
    }

    #[test]
    fn plain_encoding_is_encoding_without_noise() {
        fn check<P: OutputPixel + PartialEq + std::fmt::Debug>() {
            for v in encoding_test_values(65536) {
                let (a, b) = (P::encode_plain(v), P::encode(v, 0.0));
                // Compared as printed, so that NaN (f32) matches NaN.
                assert_eq!(format!("{a:?}"), format!("{b:?}"), "{v}");
            }
        }
        check::<u8>();
        check::<u16>();
        check::<f32>();
    }

    #[test]
    fn branchless_encoding_is_encoding() {
        fn check<P: OutputPixel + PartialEq + std::fmt::Debug>() {
            let noises = [-0.999_999, -0.5, -1.0 / 256.0, 0.0, 0.25, 0.5, 0.999_999];
            for v in encoding_test_values(4096) {
                for noise in noises {
                    let (a, b) = (P::encode_branchless(v, noise), P::encode(v, noise));
                    assert_eq!(format!("{a:?}"), format!("{b:?}"), "{v} {noise}");
                }
            }
        }
        check::<u8>();
        check::<u16>();
        check::<f32>();
    }

    #[test]
    fn noise_of_a_block_is_each_pixels_noise() {
        let mut random = crate::render::test_random(7);
        for _ in 0..2000 {
            let (x, y) = ((random() >> 40) as u32, (random() >> 40) as u32);
            let block = dither_noise_block::<8, 32>(x, y);
            for k in 0..8 {
                let one = dither_noise(x + k as u32, y);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&block[4 * k..4 * k + 4]), bits(&one));
            }
        }
    }

    #[test]
    fn noise_is_triangular_and_centred() {
        let mut sum = 0.0;
        let mut inner = 0;
        let n = 200_000;
        for i in 0..n {
            for v in dither_noise(i % 512, i / 512) {
                assert!((-1.0..1.0).contains(&v));
                sum += v as f64;
                if v.abs() < 0.5 {
                    inner += 1;
                }
            }
        }
        let n = 4.0 * n as f64;
        assert!((sum / n).abs() < 0.01);
        // A triangular density puts 3/4 of its mass within half the range.
        assert!((inner as f64 / n - 0.75).abs() < 0.01);
    }

    #[test]
    fn noise_is_uncorrelated_between_channels_and_neighbours() {
        let (mut channels, mut neighbours, mut power) = (0.0, 0.0, 0.0);
        for y in 0..256 {
            for x in 0..256 {
                let (v, right) = (dither_noise(x, y), dither_noise(x + 1, y));
                channels += (v[0] * v[1]) as f64;
                neighbours += (v[2] * right[2]) as f64;
                power += (v[0] * v[0]) as f64;
            }
        }
        assert!((channels / power).abs() < 0.02, "{}", channels / power);
        assert!((neighbours / power).abs() < 0.02, "{}", neighbours / power);
    }

    #[test]
    fn dithering_keeps_the_mean_and_the_extremes() {
        let mut img = Image::new(64, 64);
        img.data
            .iter_mut()
            .for_each(|v| *v = 0.3 / 255.0 + 100.0 / 255.0);
        img.data[0] = 0.0;
        img.data[1] = 1.0;
        let q = img.to_u8(true);
        assert_eq!((q[0], q[1]), (0, 255));
        let mean = q[2..].iter().map(|&v| v as f64).sum::<f64>() / (q.len() - 2) as f64;
        assert!((mean - 100.3).abs() < 0.05, "{mean}");
        assert!(img.to_u8(false)[2..].iter().all(|&v| v == 100));
    }

    #[test]
    fn png_from_bytes_checks_the_length() {
        assert!(encode_png_rgba8(3, 2, &[0; 24]).is_ok());
        assert!(encode_png_rgba8(3, 2, &[0; 23]).is_err());
        assert!(encode_png_rgba16(3, 2, &[0; 25]).is_err());
    }

    #[test]
    fn png_has_an_srgb_chunk_and_round_trips() {
        let mut img = Image::new(3, 2);
        for (i, v) in img.data.iter_mut().enumerate() {
            *v = i as f32 / 23.0;
        }
        for depth in [PngDepth::Eight { dither: false }, PngDepth::Sixteen] {
            let bytes = encode_png(&img, depth).unwrap();
            let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
            let mut reader = decoder.read_info().unwrap();
            assert!(reader.info().srgb.is_some());
            let mut buf = vec![0; reader.output_buffer_size().unwrap()];
            let frame = reader.next_frame(&mut buf).unwrap();
            assert_eq!((frame.width, frame.height), (3, 2));
            if depth == PngDepth::Sixteen {
                let v = u16::from_be_bytes([buf[2 * 5], buf[2 * 5 + 1]]);
                assert_eq!(v, (5.0 / 23.0 * 65535.0f32 + 0.5) as u16);
            } else {
                assert_eq!(buf[5], (5.0 / 23.0 * 255.0f32 + 0.5) as u8);
            }
        }
    }

    /// 16-bit rows go out in bands of 64: an image of several bands and an odd width comes
    /// back value for value.
    #[test]
    fn png_of_16_bits_round_trips_over_several_bands() {
        let (w, h) = (37u32, 150u32);
        let data: Vec<u16> = (0..4 * w * h)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 16) as u16)
            .collect();
        let bytes = encode_png_rgba16(w, h, &data).unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut buf).unwrap();
        let back: Vec<u16> = buf
            .chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect();
        assert_eq!(back, data);
    }

    /// Both compressions give the same pixels, over several of the fast encoder's segments.
    #[test]
    fn png_compressions_decode_to_the_same_pixels() {
        let (w, h) = (173u32, 900u32);
        let data: Vec<u8> = (0..4 * w * h)
            .map(|i| ((i / 4 % w) / 3 + (i / 4 / w) / 5 + 40 * (i % 4)) as u8)
            .collect();
        for compression in [PngCompression::Fast, PngCompression::Best] {
            let mut bytes = Vec::new();
            write_png_rgba8_with(&mut bytes, w, h, &data, compression).unwrap();
            let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
                .read_info()
                .unwrap();
            assert!(reader.info().srgb.is_some());
            let mut buf = vec![0; reader.output_buffer_size().unwrap()];
            reader.next_frame(&mut buf).unwrap();
            assert_eq!(buf, data, "{compression:?}");
        }
    }

    /// A writer that fails (a full disk, say) fails the encoding with an error, not a panic.
    #[test]
    fn png_writing_reports_a_failing_writer() {
        struct Full;
        impl Write for Full {
            fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
                Err(std::io::Error::other("no space left"))
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let e = write_png_rgba8(Full, 3, 2, &[0; 24]).unwrap_err();
        assert!(e.to_string().contains("no space left"), "{e}");
        let e = write_png_rgba16(Full, 3, 2, &[0; 24]).unwrap_err();
        assert!(e.to_string().contains("no space left"), "{e}");
    }
}
