//! Compositing: each band of rows draws every layer's triangles and outline into per-thread
//! buffers, converts colours to the blend space, composites the layers front to back and
//! encodes the pixels into the output.

use crate::colour::fast::srgb_encode_f32;
use std::ops::Range;

use crate::colour::ColourSpace;

use crate::colour::gamut::GamutMapping;
use crate::colour::gamut::{self, BlendSpace, RUN};
use crate::render::arrays::each4;
use crate::render::options::RenderOptions;
use crate::render::output::pixels as output;
use crate::render::output::pixels::OutputPixel;
use crate::render::raster::coverage;
use crate::render::raster::triangles;
use crate::render::tessellate::layer::{Clip, DrawableLayer, BAND};

/// Per-thread working buffers, fully reset by each band that uses them.
pub(crate) struct Scratch {
    attributes: Vec<[f32; 4]>,
    covered: Vec<bool>,
    /// Pixels of the band that layers above have made opaque (a byte each: the span loop
    /// tests it at random places, where the colour rows would miss the cache).
    opaque: Vec<bool>,
    accumulation: coverage::Accumulator,
    coverage: Vec<f32>,
    /// The same for a layer's clip outline.
    clip_accumulation: coverage::Accumulator,
    clip_coverage: Vec<f32>,
    /// The pixels of a run that a layer shows, before and after conversion to the blend space.
    run: Box<Run>,
    /// Premultiplied colour in the blend space. Single precision: compositing a few layers
    /// loses far less than a 16-bit step, and half the bytes keep a wide band in cache.
    colour: Vec<[f32; 4]>,
}

thread_local! {
    /// Each thread's scratch, kept between bands and renders: allocating it per rayon job
    /// (`for_each_init`) cost fresh pages, and so page faults, for every job.
    static SCRATCH: std::cell::Cell<Option<Scratch>> = const { std::cell::Cell::new(None) };
}

/// The widest rows whose scratch a thread keeps between bands and renders.
const KEEP_SCRATCH_MAX_WIDTH: usize = 8192;

impl Scratch {
    /// Runs `f` with this thread's scratch for rows `w` pixels wide.
    pub(crate) fn with<R>(w: usize, f: impl FnOnce(&mut Scratch) -> R) -> R {
        // Taken out of the slot while in use: a band that re-entered here (draw_band does not
        // call into rayon) or one that panicked leaves no half-used scratch behind.
        let kept = SCRATCH.with(|cell| cell.take());
        let mut scratch = match kept {
            Some(s) if s.accumulation.width() == w => s,
            _ => Scratch::new(w),
        };
        let r = f(&mut scratch);
        // Very wide images get a scratch for the band only: a thread keeps at most about
        // 7 MB between renders.
        if w <= KEEP_SCRATCH_MAX_WIDTH {
            SCRATCH.with(|cell| cell.set(Some(scratch)));
        }
        r
    }

    fn new(w: usize) -> Self {
        Scratch {
            attributes: vec![[0.0; 4]; w * BAND],
            covered: vec![false; w * BAND],
            opaque: vec![false; w * BAND],
            accumulation: coverage::Accumulator::new(w, BAND),
            coverage: vec![0.0; w],
            clip_accumulation: coverage::Accumulator::new(w, BAND),
            clip_coverage: vec![0.0; w],
            colour: vec![[0.0; 4]; w * BAND],
            run: Box::new(Run {
                colour: [[0.0; RUN]; 3],
                pixel: [0; RUN],
                alpha: [0.0; RUN],
                block: [false; RUN],
                rgb: [[0.0; 3]; RUN],
            }),
        }
    }
}

/// Up to [`RUN`] pixels of a row that one layer shows: their working-space colours (one array
/// per channel, for [`gamut::RunConverter`]), where they go, their opacity, and their colours
/// in the blend space.
struct Run {
    colour: [[f32; RUN]; 3],
    pixel: [u32; RUN],
    alpha: [f32; RUN],
    /// Whether a whole block ([`whole_block`]) starts at this entry: its pixels follow the
    /// first's, and their alpha is one (only the first entry's `pixel` is written).
    block: [bool; RUN],
    rgb: [[f32; 3]; RUN],
}

/// One band of the image to draw: columns `columns` of rows `index * BAND ..`, whose pixels
/// are `out` (the others are left as they are).
pub(crate) struct Band<'a, P> {
    /// Whether this is the x86-64-v3 compilation, whose vectors some loops are written for.
    pub(crate) wide: bool,
    pub(crate) index: usize,
    pub(crate) columns: Range<usize>,
    pub(crate) out: &'a mut [P],
    pub(crate) layers: &'a [&'a DrawableLayer],
    pub(crate) opts: &'a RenderOptions,
    pub(crate) background: Option<[f32; 4]>,
    /// Receives, per layer, the farthest an outline pixel's colour was taken from.
    pub(crate) reach: &'a mut [f64],
}

