//! Pictures to fit: an RGBA image type, PNG and JPEG decoding with the size checked before any
//! pixel is decoded, the target colours in the working space, and PSNR.

use std::io::{Cursor, Read};
use std::path::Path;

use crate::colour::{srgb_decode, ColourSpace};
use crate::error::{Error, ErrorKind};

/// The largest picture the command line decodes by default, in pixels (64 megapixels).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// The largest image file the command line reads by default, in bytes (256 MiB).
pub const MAX_IMAGE_BYTES: u64 = 1 << 28;

/// A picture: RGBA, straight alpha, sRGB-encoded channels in `0..=1`, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbaImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels.
    pub pixels: Vec<[f32; 4]>,
}

fn invalid(what: &str, message: impl Into<String>) -> Error {
    Error::new(ErrorKind::Invalid {
        what: what.into(),
        message: message.into(),
    })
}

/// Refuses an empty picture or one of more than `max_pixels` pixels.
fn check_size(what: &str, width: u64, height: u64, max_pixels: u64) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(invalid(
            what,
            format!("{width} x {height} pixels: the picture is empty"),
        ));
    }
    let pixels = width.saturating_mul(height);
    if pixels > max_pixels {
        return Err(Error::new(ErrorKind::LimitExceeded {
            what: format!("{what}: the number of pixels ({width} x {height})"),
            found: pixels,
            limit: max_pixels,
        }));
    }
    Ok(())
}

impl RgbaImage {
    /// A picture of one colour.
    pub fn filled(width: u32, height: u32, rgba: [f32; 4]) -> RgbaImage {
        RgbaImage {
            width,
            height,
            pixels: vec![rgba; width as usize * height as usize],
        }
    }

    /// A picture from 8-bit RGBA channels (`4 * width * height` of them).
    pub fn from_rgba8(width: u32, height: u32, data: &[u8]) -> Result<RgbaImage, Error> {
        if data.len() != 4 * width as usize * height as usize {
            return Err(invalid(
                "image",
                format!("{} channels for {width} x {height} RGBA pixels", data.len()),
            ));
        }
        let pixels = data
            .chunks_exact(4)
            .map(|p| [0, 1, 2, 3].map(|k| p[k] as f32 / 255.0))
            .collect();
        Ok(RgbaImage {
            width,
            height,
            pixels,
        })
    }

    /// Reads and decodes a PNG or JPEG file ([`RgbaImage::decode`]), refusing a file of more
    /// than `max_bytes` before reading it; errors name the file.
    pub fn read_path(path: &Path, max_bytes: u64, max_pixels: u64) -> Result<RgbaImage, Error> {
        let io =
            |e: std::io::Error| Error::new(ErrorKind::Io(format!("cannot read the file: {e}")));
        let located = |e: Error| e.in_file(path);
        let file = std::fs::File::open(path).map_err(io).map_err(located)?;
        let size = file.metadata().map_err(io).map_err(located)?.len();
        let too_large = |found: u64| {
            Error::new(ErrorKind::LimitExceeded {
                what: "the file's size in bytes".into(),
                found,
                limit: max_bytes,
            })
            .in_file(path)
        };
        if size > max_bytes {
            return Err(too_large(size));
        }
        let mut bytes = Vec::with_capacity(size as usize);
        file.take(max_bytes.saturating_add(1))
            .read_to_end(&mut bytes)
            .map_err(io)
            .map_err(located)?;
        if bytes.len() as u64 > max_bytes {
            return Err(too_large(bytes.len() as u64));
        }
        RgbaImage::decode(&bytes, max_pixels).map_err(located)
    }

    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// 8-bit RGBA channels, rounded.
    pub fn to_rgba8(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect()
    }

    /// Decodes a PNG or JPEG file's bytes (told apart by their signature). The size in the
    /// header is checked against `max_pixels` before any pixel is decoded; a file that is not
    /// a PNG or JPEG, is truncated or corrupt, or is empty gives an error saying so.
    pub fn decode(bytes: &[u8], max_pixels: u64) -> Result<RgbaImage, Error> {
        if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            decode_png(bytes, max_pixels)
        } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
            decode_jpeg(bytes, max_pixels)
        } else {
            Err(invalid(
                "image",
                "not a PNG or JPEG file (its first bytes are neither signature)",
            ))
        }
    }
}

