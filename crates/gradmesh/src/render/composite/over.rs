//! Compositing a picture over a caller's canvas: premultiplied RGBA in 8 or 16 bits (tiny-skia's
//! and resvg's pixmap layout in 8 bits), so that other content and mesh layers share one buffer.
//! Each band is drawn into a band-sized `f32` buffer and composited source-over onto the
//! canvas's band; nothing the size of the image is allocated.

use crate::render::output::pixels::{dither_noise, OutputPixel};

/// A channel type of a premultiplied canvas a picture can be composited over: `u8` or `u16`.
pub trait CanvasPixel: OutputPixel {
    /// The value in `0..=1` that this code stands for.
    fn decode(self) -> f32;
}

impl CanvasPixel for u8 {
    #[inline(always)]
    fn decode(self) -> f32 {
        f32::from(self) / 255.0
    }
}

impl CanvasPixel for u16 {
    #[inline(always)]
    fn decode(self) -> f32 {
        f32::from(self) / 65535.0
    }
}

/// Composites `band` (straight alpha, sRGB-encoded, as the renderer draws) over `canvas`
/// (premultiplied), both rows `y0..` of an image `width` pixels wide. Pixels the band leaves
/// clear keep their bits; the others are dithered (8-bit canvas) with the renderer's noise.
pub(crate) fn composite_band_over<P: CanvasPixel>(
    canvas: &mut [P],
    band: &[f32],
    (width, y0): (usize, usize),
    dither: bool,
) {
    let dither = dither && P::DITHERED;
    for (i, (dst, src)) in canvas
        .chunks_exact_mut(4)
        .zip(band.chunks_exact(4))
        .enumerate()
    {
        let alpha = src[3].clamp(0.0, 1.0);
        if alpha <= 0.0 {
            continue;
        }
        let noise = if dither {
            dither_noise((i % width) as u32, (y0 + i / width) as u32)
        } else {
            [0.0; 4]
        };
        let keep = 1.0 - alpha;
        for c in 0..3 {
            let v = src[c].clamp(0.0, 1.0) * alpha + dst[c].decode() * keep;
            dst[c] = P::encode(v, noise[c]);
        }
        dst[3] = P::encode(alpha + dst[3].decode() * keep, noise[3]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opaque_source_replaces_and_clear_source_keeps() {
        let mut canvas: Vec<u8> = vec![10, 20, 30, 40, 10, 20, 30, 40];
        let band = [1.0, 0.5, 0.0, 1.0, 0.3, 0.3, 0.3, 0.0];
        composite_band_over(&mut canvas, &band, (2, 0), false);
        assert_eq!(canvas, vec![255, 128, 0, 255, 10, 20, 30, 40]);
    }

    #[test]
    fn half_opaque_source_over_premultiplied_canvas() {
        // White at half opacity over premultiplied half-opaque black (0, 0, 0, 0.5): colour
        // 0.5 * 1 + 0 * 0.5 = 0.5, alpha 0.5 + 0.5 * 0.5 = 0.75.
        let mut canvas: Vec<u16> = vec![0, 0, 0, 32768];
        composite_band_over(&mut canvas, &[1.0, 1.0, 1.0, 0.5], (1, 0), false);
        assert_eq!(canvas[0], 32768);
        assert_eq!(canvas[3], 49152);
    }
}