/// Draws every layer into a band. Inlined into the two compilations of
/// [`draw_band_dispatched`](crate::render::draw_band_dispatched), with the hot functions it calls: each step below is
/// `#[inline(always)]` so that it is compiled for the wide vectors too.
#[inline(always)]
pub(crate) fn draw_band<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
    let Band {
        wide,
        index: band,
        columns: Range { start: x0, end: x1 },
        out,
        layers,
        opts,
        background,
        reach,
    } = job;
    reach.fill(f64::NEG_INFINITY);
    let w = opts.width as usize;
    let rows = out.len() / (4 * w);
    let area = BandArea {
        width: w,
        y0: band * BAND,
        rows,
        x0,
        x1,
        // Every pixel is computed alone (its coverage's prefix sum from the layer's left end):
        // drawing some columns gives them the bits drawing all would.
        whole_rows: x0 == 0 && x1 == w,
    };
    let dither = opts.dither && P::DITHERED;
    let linear = opts.blend == BlendSpace::Linear;

    if layers.iter().all(|l| l.line_bins.get(band).is_empty())
        && fill_with_background(out, area, background, dither, linear)
    {
        return;
    }
    clear_band(s, area);

    // Front to back ("under"): a pixel that is already opaque is not evaluated again, and the
    // band stops once all of its pixels are.
    let mut opaque = 0usize;
    // Whether no layer above has drawn into the band: its pixels are then all clear.
    let mut fresh = true;
    for (li, layer) in layers.iter().enumerate().rev() {
        if opaque == (x1 - x0) * rows {
            break;
        }
        let Some((made_opaque, farthest)) =
            draw_layer::<P>(layer, band, area, opts, wide, fresh, s)
        else {
            continue;
        };
        opaque += made_opaque;
        fresh = false;
        reach[li] = farthest;
    }
    let colour = &mut s.colour[..w * rows];
    if let Some(bg) = background {
        put_background_under(colour, bg, area);
    }
    encode_band(out, colour, area, dither, linear);
}

/// The pixels of a band being drawn: columns `x0..x1` of `rows` rows from `y0`, in an image
/// `width` pixels wide.
#[derive(Clone, Copy)]
struct BandArea {
    width: usize,
    y0: usize,
    rows: usize,
    x0: usize,
    x1: usize,
    /// Whether the columns are the whole rows.
    whole_rows: bool,
}

/// Fills a band that no layer reaches (a canvas larger than the drawing) with the background:
/// one pixel, encoded once. Returns false, drawing nothing, when dithering would give each
/// pixel its own noise.
#[inline(always)]
fn fill_with_background<P: OutputPixel>(
    out: &mut [P],
    area: BandArea,
    background: Option<[f32; 4]>,
    dither: bool,
    linear: bool,
) -> bool {
    let rgba = straight_srgb::<P>(&background.unwrap_or([0.0; 4]), linear);
    if dither && !rgba.iter().all(|&v| v == 0.0 || v == 1.0) {
        return false;
    }
    let pixel = each4(|ch| P::encode(rgba[ch], 0.0));
    for row in out.chunks_exact_mut(4 * area.width) {
        for px in row[4 * area.x0..4 * area.x1].chunks_exact_mut(4) {
            px.copy_from_slice(&pixel);
        }
    }
    true
}

/// Clears the colour and opacity of the band's pixels.
#[inline(always)]
fn clear_band(s: &mut Scratch, area: BandArea) {
    let BandArea {
        width: w,
        rows,
        x0,
        x1,
        ..
    } = area;
    let colour = &mut s.colour[..w * rows];
    if area.whole_rows {
        // One call each (a loop per row was compiled into a slower inline fill).
        colour.fill([0.0; 4]);
        s.opaque[..w * rows].fill(false);
    } else {
        for r in 0..rows {
            colour[r * w + x0..r * w + x1].fill([0.0; 4]);
            s.opaque[r * w + x0..r * w + x1].fill(false);
        }
    }
}