fn decode_png(bytes: &[u8], max_pixels: u64) -> Result<RgbaImage, Error> {
    let broken = |e: png::DecodingError| invalid("PNG image", e.to_string());
    // The decoder's own allocation limit covers what the size check below does not (text
    // chunks, ICC profiles); the pixels themselves are checked against `max_pixels`.
    let limits = png::Limits {
        bytes: (max_pixels.saturating_mul(8)).min(usize::MAX as u64) as usize,
    };
    let mut decoder = png::Decoder::new_with_limits(Cursor::new(bytes), limits);
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(broken)?;
    let (width, height) = reader.info().size();
    check_size("PNG image", width as u64, height as u64, max_pixels)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| invalid("PNG image", "too large to decode"))?;
    let mut buf = vec![0; size];
    let info = reader.next_frame(&mut buf).map_err(broken)?;
    let data = &buf[..info.buffer_size()];
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => {
            return Err(invalid("PNG image", "palette not expanded"));
        }
    };
    let row = info.line_size;
    let mut pixels = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height as usize {
        let line = &data[y * row..];
        for x in 0..width as usize {
            let p = &line[x * channels..(x + 1) * channels];
            let c = |k: usize| p[k] as f32 / 255.0;
            pixels.push(match channels {
                1 => [c(0), c(0), c(0), 1.0],
                2 => [c(0), c(0), c(0), c(1)],
                3 => [c(0), c(1), c(2), 1.0],
                _ => [c(0), c(1), c(2), c(3)],
            });
        }
    }
    Ok(RgbaImage {
        width,
        height,
        pixels,
    })
}

fn decode_jpeg(bytes: &[u8], max_pixels: u64) -> Result<RgbaImage, Error> {
    use zune_jpeg::zune_core::colorspace::ColorSpace;
    use zune_jpeg::zune_core::options::DecoderOptions;
    let broken = |e: zune_jpeg::errors::DecodeErrors| invalid("JPEG image", format!("{e:?}"));
    let options = DecoderOptions::default()
        .jpeg_set_out_colorspace(ColorSpace::RGB)
        .set_max_width(1 << 16)
        .set_max_height(1 << 16);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(Cursor::new(bytes), options);
    decoder.decode_headers().map_err(broken)?;
    let info = decoder
        .info()
        .ok_or_else(|| invalid("JPEG image", "no frame header"))?;
    let (width, height) = (info.width as u32, info.height as u32);
    check_size("JPEG image", width as u64, height as u64, max_pixels)?;
    let data = decoder.decode().map_err(broken)?;
    let expected = 3 * width as usize * height as usize;
    if data.len() < expected {
        return Err(invalid(
            "JPEG image",
            format!("{} bytes decoded for {width} x {height} pixels", data.len()),
        ));
    }
    let pixels = data[..expected]
        .chunks_exact(3)
        .map(|p| {
            let c = |k: usize| p[k] as f32 / 255.0;
            [c(0), c(1), c(2), 1.0]
        })
        .collect();
    Ok(RgbaImage {
        width,
        height,
        pixels,
    })
}

/// Peak signal-to-noise ratio of `b` against `a` in decibels, over the 8-bit sRGB colour
/// channels of every pixel premultiplied by its alpha (the pictures over black, so that a
/// transparent pixel where the other is opaque counts, and colours where both are transparent
/// do not): `10 log10(255^2 / MSE)`, infinite for equal pictures. The two must have the same
/// size.
pub fn psnr(a: &RgbaImage, b: &RgbaImage) -> Result<f64, Error> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(invalid(
            "psnr",
            format!(
                "pictures of {} x {} and {} x {} pixels",
                a.width, a.height, b.width, b.height
            ),
        ));
    }
    let eight = |p: &[f32; 4], k: usize| {
        (p[k].clamp(0.0, 1.0) * p[3].clamp(0.0, 1.0) * 255.0).round() as f64
    };
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| {
            (0..3)
                .map(|k| (eight(p, k) - eight(q, k)).powi(2))
                .sum::<f64>()
        })
        .sum();
    Ok(psnr_of_sum(sum, 3 * a.pixels.len()))
}

/// PSNR of a sum of squared 8-bit errors over `count` channels.
pub(crate) fn psnr_of_sum(sum: f64, count: usize) -> f64 {
    if sum == 0.0 {
        return f64::INFINITY;
    }
    10.0 * (255.0f64 * 255.0 * count as f64 / sum).log10()
}

/// What a fit aims at: a colour in the working space and a weight (the alpha) per pixel.
#[derive(Clone, Debug)]
pub(crate) struct Target {
    pub width: usize,
    pub height: usize,
    pub colour: Vec<[f64; 3]>,
    pub weight: Vec<f64>,
}

impl Target {
    /// The picture's colours converted to `space`, weighted by their alpha.
    pub fn new(image: &RgbaImage, space: ColourSpace) -> Target {
        use rayon::prelude::*;
        let colour = image
            .pixels
            .par_iter()
            .map(|p| {
                let linear = [0, 1, 2].map(|k| srgb_decode(p[k].clamp(0.0, 1.0) as f64));
                space.from_linear_srgb(linear)
            })
            .collect();
        let weight = image
            .pixels
            .iter()
            .map(|p| p[3].clamp(0.0, 1.0) as f64)
            .collect();
        Target {
            width: image.width as usize,
            height: image.height as usize,
            colour,
            weight,
        }
    }
}
