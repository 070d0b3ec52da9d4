//! From a working-space colour to a displayable sRGB colour: conversion to linear light, gamut
//! mapping, and the choice of compositing space.

use crate::colour::{srgb_encode, ColourSpace};

/// What to do with a colour that lies outside the sRGB gamut.
///
/// Interpolating in CIE Lab (the paper's space) between in-gamut colours can leave the gamut, so
/// some decision is needed for every pixel; it is taken in linear light, after the colour has been
/// interpolated, never on an intermediate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum GamutMapping {
    /// Clamp each linear-light channel to `0..=1`. Fast, but shifts hue and lightness of
    /// saturated colours (a saturated blue clamps towards purple).
    Clip,
    /// Reduce chroma in Oklch at constant lightness and hue until the colour is inside (within a
    /// just-noticeable difference of 0.02 in Oklab, then clip): the gamut-mapping algorithm of
    /// CSS Color 4, section 13.2. The default: it keeps the hue and lightness that the
    /// interpolation produced, and it only costs time on the (few) pixels outside the gamut.
    #[default]
    Chroma,
}

impl GamutMapping {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            GamutMapping::Clip => "clip",
            GamutMapping::Chroma => "chroma",
        }
    }

    /// The mapping with the given name.
    pub fn from_name(name: &str) -> Option<GamutMapping> {
        [GamutMapping::Clip, GamutMapping::Chroma]
            .into_iter()
            .find(|g| g.name() == name)
    }

    /// Maps a linear-light sRGB colour into `0..=1` on every channel.
    pub fn apply(self, rgb: [f64; 3]) -> [f64; 3] {
        if in_gamut(rgb, 0.0) {
            return rgb;
        }
        match self {
            GamutMapping::Clip => clip(rgb),
            GamutMapping::Chroma => reduce_chroma(rgb),
        }
    }
}

/// The space in which layers are composited (source-over, premultiplied alpha), and in which the
/// anti-aliased outline is blended with what lies below.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BlendSpace {
    /// sRGB-encoded values, as SVG, CSS, PDF viewers and every image viewer composite. The default:
    /// an image rendered with a transparent background and composited by a viewer looks the same
    /// as the image rendered here over that background (source-over is associative only within one
    /// space), and layered artwork made in the authors' tool was drawn the same way.
    #[default]
    Srgb,
    /// Linear light: physically correct mixing of light (anti-aliased edges keep their apparent
    /// weight), but different from how a viewer composites the resulting PNG.
    Linear,
}

impl BlendSpace {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            BlendSpace::Srgb => "srgb",
            BlendSpace::Linear => "linear",
        }
    }

    /// The space with the given name.
    pub fn from_name(name: &str) -> Option<BlendSpace> {
        [BlendSpace::Srgb, BlendSpace::Linear]
            .into_iter()
            .find(|g| g.name() == name)
    }
}

/// Converts a working-space colour to an in-gamut colour in the blend space.
#[inline]
pub(crate) fn to_blend_space(
    space: ColourSpace,
    c: [f64; 3],
    gamut: GamutMapping,
    blend: BlendSpace,
) -> [f64; 3] {
    let lin = gamut.apply(space.to_linear_srgb(c));
    match blend {
        BlendSpace::Linear => lin,
        BlendSpace::Srgb => lin.map(srgb_encode),
    }
}

fn in_gamut(rgb: [f64; 3], tolerance: f64) -> bool {
    rgb.iter()
        .all(|&v| (-tolerance..=1.0 + tolerance).contains(&v))
}

fn clip(rgb: [f64; 3]) -> [f64; 3] {
    rgb.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
}

/// Linear-light sRGB to Oklab (Ottosson 2020).
pub(crate) fn linear_srgb_to_oklab(c: [f64; 3]) -> [f64; 3] {
    let [r, g, b] = c;
    let l = 0.412_221_470_8 * r + 0.536_332_536_3 * g + 0.051_445_992_9 * b;
    let m = 0.211_903_498_2 * r + 0.680_699_545_1 * g + 0.107_396_956_6 * b;
    let s = 0.088_302_461_9 * r + 0.281_718_837_6 * g + 0.629_978_700_5 * b;
    let (l, m, s) = (l.cbrt(), m.cbrt(), s.cbrt());
    [
        0.210_454_255_3 * l + 0.793_617_785_0 * m - 0.004_072_046_8 * s,
        1.977_998_495_1 * l - 2.428_592_205_0 * m + 0.450_593_709_9 * s,
        0.025_904_037_1 * l + 0.782_771_766_2 * m - 0.808_675_766_0 * s,
    ]
}