/// Composites one layer under the band's colour. Returns how many pixels became opaque and
/// the farthest an outline pixel's colour was taken from, or `None` when the layer reaches
/// none of the band's pixels. `P`: see [`fill_triangles`].
#[inline(always)]
fn draw_layer<P: OutputPixel>(
    layer: &DrawableLayer,
    band: usize,
    area: BandArea,
    opts: &RenderOptions,
    wide: bool,
    fresh: bool,
    s: &mut Scratch,
) -> Option<(usize, f64)> {
    let BandArea {
        width: w,
        y0,
        rows,
        x0,
        x1,
        ..
    } = area;
    let lines = layer.line_bins.get(band);
    if lines.is_empty() {
        return None;
    }
    // Coverage is summed over the layer's columns `c0..c1`, and shown over `d0..d1`.
    let (c0, c1) = layer.columns;
    let (d0, d1) = (c0.max(x0), c1.min(x1));
    if d0 >= d1 {
        return None;
    }
    let shading = Shading::of_layer(layer, opts, wide);
    // Outline colours of a layer with quadratic sides are clamped as its triangles are.
    let farthest = std::cell::Cell::new(f64::NEG_INFINITY);
    let nearest = |p: [f64; 2]| {
        let (a, distance) = layer.nearest.attributes_and_distance_at(p)?;
        farthest.set(farthest.get().max(distance));
        Some(match layer.bounds {
            Some(b) => each4(|k| a[k].clamp(b[0][k], b[1][k])),
            None => a,
        })
    };
    fill_triangles::<P>(layer, band, area, d0..d1, s);
    for &li in lines {
        let line = &layer.lines[li as usize];
        // A line changes the cells from the one holding its left end: one right of the
        // columns drawn changes no sum they take.
        if !area.whole_rows && line.p0[0].min(line.p1[0]) >= d1 as f64 {
            continue;
        }
        s.accumulation.add(y0 as i64, rows, line);
    }
    if let Some(clip) = &layer.clip {
        accumulate_clip(clip, band, area, d1, &mut s.clip_accumulation);
    }
    let colour = &mut s.colour[..w * rows];
    let mut opaque = 0;
    for r in 0..rows {
        // Left of the layer's columns the accumulation is all zeros, so its prefix sums
        // may start there. Only columns `a..b` are covered at all.
        let (mut a, mut b) = s.accumulation.resolve(r, c0, d1, &mut s.coverage);
        if layer.covered_by_triangles {
            let covered = &s.covered[r * w + d0..r * w + d1];
            for (c, &inside) in s.coverage[d0..d1].iter_mut().zip(covered) {
                if inside {
                    *c = 1.0;
                }
            }
            (a, b) = (d0, d1);
        }
        let (a, b) = match &layer.clip {
            Some(clip) => {
                let cols = (c0.min(clip.columns.0), d1);
                let (ca, cb) = clip_row(
                    clip,
                    r,
                    cols,
                    &mut s.clip_accumulation,
                    &mut s.clip_coverage,
                );
                let (a, b) = (a.max(ca), b.min(cb));
                for (c, &k) in s.coverage[a.min(b)..b]
                    .iter_mut()
                    .zip(&s.clip_coverage[a.min(b)..b])
                {
                    *c = c.min(k);
                }
                (a, b.max(a))
            }
            None => (a, b),
        };
        // Bounds the loops below can see, so that they index without checks.
        let coverage = &s.coverage[..d1];
        let (a, b) = (a.max(d0), b.min(d1));
        let y = (y0 + r) as f64 + 0.5;
        let band = BandPixels {
            row: r * w,
            opaque: &mut s.opaque,
            covered: &s.covered,
            attributes: &s.attributes,
            run: &mut s.run,
            colour,
        };
        // Separate loops for the first layer, which has nothing to test and nothing to
        // read: the tests are a noticeable share of drawing.
        opaque += if fresh {
            shade_row::<true>(a..b, coverage, y, band, &nearest, &shading)
        } else {
            shade_row::<false>(a..b, coverage, y, band, &nearest, &shading)
        };
    }
    Some((opaque, farthest.get()))
}

/// Adds the lines of `clip` that cross band `band` (those that can change columns before `d1`)
/// to `acc`.
#[inline(always)]
fn accumulate_clip(
    clip: &Clip,
    band: usize,
    area: BandArea,
    d1: usize,
    acc: &mut coverage::Accumulator,
) {
    for &li in clip.line_bins.get(band) {
        let line = &clip.lines[li as usize];
        if !area.whole_rows && line.p0[0].min(line.p1[0]) >= d1 as f64 {
            continue;
        }
        acc.add(area.y0 as i64, area.rows, line);
    }
}

/// Resolves row `r` of a clip's accumulation over columns `cols` into `out` with the clip's
/// fill rule (clearing the row); returns the columns outside which the clip covers nothing.
#[inline(always)]
fn clip_row(
    clip: &Clip,
    r: usize,
    (c0, c1): (usize, usize),
    acc: &mut coverage::Accumulator,
    out: &mut [f32],
) -> (usize, usize) {
    if clip.even_odd {
        acc.resolve_with::<true>(r, c0, c1, out)
    } else {
        acc.resolve_with::<false>(r, c0, c1, out)
    }
}

