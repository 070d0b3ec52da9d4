//! From a working-space colour to a displayable sRGB colour: conversion to linear light, gamut
//! mapping, and the choice of compositing space.

use super::fast::{
    encode_table_f32, lab_matrix_f32, lab_to_linear_srgb, lab_to_linear_srgb_f32,
    linear_srgb_to_oklab_lanes, oklab_to_linear_srgb_lanes, srgb_encode_f32_with, srgb_encode_fast,
    srgb_encode_unit_f32, ENCODE_TABLE_F32_LEN,
};
use super::ColourSpace;

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

    /// [`GamutMapping::apply_to_all`], inlined into each compilation of it.
    #[inline(always)]
    pub(crate) fn apply_to_all_inlined(self, colours: &mut [[f64; 3]]) {
        if self == GamutMapping::Clip {
            colours.iter_mut().for_each(|c| *c = self.apply(*c));
            return;
        }
        // Only colours outside take lanes: one inside would idle in its lane while the others
        // search.
        let mut group = [0; GAMUT_LANES];
        let mut n = 0;
        for i in 0..colours.len() {
            if in_gamut(colours[i], 0.0) {
                continue;
            }
            group[n] = i;
            n += 1;
            if n == GAMUT_LANES {
                let mapped = self.apply_lanes(group.map(|i| colours[i]));
                for (&i, c) in group.iter().zip(mapped) {
                    colours[i] = c;
                }
                n = 0;
            }
        }
        for &i in &group[..n] {
            colours[i] = self.apply(colours[i]);
        }
    }

    /// [`GamutMapping::apply`] of `N` colours at once, with the same bits for each. The chroma
    /// search runs in lanes (see [`reduce_chroma_lanes`]): its divisions and square roots
    /// overlap, and its decisions are selections rather than branches the processor guesses.
    #[inline(always)]
    pub(crate) fn apply_lanes<const N: usize>(self, rgb: [[f64; 3]; N]) -> [[f64; 3]; N] {
        match self {
            GamutMapping::Clip => rgb.map(|c| self.apply(c)),
            GamutMapping::Chroma => {
                let mut channels = [[0.0; N]; 3];
                for (i, c) in rgb.iter().enumerate() {
                    for k in 0..3 {
                        channels[k][i] = c[k];
                    }
                }
                let mapped = reduce_chroma_lanes(channels);
                let mut out = rgb;
                for (i, c) in out.iter_mut().enumerate() {
                    if !in_gamut(*c, 0.0) {
                        *c = [mapped[0][i], mapped[1][i], mapped[2][i]];
                    }
                }
                out
            }
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
    // sRGB-encoded colours in range blended in sRGB: decoding, the (identity) gamut mapping and
    // encoding again give the colour back.
    if space == ColourSpace::Srgb
        && blend == BlendSpace::Srgb
        && c.iter().all(|v| (0.0..=1.0).contains(v))
    {
        return c;
    }
    let lin = match space {
        ColourSpace::Lab => lab_to_linear_srgb(c),
        _ => space.to_linear_srgb(c),
    };
    let lin = gamut.apply(lin);
    match blend {
        BlendSpace::Linear => lin,
        BlendSpace::Srgb => lin.map(srgb_encode_fast),
    }
}

/// [`to_blend_space`] in single precision: Lab and sRGB colours inside the gamut (most pixels)
/// stay in `f32`, with the table of
/// [`srgb_encode_f32`](crate::colour::fast::srgb_encode_f32); every other colour goes through
/// [`to_blend_space`]. Single precision keeps about 7 digits, far below a 16-bit output step.
/// The per-pixel loop converts Lab colours in runs with [`RunConverter`], which gives the
/// same bits.
#[inline(always)]
pub(crate) fn to_blend_space_f32(
    space: ColourSpace,
    c: [f32; 3],
    gamut: GamutMapping,
    blend: BlendSpace,
) -> [f32; 3] {
    // sRGB in range, blended in sRGB (as the `vs_cairo` scene): inline, nothing to do.
    if space == ColourSpace::Srgb && blend == BlendSpace::Srgb && in_unit(&c) {
        return c;
    }
    to_blend_space_f32_converted(space, c, gamut, blend)
}

/// [`to_blend_space_f32`] when the colour needs converting.
#[inline(never)]
fn to_blend_space_f32_converted(
    space: ColourSpace,
    c: [f32; 3],
    gamut: GamutMapping,
    blend: BlendSpace,
) -> [f32; 3] {
    if space == ColourSpace::Lab {
        let lin = lab_to_linear_srgb_f32(lab_matrix_f32(), c);
        if in_unit(&lin) {
            return linear_to_blend_space_f32(encode_table_f32(), lin, blend);
        }
    }
    to_blend_space_in_f64(space, c, gamut, blend)
}

/// Whether every channel lies in `0..=1`.
#[inline(always)]
fn in_unit(v: &[f32; 3]) -> bool {
    v.iter().all(|x| (0.0..=1.0).contains(x))
}

/// An in-gamut linear-light colour in the blend space, with the encoding `table`
/// ([`encode_table_f32`]).
#[inline(always)]
fn linear_to_blend_space_f32(table: &[f32], lin: [f32; 3], blend: BlendSpace) -> [f32; 3] {
    // Written out: `array::map` with a closure stayed a chain of calls here.
    let encode = |v| srgb_encode_f32_with(table, v);
    match blend {
        BlendSpace::Linear => lin,
        BlendSpace::Srgb => [encode(lin[0]), encode(lin[1]), encode(lin[2])],
    }
}

/// [`to_blend_space`] of a single-precision colour.
fn to_blend_space_in_f64(
    space: ColourSpace,
    c: [f32; 3],
    gamut: GamutMapping,
    blend: BlendSpace,
) -> [f32; 3] {
    let double = to_blend_space(space, [c[0] as f64, c[1] as f64, c[2] as f64], gamut, blend);
    [double[0] as f32, double[1] as f32, double[2] as f32]
}

/// Colours per run of [`RunConverter::convert`].
pub(crate) const RUN: usize = 64;
// `RunConverter::convert` keeps indices into a run in bytes.
const _: () = assert!(RUN <= 256);

/// [`to_blend_space_f32`] for runs of up to [`RUN`] colours of one layer, with the same bits:
/// the colours come as one array per channel, so that the Lab part is a loop over whole
/// arrays the compiler turns into vector instructions, and the tables are looked up once per
/// run instead of once per pixel.
pub(crate) struct RunConverter {
    space: ColourSpace,
    gamut: GamutMapping,
    blend: BlendSpace,
    matrix: &'static [[f32; 3]; 3],
    table: &'static [f32; ENCODE_TABLE_F32_LEN],
    branch_free: bool,
}

impl RunConverter {
    /// `branch_free`: encode for the blend space with [`srgb_encode_unit_f32`] over the whole
    /// run rather than colour by colour (same bits). Faster where the code is compiled for
    /// AVX2, slower on the x86-64 baseline.
    pub fn new(
        space: ColourSpace,
        gamut: GamutMapping,
        blend: BlendSpace,
        branch_free: bool,
    ) -> RunConverter {
        RunConverter {
            space,
            gamut,
            blend,
            matrix: lab_matrix_f32(),
            table: encode_table_f32(),
            branch_free,
        }
    }

    /// Converts the first `n` colours of `c` (channel `k` of colour `m` at `c[k][m]`) into
    /// `out[m]`.
    // Always inlined: see `render::composite::wide_vectors`.
    #[inline(always)]
    pub fn convert(&self, c: &[[f32; RUN]; 3], n: usize, out: &mut [[f32; 3]; RUN]) {
        let n = n.min(RUN);
        if self.space != ColourSpace::Lab {
            for m in 0..n {
                let colour = [c[0][m], c[1][m], c[2][m]];
                out[m] = to_blend_space_f32(self.space, colour, self.gamut, self.blend);
            }
            return;
        }
        // Every lane, used or not: a fixed trip count over whole arrays vectorises.
        let mut lin = [[0.0f32; RUN]; 3];
        for m in 0..RUN {
            let l = lab_to_linear_srgb_f32(self.matrix, [c[0][m], c[1][m], c[2][m]]);
            for k in 0..3 {
                lin[k][m] = l[k];
            }
        }
        // Encoded for the blend space by lanes, without branches (vectorised), or else below
        // colour by colour.
        let by_lanes = self.branch_free && self.blend == BlendSpace::Srgb;
        let mut encoded = lin;
        if by_lanes {
            for channel in &mut encoded {
                for v in channel[..n].iter_mut() {
                    *v = srgb_encode_unit_f32(self.table, *v);
                }
            }
            // Most runs lie wholly inside the gamut: their colours are then their encodings,
            // without a test and a branch per colour. `fold` with `&`: it vectorises.
            let unit = |v: f32| (0.0..=1.0).contains(&v);
            let inside = (0..n).fold(true, |all, m| {
                all & unit(lin[0][m]) & unit(lin[1][m]) & unit(lin[2][m])
            });
            if inside {
                for (m, o) in out[..n].iter_mut().enumerate() {
                    *o = [encoded[0][m], encoded[1][m], encoded[2][m]];
                }
                return;
            }
        }
        // Colours outside the gamut in single precision, converted after the loop.
        let mut outside = [0u8; RUN];
        let mut outside_count = 0;
        for m in 0..n {
            let l = [lin[0][m], lin[1][m], lin[2][m]];
            if in_unit(&l) {
                let e = if by_lanes {
                    [encoded[0][m], encoded[1][m], encoded[2][m]]
                } else {
                    linear_to_blend_space_f32(self.table, l, self.blend)
                };
                // Each channel stored on its own: a colour returned through a temporary was
                // copied out with a load wider than its stores, which stalled every pixel.
                out[m].copy_from_slice(&e);
            } else {
                outside[outside_count] = m as u8;
                outside_count += 1;
            }
        }
        if outside_count > 0 {
            self.convert_outside(c, &outside[..outside_count], out);
        }
    }

    /// [`to_blend_space_in_f64`] of the Lab colours `c[..][m]` for each `m` in `indices`, into
    /// `out[m]`: in double precision, and gamut-mapped many colours at a time.
    #[inline(always)]
    fn convert_outside(&self, c: &[[f32; RUN]; 3], indices: &[u8], out: &mut [[f32; 3]; RUN]) {
        // Groups of `GAMUT_LANES` where there are many colours (sixteen lanes overlap the
        // search's chains of divisions better than eight or four), of four for the few left.
        let mut full = indices.chunks_exact(GAMUT_LANES);
        for group in &mut full {
            self.convert_outside_group::<GAMUT_LANES>(c, group, out);
        }
        for group in full.remainder().chunks(4) {
            self.convert_outside_group::<4>(c, group, out);
        }
    }

    /// [`RunConverter::convert_outside`] of at most `N` colours.
    #[inline(always)]
    fn convert_outside_group<const N: usize>(
        &self,
        c: &[[f32; RUN]; 3],
        indices: &[u8],
        out: &mut [[f32; 3]; RUN],
    ) {
        // Unused lanes hold mid grey, which is inside and costs the search nothing.
        let mut lin = [[0.5; 3]; N];
        for (l, &m) in lin.iter_mut().zip(indices) {
            let m = usize::from(m);
            *l = lab_to_linear_srgb([c[0][m], c[1][m], c[2][m]].map(f64::from));
        }
        let mapped = self.gamut.apply_lanes(lin);
        for (&m, rgb) in indices.iter().zip(mapped) {
            out[usize::from(m)] = linear_to_blend_space_in_f64(rgb, self.blend);
        }
    }
}

/// A gamut-mapped linear-light colour in the blend space, in single precision: the end of
/// [`to_blend_space_in_f64`].
#[inline(always)]
fn linear_to_blend_space_in_f64(rgb: [f64; 3], blend: BlendSpace) -> [f32; 3] {
    let encoded = match blend {
        BlendSpace::Linear => rgb,
        BlendSpace::Srgb => rgb.map(srgb_encode_fast),
    };
    encoded.map(|v| v as f32)
}

/// [`to_blend_space_f32`], unless the colour needs the chroma search: then its linear-light
/// colour, for [`WaitingColours`].
#[inline(always)]
pub(crate) fn to_blend_space_f32_or_outside(
    space: ColourSpace,
    c: [f32; 3],
    gamut: GamutMapping,
    blend: BlendSpace,
) -> Result<[f32; 3], [f64; 3]> {
    if gamut == GamutMapping::Clip
        || space == ColourSpace::Lab
        || (space == ColourSpace::Srgb && blend == BlendSpace::Srgb && in_unit(&c))
    {
        return Ok(to_blend_space_f32(space, c, gamut, blend));
    }
    converted_or_outside(space, c, blend)
}

/// [`to_blend_space_in_f64`] of a colour of `space` (not Lab) under the chroma search, stopping
/// before the search: the colour in the blend space if it lies inside the gamut, else its
/// linear-light colour.
#[inline(never)]
fn converted_or_outside(
    space: ColourSpace,
    c: [f32; 3],
    blend: BlendSpace,
) -> Result<[f32; 3], [f64; 3]> {
    let lin = space.to_linear_srgb(c.map(f64::from));
    if in_gamut(lin, 0.0) {
        Ok(linear_to_blend_space_in_f64(lin, blend))
    } else {
        Err(lin)
    }
}

/// Colours of one layer's row waiting for the chroma search ([`to_blend_space_f32_or_outside`]),
/// which takes them [`GAMUT_LANES`] at a time: the pixels' indices, linear-light colours and
/// coverage. Room for a group and the colours of one more stretch of [`GAMUT_LANES`] pixels,
/// so that the pixel loop need not test for room.
pub(crate) struct WaitingColours {
    pixel: [usize; 2 * GAMUT_LANES],
    linear: [[f64; 3]; 2 * GAMUT_LANES],
    alpha: [f32; 2 * GAMUT_LANES],
    count: usize,
}

impl WaitingColours {
    pub fn new() -> WaitingColours {
        WaitingColours {
            pixel: [0; 2 * GAMUT_LANES],
            linear: [[0.0; 3]; 2 * GAMUT_LANES],
            alpha: [0.0; 2 * GAMUT_LANES],
            count: 0,
        }
    }

    /// Adds a colour. At most [`GAMUT_LANES`] may be added between calls of
    /// [`WaitingColours::map_group`].
    #[inline(always)]
    pub fn add(&mut self, pixel: usize, linear: [f64; 3], alpha: f32) {
        let k = self.count;
        (self.pixel[k], self.linear[k], self.alpha[k]) = (pixel, linear, alpha);
        self.count += 1;
    }

    /// Maps a group of [`GAMUT_LANES`] colours, if that many wait, and hands each to
    /// `put(pixel, colour in the blend space, alpha)`.
    #[inline(always)]
    pub fn map_group(
        &mut self,
        gamut: GamutMapping,
        blend: BlendSpace,
        mut put: impl FnMut(usize, [f32; 3], f32),
    ) {
        if self.count >= GAMUT_LANES {
            self.finish_group::<GAMUT_LANES>(0, gamut, blend, &mut put);
            let rest = GAMUT_LANES..self.count;
            self.pixel.copy_within(rest.clone(), 0);
            self.linear.copy_within(rest.clone(), 0);
            self.alpha.copy_within(rest, 0);
            self.count -= GAMUT_LANES;
        }
    }

    /// Maps every colour still waiting, four at a time, as [`WaitingColours::map_group`].
    #[inline(always)]
    pub fn map_rest(
        &mut self,
        gamut: GamutMapping,
        blend: BlendSpace,
        mut put: impl FnMut(usize, [f32; 3], f32),
    ) {
        self.map_group(gamut, blend, &mut put);
        for start in (0..self.count).step_by(4) {
            self.finish_group::<4>(start, gamut, blend, &mut put);
        }
        self.count = 0;
    }

    /// Maps colours `start .. start + N` (those of them waiting).
    #[inline(always)]
    fn finish_group<const N: usize>(
        &self,
        start: usize,
        gamut: GamutMapping,
        blend: BlendSpace,
        put: &mut impl FnMut(usize, [f32; 3], f32),
    ) {
        let end = (start + N).min(self.count);
        // Unused lanes hold mid grey, which is inside and costs the search nothing.
        let mut linear = [[0.5; 3]; N];
        linear[..end - start].copy_from_slice(&self.linear[start..end]);
        let mapped = gamut.apply_lanes(linear);
        for (k, rgb) in (start..end).zip(mapped) {
            put(
                self.pixel[k],
                linear_to_blend_space_in_f64(rgb, blend),
                self.alpha[k],
            );
        }
    }
}

fn in_gamut(rgb: [f64; 3], tolerance: f64) -> bool {
    rgb.iter()
        .all(|&v| (-tolerance..=1.0 + tolerance).contains(&v))
}

fn clip(rgb: [f64; 3]) -> [f64; 3] {
    rgb.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
}

/// CSS Color 4's chroma search ([`reduce_chroma_lanes`]) for one colour.
fn reduce_chroma(rgb: [f64; 3]) -> [f64; 3] {
    reduce_chroma_lanes(rgb.map(|v| [v])).map(|[v]| v)
}

/// Colours gamut-mapped together by [`RunConverter`] where a run has many outside the gamut:
/// four AVX2 vectors of double-precision lanes.
pub(crate) const GAMUT_LANES: usize = 16;

/// Each lane clamped to `0..=1`, NaN to 0.
#[inline(always)]
fn clip_lanes<const N: usize>(c: &[[f64; N]; 3]) -> [[f64; N]; 3] {
    // Loops rather than `map`, which was copied through memory here.
    let mut out = [[0.0; N]; 3];
    for k in 0..3 {
        for i in 0..N {
            let v = c[k][i];
            out[k][i] = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        }
    }
    out
}

/// The Oklab distance between `a` and `b`, lane by lane.
#[inline(always)]
fn delta_e_ok_lanes<const N: usize>(a: &[[f64; N]; 3], b: &[[f64; N]; 3]) -> [f64; N] {
    let mut out = [0.0; N];
    for i in 0..N {
        let d = [a[0][i] - b[0][i], a[1][i] - b[1][i], a[2][i] - b[2][i]];
        out[i] = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    }
    out
}

/// CSS Color 4's binary search for the largest chroma (at the colour's Oklab lightness and hue)
/// whose clipped version is within a just-noticeable difference of it, for `N` colours at once
/// (channels outermost). Every lane takes the steps it would take alone, with the same
/// arithmetic, so the result does not depend on its neighbours; the lanes only share the loop,
/// which runs until the last of them is found.
#[inline(always)]
fn reduce_chroma_lanes<const N: usize>(rgb: [[f64; N]; 3]) -> [[f64; N]; 3] {
    const JND: f64 = 0.02;
    const EPSILON: f64 = 1e-4;
    // Each lane's answer so far: the plain clip, unless the search below finds better.
    let mut clipped = clip_lanes(&rgb);
    // Lanes still searching.
    let mut searching = [true; N];
    let lab = linear_srgb_to_oklab_lanes(&rgb);
    let (mut ua, mut ub) = ([0.0; N], [0.0; N]);
    let mut max = [0.0; N];
    for i in 0..N {
        let l = lab[0][i];
        let chroma = lab[1][i].hypot(lab[2][i]);
        if !rgb.iter().all(|channel| channel[i].is_finite()) {
            searching[i] = false;
        } else if l >= 1.0 || l <= 0.0 {
            let v = if l >= 1.0 { 1.0 } else { 0.0 };
            for channel in &mut clipped {
                channel[i] = v;
            }
            searching[i] = false;
        } else if chroma == 0.0 {
            searching[i] = false;
        }
        (ua[i], ub[i], max[i]) = (lab[1][i] / chroma, lab[2][i] / chroma, chroma);
    }
    // The plain clip, when it is close enough already.
    let e = delta_e_ok_lanes(&linear_srgb_to_oklab_lanes(&clip_lanes(&rgb)), &lab);
    for i in 0..N {
        searching[i] &= e[i] >= JND;
    }
    let mut min = [0.0; N];
    let mut min_in_gamut = [true; N];
    loop {
        for i in 0..N {
            searching[i] &= max[i] - min[i] > EPSILON;
        }
        if !searching.contains(&true) {
            break;
        }
        let mut c = [0.0; N];
        let mut current = [[0.0; N]; 3];
        for i in 0..N {
            c[i] = 0.5 * (min[i] + max[i]);
            current[0][i] = lab[0][i];
            current[1][i] = c[i] * ua[i];
            current[2][i] = c[i] * ub[i];
        }
        let current_rgb = oklab_to_linear_srgb_lanes(&current);
        let current_clipped = clip_lanes(&current_rgb);
        // Inside while nothing outside was accepted: only the lower bound moves. Otherwise
        // the clipped candidate is measured; when no lane needs that (early steps, and most
        // steps of a lone colour), the cube roots are skipped.
        let mut measured = [false; N];
        for i in 0..N {
            let inside = (0..3).fold(true, |all, k| {
                all & (0.0..=1.0).contains(&current_rgb[k][i])
            });
            measured[i] = searching[i] & !(min_in_gamut[i] & inside);
        }
        let e = if measured.contains(&true) {
            delta_e_ok_lanes(&linear_srgb_to_oklab_lanes(&current_clipped), &current)
        } else {
            [0.0; N]
        };
        // Every lane's decision as selections (`&` on booleans, no early exit): branches on
        // them would go one way or the other at random.
        for i in 0..N {
            let (active, measured) = (searching[i], measured[i]);
            let raise = active & !measured;
            let close = e[i] < JND;
            for k in 0..3 {
                if measured {
                    clipped[k][i] = current_clipped[k][i];
                }
            }
            if active & (raise | close) {
                min[i] = c[i];
            }
            if measured & !close {
                max[i] = c[i];
            }
            min_in_gamut[i] &= !(measured & close);
            searching[i] = active & !(measured & close & (JND - e[i] < EPSILON));
        }
    }
    clipped
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Linear-light sRGB to Oklab (Ottosson 2020).
    fn linear_srgb_to_oklab(c: [f64; 3]) -> [f64; 3] {
        linear_srgb_to_oklab_lanes(&c.map(|v| [v])).map(|[v]| v)
    }

    #[test]
    fn single_precision_conversion_matches_double() {
        let blends = [BlendSpace::Srgb, BlendSpace::Linear];
        let mut worst = 0.0f64;
        for l in (0..=100).step_by(5) {
            for a in (-120..=120).step_by(12) {
                for b in (-120..=120).step_by(12) {
                    for blend in blends {
                        let c = [l as f64, a as f64, b as f64];
                        let double =
                            to_blend_space(ColourSpace::Lab, c, GamutMapping::Chroma, blend);
                        let single = to_blend_space_f32(
                            ColourSpace::Lab,
                            c.map(|v| v as f32),
                            GamutMapping::Chroma,
                            blend,
                        );
                        for k in 0..3 {
                            worst = worst.max((double[k] - single[k] as f64).abs());
                        }
                    }
                }
            }
        }
        assert!(worst < 5e-6, "worst {worst}");
    }

    /// The run converter gives the bits of the per-colour conversion, in every space and blend
    /// space, for colours inside and outside the gamut, and for partial runs.
    #[test]
    fn run_conversion_matches_single_colours() {
        let mut bits = crate::render::test_random(0x853c_49e6_748f_ea9b_u64);
        let mut next = || (bits() >> 11) as f32 / (1u64 << 53) as f32;
        let spaces = [
            ColourSpace::Lab,
            ColourSpace::Srgb,
            ColourSpace::SrgbLinear,
            ColourSpace::Oklab,
        ];
        for space in spaces {
            for blend in [BlendSpace::Srgb, BlendSpace::Linear] {
                for (gamut, n, branch_free) in [GamutMapping::Clip, GamutMapping::Chroma]
                    .into_iter()
                    .flat_map(|g| [RUN, 1, 17].map(|n| (g, n)))
                    .flat_map(|(g, n)| [false, true].map(|b| (g, n, b)))
                {
                    let convert = RunConverter::new(space, gamut, blend, branch_free);
                    {
                        let mut c = [[0.0f32; RUN]; 3];
                        for m in 0..RUN {
                            // Lab-sized values, and unit-sized ones (some just outside 0..1).
                            let colour = if space == ColourSpace::Lab {
                                [
                                    110.0 * next() - 5.0,
                                    260.0 * next() - 130.0,
                                    260.0 * next() - 130.0,
                                ]
                            } else {
                                [1.2 * next() - 0.1, 1.2 * next() - 0.1, 1.2 * next() - 0.1]
                            };
                            for k in 0..3 {
                                c[k][m] = colour[k];
                            }
                        }
                        let mut out = [[f32::NAN; 3]; RUN];
                        convert.convert(&c, n, &mut out);
                        for m in 0..n {
                            let one = to_blend_space_f32(
                                space,
                                [c[0][m], c[1][m], c[2][m]],
                                gamut,
                                blend,
                            );
                            assert_eq!(
                                out[m].map(f32::to_bits),
                                one.map(f32::to_bits),
                                "{space:?} {m}"
                            );
                        }
                        assert!(
                            out[n..].iter().flatten().all(|v| v.is_nan()),
                            "wrote past the run"
                        );
                    }
                }
            }
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

    #[test]
    fn chroma_search_in_lanes_is_lane_independent() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut colours = vec![];
        for _ in 0..20_000 {
            let lab = [
                120.0 * next() - 10.0,
                260.0 * next() - 130.0,
                260.0 * next() - 130.0,
            ];
            colours.push(ColourSpace::Lab.to_linear_srgb(lab));
        }
        colours.extend([
            [0.0; 3],
            [1.0; 3],
            [1.0, 1.0, 1.2],
            [f64::NAN, 0.5, 0.5],
            [f64::INFINITY, 0.0, 0.0],
            [-0.2, -0.1, -0.3],
            [0.5, 0.5, 0.5],
            [2.0, 2.0, 2.0],
        ]);
        for chunk in colours.chunks_exact(4) {
            let lanes = GamutMapping::Chroma.apply_lanes([chunk[0], chunk[1], chunk[2], chunk[3]]);
            for (c, l) in chunk.iter().zip(lanes) {
                let s = GamutMapping::Chroma.apply(*c);
                assert_eq!(s.map(f64::to_bits), l.map(f64::to_bits), "{c:?}");
                let one = GamutMapping::Chroma.apply_lanes([*c]);
                assert_eq!(s.map(f64::to_bits), one[0].map(f64::to_bits), "{c:?}");
            }
        }
    }

    /// Colours that wait for the chroma search ([`WaitingColours`]) come out as
    /// [`to_blend_space_f32`] gives them one by one, bit for bit, whatever the stretches and
    /// groups they wait in.
    #[test]
    fn waiting_colours_match_single_colours() {
        let mut bits = crate::render::test_random(0x2545_f491_4f6c_dd1d_u64);
        let mut next = || (bits() >> 11) as f32 / (1u64 << 53) as f32;
        for space in [
            ColourSpace::Srgb,
            ColourSpace::SrgbLinear,
            ColourSpace::Oklab,
        ] {
            for blend in [BlendSpace::Srgb, BlendSpace::Linear] {
                for gamut in [GamutMapping::Clip, GamutMapping::Chroma] {
                    // Runs of colours inside and outside, so that groups fill unevenly.
                    let colours: Vec<[f32; 3]> = (0..300)
                        .map(|i| {
                            let spread = if (i / 7) % 3 == 0 { 0.6 } else { 1.6 };
                            let mut c = [0.0; 3].map(|_| spread * (next() - 0.5));
                            if space != ColourSpace::Oklab {
                                c = c.map(|v| v + 0.5);
                            } else {
                                c[0] = c[0].abs() + 0.3;
                            }
                            c
                        })
                        .collect();
                    let mut out = vec![[f32::NAN; 3]; colours.len()];
                    let mut waiting = WaitingColours::new();
                    let mut outside = 0;
                    let mut put = |k: usize, rgb: [f32; 3], alpha: f32| {
                        assert_eq!(alpha, k as f32);
                        assert!(out[k][0].is_nan(), "colour {k} handed over twice");
                        out[k] = rgb;
                    };
                    for (start, stretch) in colours.chunks(GAMUT_LANES).enumerate() {
                        for (i, &c) in stretch.iter().enumerate() {
                            let k = start * GAMUT_LANES + i;
                            match to_blend_space_f32_or_outside(space, c, gamut, blend) {
                                Ok(rgb) => put(k, rgb, k as f32),
                                Err(linear) => {
                                    outside += 1;
                                    waiting.add(k, linear, k as f32)
                                }
                            }
                        }
                        waiting.map_group(gamut, blend, &mut put);
                    }
                    waiting.map_rest(gamut, blend, &mut put);
                    if gamut == GamutMapping::Chroma {
                        assert!(outside > 3 * GAMUT_LANES, "{space:?}: {outside} outside");
                    }
                    for (k, (&c, o)) in colours.iter().zip(&out).enumerate() {
                        let one = to_blend_space_f32(space, c, gamut, blend);
                        assert_eq!(o.map(f32::to_bits), one.map(f32::to_bits), "{space:?} {k}");
                    }
                }
            }
        }
    }
}