/// Oklab to linear-light sRGB.
pub(crate) fn oklab_to_linear_srgb(c: [f64; 3]) -> [f64; 3] {
    let [ll, a, b] = c;
    let l = ll + 0.396_337_777_4 * a + 0.215_803_757_3 * b;
    let m = ll - 0.105_561_345_8 * a - 0.063_854_172_8 * b;
    let s = ll - 0.089_484_177_5 * a - 1.291_485_548_0 * b;
    let (l, m, s) = (l * l * l, m * m * m, s * s * s);
    [
        4.076_741_662_1 * l - 3.307_711_591_3 * m + 0.230_969_929_2 * s,
        -1.268_438_004_6 * l + 2.609_757_401_1 * m - 0.341_319_396_5 * s,
        -0.004_196_086_3 * l - 0.703_418_614_7 * m + 1.707_614_701_0 * s,
    ]
}

fn delta_e_ok(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// CSS Color 4's binary search for the largest chroma (at the colour's Oklab lightness and hue)
/// whose clipped version is within a just-noticeable difference of it.
fn reduce_chroma(rgb: [f64; 3]) -> [f64; 3] {
    const JND: f64 = 0.02;
    const EPSILON: f64 = 1e-4;
    if rgb.iter().any(|v| !v.is_finite()) {
        return clip(rgb);
    }
    let lab = linear_srgb_to_oklab(rgb);
    let l = lab[0];
    if l >= 1.0 {
        return [1.0; 3];
    }
    if l <= 0.0 {
        return [0.0; 3];
    }
    let chroma = lab[1].hypot(lab[2]);
    if chroma == 0.0 {
        return clip(rgb);
    }
    let (ua, ub) = (lab[1] / chroma, lab[2] / chroma);
    let with_chroma = |c: f64| [l, c * ua, c * ub];

    let mut clipped = clip(rgb);
    if delta_e_ok(linear_srgb_to_oklab(clipped), lab) < JND {
        return clipped;
    }
    let (mut min, mut max) = (0.0, chroma);
    let mut min_in_gamut = true;
    while max - min > EPSILON {
        let c = 0.5 * (min + max);
        let current = with_chroma(c);
        let current_rgb = oklab_to_linear_srgb(current);
        if min_in_gamut && in_gamut(current_rgb, 0.0) {
            min = c;
            continue;
        }
        clipped = clip(current_rgb);
        let e = delta_e_ok(linear_srgb_to_oklab(clipped), current);
        if e < JND {
            if JND - e < EPSILON {
                return clipped;
            }
            min_in_gamut = false;
            min = c;
        } else {
            max = c;
        }
    }
    clipped
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oklab_round_trip_and_white() {
        let w = linear_srgb_to_oklab([1.0, 1.0, 1.0]);
        assert!((w[0] - 1.0).abs() < 1e-6 && w[1].abs() < 1e-6 && w[2].abs() < 1e-6);
        let c = [0.2, 0.7, 0.05];
        let back = oklab_to_linear_srgb(linear_srgb_to_oklab(c));
        for (x, y) in back.iter().zip(c) {
            assert!((x - y).abs() < 1e-6);
        }
    }

    #[test]
    fn in_gamut_colours_are_untouched() {
        for g in [GamutMapping::Clip, GamutMapping::Chroma] {
            assert_eq!(g.apply([0.1, 0.5, 1.0]), [0.1, 0.5, 1.0]);
        }
    }

    #[test]
    fn chroma_reduction_keeps_hue_and_lightness() {
        // A Lab colour far outside sRGB: a very saturated cyan-blue.
        let lab = [60.0, -40.0, -90.0];
        let lin = ColourSpace::Lab.to_linear_srgb(lab);
        assert!(lin.iter().any(|&v| !(0.0..=1.0).contains(&v)));
        let mapped = GamutMapping::Chroma.apply(lin);
        assert!(
            mapped.iter().all(|&v| (0.0..=1.0).contains(&v)),
            "{mapped:?}"
        );
        let (a, b) = (linear_srgb_to_oklab(lin), linear_srgb_to_oklab(mapped));
        assert!((a[0] - b[0]).abs() < 0.02, "lightness {a:?} {b:?}");
        let hue = |c: [f64; 3]| c[2].atan2(c[1]);
        assert!((hue(a) - hue(b)).abs() < 0.1, "hue {a:?} {b:?}");
        // Clipping keeps neither as well.
        let clipped = GamutMapping::Clip.apply(lin);
        let c = linear_srgb_to_oklab(clipped);
        assert!((hue(a) - hue(c)).abs() > (hue(a) - hue(b)).abs());
    }

    #[test]
    fn extremes() {
        assert_eq!(GamutMapping::Chroma.apply([1.5, 1.2, 1.1]), [1.0; 3]);
        assert_eq!(GamutMapping::Chroma.apply([-0.1, -0.2, -0.05]), [0.0; 3]);
        assert_eq!(
            GamutMapping::Clip.apply([f64::NAN, 2.0, -1.0]),
            [0.0, 1.0, 0.0]
        );
    }
}