/// Fills the attributes of the pixels in columns `cols` that the layer's triangles cover, and
/// marks them covered. Generic over the output pixel type `P` only so that each compilation
/// of [`draw_band`] gets its own copy of the span closure, which is then inlined into it (a
/// single copy called from all of them is not, and is compiled without the wide vectors).
#[allow(clippy::extra_unused_type_parameters)]
#[inline(always)]
fn fill_triangles<P: OutputPixel>(
    layer: &DrawableLayer,
    band: usize,
    area: BandArea,
    cols: Range<usize>,
    s: &mut Scratch,
) {
    let BandArea {
        width: w, y0, rows, ..
    } = area;
    let Range { start: d0, end: d1 } = cols;
    let bounds = layer.bounds.as_ref().unwrap_or(&triangles::UNBOUNDED);
    for r in 0..rows {
        s.covered[r * w + d0..r * w + d1].fill(false);
    }
    let mut cursor = layer.triangles.cursor();
    for &ti in layer.triangle_bins.get(band) {
        let t = cursor.get(ti as usize);
        if !area.whole_rows {
            let (a, b) = t.columns(w);
            if b <= d0 || a >= d1 {
                continue;
            }
        }
        let (r0, r1) = t.rows();
        let (j0, j1) = (r0.max(y0 as i64), r1.min((y0 + rows) as i64));
        t.for_each_span(j0..j1, w as i64, |j, a, b| {
            let (a, b) = ((a as usize).max(d0), (b as usize).min(d1));
            if a >= b {
                return;
            }
            let row = (j as usize - y0) * w;
            let y = j as f64 + 0.5;
            let span = row + a..row + b;
            t.fill_row(y, a as f64 + 0.5, &mut s.attributes[span.clone()], bounds);
            s.covered[span].fill(true);
        });
    }
}

/// Composites the premultiplied background `bg` under the band's colour.
#[inline(always)]
fn put_background_under(colour: &mut [[f32; 4]], bg: [f32; 4], area: BandArea) {
    for row in colour.chunks_exact_mut(area.width) {
        for dst in &mut row[area.x0..area.x1] {
            let keep = 1.0 - dst[3];
            if keep > 0.0 {
                for c in 0..4 {
                    dst[c] += bg[c] * keep;
                }
            }
        }
    }
}

/// Encodes the band's premultiplied colour into `out`: straight alpha, sRGB-encoded.
#[inline(always)]
fn encode_band<P: OutputPixel>(
    out: &mut [P],
    colour: &[[f32; 4]],
    area: BandArea,
    dither: bool,
    linear: bool,
) {
    let BandArea {
        width: w,
        y0,
        x0,
        x1,
        ..
    } = area;
    for (r, (row_out, row_colour)) in out
        .chunks_exact_mut(4 * w)
        .zip(colour.chunks_exact(w))
        .enumerate()
    {
        let y = (y0 + r) as u32;
        let (row_out, row_colour) = (&mut row_out[4 * x0..4 * x1], &row_colour[x0..x1]);
        let pixels = row_out.chunks_exact_mut(4).zip(row_colour);
        if dither && !linear {
            encode_row_dithered(row_out, row_colour, x0, y);
        } else if dither {
            for (x, (px, c)) in (x0..).zip(pixels) {
                let rgba = straight_srgb::<P>(c, linear);
                let noise = output::dither_noise(x as u32, y);
                for ch in 0..4 {
                    px[ch] = P::encode(rgba[ch], noise[ch]);
                }
            }
        } else if linear {
            for (px, c) in pixels {
                let rgba = straight_srgb::<P>(c, linear);
                for ch in 0..4 {
                    px[ch] = P::encode_plain(rgba[ch]);
                }
            }
        } else {
            encode_row_plain(row_out, row_colour);
        }
    }
}

/// Pixels per block of a row that [`encode_row_plain`] and [`encode_row_dithered`] encode at
/// once when all of them are opaque.
const BLOCK: usize = 8;

/// Whether the pixels of `block` (premultiplied colour) are all opaque: their straight colour is
/// then the colour itself. `fold` with `&` rather than `all`: without an early exit the test
/// vectorises.
#[inline(always)]
fn all_opaque(block: &[[f32; 4]; BLOCK]) -> bool {
    block.iter().fold(true, |all, c| all & (c[3] >= 1.0))
}

/// Splits a row into blocks of [`BLOCK`] pixels: calls `opaque(start, colour, out)` for each
/// whole block whose pixels are all opaque, and `one(i, colour, out)` for every other pixel
/// (`out`: the pixels' channels).
#[inline(always)]
fn for_each_block<P>(
    out: &mut [P],
    colour: &[[f32; 4]],
    mut opaque: impl FnMut(usize, &[[f32; 4]; BLOCK], &mut [P; 4 * BLOCK]),
    mut one: impl FnMut(usize, &[f32; 4], &mut [P]),
) {
    let mut out_blocks = out.chunks_exact_mut(4 * BLOCK);
    let mut colour_blocks = colour.chunks_exact(BLOCK);
    for (b, (dst, c)) in out_blocks.by_ref().zip(colour_blocks.by_ref()).enumerate() {
        let (dst, c): (&mut [P; 4 * BLOCK], &[[f32; 4]; BLOCK]) = (
            dst.try_into().expect("a whole block"),
            c.try_into().expect("a whole block"),
        );
        if all_opaque(c) {
            opaque(b * BLOCK, c, dst);
        } else {
            for (k, (px, c)) in dst.chunks_exact_mut(4).zip(c).enumerate() {
                one(b * BLOCK + k, c, px);
            }
        }
    }
    let start = colour.len() - colour_blocks.remainder().len();
    let pixels = out_blocks.into_remainder().chunks_exact_mut(4);
    for (k, (px, c)) in pixels.zip(colour_blocks.remainder()).enumerate() {
        one(start + k, c, px);
    }
}

/// Encodes a row of premultiplied sRGB-encoded colour without dither. Blocks of opaque pixels
/// (most of them) take a loop of fixed length without branches, which vectorises; the others
/// go pixel by pixel.
// Always inlined: see `wide_vectors`.
#[inline(always)]
fn encode_row_plain<P: OutputPixel>(out: &mut [P], colour: &[[f32; 4]]) {
    let opaque = |_: usize, c: &[[f32; 4]; BLOCK], dst: &mut [P; 4 * BLOCK]| {
        // Alpha, at least 1, encodes as 1.
        for (o, &v) in dst.iter_mut().zip(c.as_flattened()) {
            *o = P::encode_plain(if P::SATURATES { v } else { v.clamp(0.0, 1.0) });
        }
    };
    let one = |_: usize, c: &[f32; 4], px: &mut [P]| {
        let rgba = straight_srgb::<P>(c, false);
        for ch in 0..4 {
            px[ch] = P::encode_plain(rgba[ch]);
        }
    };
    for_each_block(out, colour, opaque, one);
}

/// [`encode_row_plain`] with dither noise, for the pixels of row `y` from column `x0`. In a
/// block of opaque pixels the hashes come first (64-bit, one at a time), then the noise
/// ([`output::dither_noise_block`]) and the encoding, which vectorise.
// Always inlined: see `wide_vectors`.
#[inline(always)]
fn encode_row_dithered<P: OutputPixel>(out: &mut [P], colour: &[[f32; 4]], x0: usize, y: u32) {
    let opaque = |start: usize, c: &[[f32; 4]; BLOCK], dst: &mut [P; 4 * BLOCK]| {
        let noise = output::dither_noise_block::<BLOCK, { 4 * BLOCK }>((x0 + start) as u32, y);
        // Alpha, at least 1, encodes as 1.
        for ((px, &v), &noise) in dst.iter_mut().zip(c.as_flattened()).zip(&noise) {
            let v = if P::SATURATES { v } else { v.clamp(0.0, 1.0) };
            *px = P::encode_branchless(v, noise);
        }
    };
    let one = |i: usize, c: &[f32; 4], px: &mut [P]| {
        let rgba = straight_srgb::<P>(c, false);
        let noise = output::dither_noise((x0 + i) as u32, y);
        for ch in 0..4 {
            px[ch] = P::encode(rgba[ch], noise[ch]);
        }
    };
    for_each_block(out, colour, opaque, one);
}

/// How one layer's attributes become colours of the blend space.
struct Shading {
    space: ColourSpace,
    converter: gamut::RunConverter,
    gamut: GamutMapping,
    blend: BlendSpace,
    /// Whether colours outside the gamut are rare enough to be mapped one by one, in the
    /// plain pixel loop (an sRGB layer blended in sRGB with colours in range).
    rarely_outside: bool,
}

impl Shading {
    /// How `layer` is shaded with `opts`; `wide`: in the x86-64-v3 compilation.
    #[inline(always)]
    fn of_layer(layer: &DrawableLayer, opts: &RenderOptions, wide: bool) -> Shading {
        Shading {
            space: layer.space,
            converter: gamut::RunConverter::new(layer.space, opts.gamut, opts.blend, wide),
            gamut: opts.gamut,
            blend: opts.blend,
            rarely_outside: layer.space == ColourSpace::Srgb
                && opts.blend == BlendSpace::Srgb
                && layer.colours_in_unit_range,
        }
    }
}

/// One row of a band's buffers, as a layer shades it.
struct BandPixels<'a> {
    /// The index of the row's first pixel in the band.
    row: usize,
    opaque: &'a mut [bool],
    covered: &'a [bool],
    attributes: &'a [[f32; 4]],
    run: &'a mut Run,
    colour: &'a mut [[f32; 4]],
}

/// Composites a layer under the band's colour in columns `cols` of one row, whose coverage is
/// `coverage` (indexed by column): the attributes its triangles filled in, or else the nearest
/// outline's (the sliver between the tessellation and the outline). `FRESH`: no layer has drawn
/// into the band yet. Returns how many pixels became opaque.
#[inline(always)]
fn shade_row<const FRESH: bool>(
    cols: Range<usize>,
    coverage: &[f32],
    y: f64,
    band: BandPixels<'_>,
    nearest: &impl Fn([f64; 2]) -> Option<[f32; 4]>,
    shading: &Shading,
) -> usize {
    let BandPixels {
        row,
        opaque,
        covered,
        attributes,
        run,
        colour,
    } = band;
    let mut made_opaque = 0;
    // Composites pixel `k`'s colour; 1 if it became opaque. The buffers are arguments, so
    // that the loops below may also write them directly.
    let put = |colour: &mut [[f32; 4]], opaque: &mut [bool], k: usize, rgb: [f32; 3], alpha| {
        if under(&mut colour[k], rgb, alpha, FRESH) {
            opaque[k] = true;
            1
        } else {
            0
        }
    };
    // The pixel's attributes and opacity, unless the layer leaves it alone.
    let shown = |i: usize, opaque: &[bool]| -> Option<([f32; 4], f32)> {
        let (cov, k) = (coverage[i], row + i);
        if cov == 0.0 || (!FRESH && opaque[k]) {
            return None;
        }
        let attr = if covered[k] {
            attributes[k]
        } else {
            nearest([i as f64 + 0.5, y])?
        };
        let alpha = cov * attr[3].clamp(0.0, 1.0);
        (alpha > 0.0).then_some((attr, alpha))
    };
    if shading.space == ColourSpace::Lab {
        // In runs: first the pixels this layer shows (whole blocks under nothing at once),
        // then their colours all at once (vectorised), then compositing.
        let gather = |j: usize, n: &mut usize, run: &mut Run, opaque: &[bool]| {
            if let Some((attr, alpha)) = shown(j, opaque) {
                for c in 0..3 {
                    run.colour[c][*n] = attr[c];
                }
                run.alpha[*n] = alpha;
                run.pixel[*n] = (row + j) as u32;
                run.block[*n] = false;
                *n += 1;
            }
        };
        let mut i = cols.start;
        while i < cols.end {
            let mut n = 0;
            while i < cols.end && n < RUN {
                if i + BLOCK > cols.end || n + BLOCK > RUN {
                    gather(i, &mut n, run, opaque);
                    i += 1;
                    continue;
                }
                let k = row + i;
                // A block that layers above have made opaque shows nothing of this one.
                if !FRESH && all_true(&opaque[k..]) {
                    i += BLOCK;
                    continue;
                }
                // A block under nothing: a fresh layer's, or one no layer above has drawn
                // into (compositing under a clear pixel gives what a fresh layer writes).
                // Whole, it is gathered at once; otherwise pixel by pixel, without testing
                // a block again from each of them.
                let under = (!FRESH).then(|| &colour[k..]);
                match whole_block(&coverage[i..], &covered[k..], &attributes[k..], under) {
                    Some(at) => {
                        for (m, a) in at.iter().enumerate() {
                            for c in 0..3 {
                                run.colour[c][n + m] = a[c];
                            }
                        }
                        run.pixel[n] = k as u32;
                        run.block[n] = true;
                        n += BLOCK;
                    }
                    None => {
                        for j in i..i + BLOCK {
                            gather(j, &mut n, run, opaque);
                        }
                    }
                }
                i += BLOCK;
            }
            shading.converter.convert(&run.colour, n, &mut run.rgb);
            let mut m = 0;
            while m < n {
                let k = run.pixel[m] as usize;
                if run.block[m] {
                    made_opaque += put_opaque_block(colour, opaque, k, &run.rgb[m..]);
                    m += BLOCK;
                } else {
                    made_opaque += put(colour, opaque, k, run.rgb[m], run.alpha[m]);
                    m += 1;
                }
            }
        }
    } else {
        // Pixel by pixel: the other spaces have no vector path, and gathering them into runs
        // costs more than it saves.
        let (gamut, blend) = (shading.gamut, shading.blend);
        if shading.rarely_outside {
            // Colours in range need nothing (SVG's, Cairo's), and the search below cost the
            // `vs_cairo` scene 8 % more time. One pixel:
            let one = |i: usize, opaque: &mut [bool], colour: &mut [[f32; 4]]| -> usize {
                let Some((attr, alpha)) = shown(i, opaque) else {
                    return 0;
                };
                let c = [attr[0], attr[1], attr[2]];
                let rgb = gamut::to_blend_space_f32(shading.space, c, gamut, blend);
                put(colour, opaque, row + i, rgb, alpha)
            };
            let mut i = cols.start;
            // Most blocks of a fresh layer's interior are whole ([`whole_block`]) and in range:
            // each pixel's colour is then its attributes with an alpha of one, copied without
            // branches (vectorised). The `vs_cairo` scene's drawing took a fifth less time.
            // The same holds under pixels no layer above has drawn into.
            while i + BLOCK <= cols.end {
                let k = row + i;
                // Hidden by layers above.
                if !FRESH && all_true(&opaque[k..]) {
                    i += BLOCK;
                    continue;
                }
                let under = (!FRESH).then(|| &colour[k..]);
                let whole = whole_block(&coverage[i..], &covered[k..], &attributes[k..], under)
                    .filter(|at| at.iter().fold(true, |all, a| all & in_unit_f32(a)));
                if let Some(at) = whole {
                    made_opaque += put_opaque_block(colour, opaque, k, at);
                } else {
                    for j in i..i + BLOCK {
                        made_opaque += one(j, opaque, colour);
                    }
                }
                i += BLOCK;
            }
            for j in i..cols.end {
                made_opaque += one(j, opaque, colour);
            }
            return made_opaque;
        }
        // Colours that need the chroma search wait, and take it many at a time. In stretches
        // of as many pixels as the search has lanes, so that the pixel loop need not test for
        // room.
        let mut waiting = gamut::WaitingColours::new();
        let mut start = cols.start;
        while start < cols.end {
            let end = (start + gamut::GAMUT_LANES).min(cols.end);
            for i in start..end {
                if let Some((attr, alpha)) = shown(i, opaque) {
                    let c = [attr[0], attr[1], attr[2]];
                    match gamut::to_blend_space_f32_or_outside(shading.space, c, gamut, blend) {
                        Ok(rgb) => made_opaque += put(colour, opaque, row + i, rgb, alpha),
                        Err(linear) => waiting.add(row + i, linear, alpha),
                    }
                }
            }
            waiting.map_group(gamut, blend, |k, rgb, alpha| {
                made_opaque += put(colour, opaque, k, rgb, alpha)
            });
            start = end;
        }
        waiting.map_rest(gamut, blend, |k, rgb, alpha| {
            made_opaque += put(colour, opaque, k, rgb, alpha)
        });
    }
    made_opaque
}

/// The attributes of the first [`BLOCK`] pixels of a row if all of them are whole: covered by
/// the outline and by triangles, opaque, and with nothing under them (the layer is the band's
/// first, or `under`, the band's colour there, is still clear: compositing under a clear pixel
/// gives what a first layer writes). The per-pixel loops would composite each of them with an
/// alpha of one.
#[inline(always)]
fn whole_block<'a>(
    coverage: &[f32],
    covered: &[bool],
    attributes: &'a [[f32; 4]],
    under: Option<&[[f32; 4]]>,
) -> Option<&'a [[f32; 4]; BLOCK]> {
    // `fold` with `&`: without an early exit the tests vectorise.
    if let Some(under) = under {
        let under: &[[f32; 4]; BLOCK] = under[..BLOCK].try_into().expect("a block");
        if !under.iter().fold(true, |all, c| all & (c[3] == 0.0)) {
            return None;
        }
    }
    let cov: &[f32; BLOCK] = coverage[..BLOCK].try_into().expect("a block");
    let cv: &[bool; BLOCK] = covered[..BLOCK].try_into().expect("a block");
    let at: &[[f32; 4]; BLOCK] = attributes[..BLOCK].try_into().expect("a block");
    let whole = (0..BLOCK).fold(true, |all, j| {
        all & (cov[j] == 1.0) & cv[j] & (at[j][3] >= 1.0)
    });
    whole.then_some(at)
}

/// Writes the first [`BLOCK`] colours of `rgb` (three channels or more) with an alpha of one
/// to the band's pixels from `k`, and marks them opaque: what `under` gives pixels under
/// nothing with an alpha of one, a block at once without branches (vectorised). Returns
/// [`BLOCK`], the pixels made opaque.
#[inline(always)]
fn put_opaque_block<const C: usize>(
    colour: &mut [[f32; 4]],
    opaque: &mut [bool],
    k: usize,
    rgb: &[[f32; C]],
) -> usize {
    for (dst, c) in colour[k..k + BLOCK].iter_mut().zip(&rgb[..BLOCK]) {
        *dst = [c[0], c[1], c[2], 1.0];
    }
    opaque[k..k + BLOCK].fill(true);
    BLOCK
}

/// Whether the first [`BLOCK`] flags of `flags` are all set.
#[inline(always)]
fn all_true(flags: &[bool]) -> bool {
    let block: &[bool; BLOCK] = flags[..BLOCK].try_into().expect("a block");
    block.iter().fold(true, |all, &f| all & f)
}

/// Whether the three colour channels of `a` lie in `0..=1`.
#[inline(always)]
fn in_unit_f32(a: &[f32; 4]) -> bool {
    (0.0..=1.0).contains(&a[0]) & (0.0..=1.0).contains(&a[1]) & (0.0..=1.0).contains(&a[2])
}

/// Composites `rgb` with coverage `alpha` under the premultiplied pixel `dst`, which is clear
/// when `fresh`; whether it is now opaque.
#[inline(always)]
fn under(dst: &mut [f32; 4], rgb: [f32; 3], alpha: f32, fresh: bool) -> bool {
    // a + (1 - a) is 1, but not always in floating point.
    let cover = |a: f32| if alpha >= 1.0 { 1.0 } else { a };
    if fresh {
        // The sum below with a clear pixel, bit for bit, without reading it.
        *dst = [rgb[0] * alpha, rgb[1] * alpha, rgb[2] * alpha, cover(alpha)];
    } else {
        let weight = alpha * (1.0 - dst[3]);
        for c in 0..3 {
            dst[c] += rgb[c] * weight;
        }
        dst[3] = cover(dst[3] + weight);
    }
    dst[3] >= 1.0
}

/// A premultiplied colour of the blend space as straight-alpha, sRGB-encoded channels, ready
/// for `P::encode` (clamped to `0..=1` unless that saturates by itself).
// Always inlined: called once per pixel from two loops, it was left as a call.
#[inline(always)]
fn straight_srgb<P: OutputPixel>(c: &[f32; 4], linear: bool) -> [f32; 4] {
    let a = c[3];
    if a.is_nan() || a <= 0.0 {
        return [0.0; 4];
    }
    // Opaque pixels (most of them) skip the division, which would be exact.
    let opaque = a >= 1.0;
    let mut out = [1.0f32; 4];
    for ch in 0..3 {
        let v = if opaque { c[ch] } else { c[ch] / a };
        out[ch] = if linear {
            srgb_encode_f32(v.clamp(0.0, 1.0))
        } else if P::SATURATES {
            v
        } else {
            v.clamp(0.0, 1.0)
        };
    }
    if !opaque {
        out[3] = a;
    }
    out
}

#[cfg(test)]
mod encode_tests {
    use super::*;

    /// A row of premultiplied colours: a block of opaque pixels (one above the range), a block
    /// with clear and translucent pixels, and five after the last whole block.
    fn row() -> Vec<[f32; 4]> {
        (0..2 * BLOCK + 5)
            .map(|i| {
                let alpha = match i {
                    9 => 0.5,
                    12 => 0.0,
                    18 => 0.25,
                    _ => 1.0,
                };
                let t = i as f32 / 21.0;
                let rgb = [t, 1.0 - t, if i == 3 { 1.2 } else { 0.5 * t }];
                [rgb[0] * alpha, rgb[1] * alpha, rgb[2] * alpha, alpha]
            })
            .collect()
    }

    fn plain_by_blocks_matches_pixels<P: OutputPixel + Default + PartialEq + std::fmt::Debug>() {
        let colour = row();
        let mut blocks = vec![P::default(); 4 * colour.len()];
        encode_row_plain(&mut blocks, &colour);
        let pixels: Vec<P> = colour
            .iter()
            .flat_map(|c| straight_srgb::<P>(c, false).map(P::encode_plain))
            .collect();
        assert_eq!(blocks, pixels);
    }

    /// Encoding a row by blocks gives the bits of encoding each pixel on its own.
    #[test]
    fn rows_encode_by_blocks_as_pixel_by_pixel() {
        plain_by_blocks_matches_pixels::<u8>();
        plain_by_blocks_matches_pixels::<u16>();
        let colour = row();
        let mut f = vec![0.0f32; 4 * colour.len()];
        encode_row_plain(&mut f, &colour);
        let expected: Vec<f32> = colour
            .iter()
            .flat_map(|c| straight_srgb::<f32>(c, false))
            .collect();
        assert!(f
            .iter()
            .zip(&expected)
            .all(|(a, b)| a.to_bits() == b.to_bits()));

        let y = 7;
        let mut dithered = vec![0u8; 4 * colour.len()];
        encode_row_dithered(&mut dithered, &colour, 0, y);
        let expected: Vec<u8> = colour
            .iter()
            .enumerate()
            .flat_map(|(x, c)| {
                let (rgba, noise) = (
                    straight_srgb::<u8>(c, false),
                    output::dither_noise(x as u32, y),
                );
                each4(|ch| u8::encode(rgba[ch], noise[ch]))
            })
            .collect();
        assert_eq!(dithered, expected);
    }
}
