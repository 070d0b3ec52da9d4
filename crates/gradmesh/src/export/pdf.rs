//! PDF output: one page, one type 7 (tensor-product patch) shading per layer, clipped to the
//! layer's outline, with a luminosity soft mask of a grey shading of the opacity when the
//! layer is not opaque.

use std::io::Write;

use flate2::write::ZlibEncoder;
use flate2::Compression;
use pdf_writer::types::MaskType;
use pdf_writer::writers::StreamShadingType;
use pdf_writer::{Content, Filter, Finish, Name, Pdf, Rect, Ref};

use super::split::{OutPatch, Target};
use super::surface::Curve;
use super::{layer_patches, ExportInfo, ExportLayer, ExportOptions, LayerPatches, PdfColour};
use crate::error::{Error, ErrorKind};
use crate::formats::pdf::POINT_ORDER;
use crate::formats::svg::FillRule;
use crate::mesh::Document;

/// The D65 white point, with Y = 1 as the format asks.
const D65: [f32; 3] = [0.9505, 1.0, 1.089];
/// The a* and b* range of the Lab space: the sRGB gamut reaches b* = -107.9, beyond the
/// default range of ±100.
const LAB_RANGE: [f32; 4] = [-128.0, 127.0, -128.0, 127.0];
/// The corners of a record's colours (c00, c03, c33, c30) among [`OutPatch`]'s corners
/// (`(0, 0)`, `(1, 0)`, `(1, 1)`, `(0, 1)` in `(u, v)`).
const CORNER_ORDER: [usize; 4] = [0, 3, 2, 1];

/// Points in a CSS pixel: 72 to the inch against 96.
pub const POINTS_PER_PIXEL: f64 = 0.75;

/// The document as a one-page PDF of the page size ([`ExportOptions::page_size_px`]) at 72
/// points to 96 CSS pixels (a 96 dpi rasterisation has the size of a render of the same
/// options), and what was written.
pub fn write_pdf(doc: &Document, opts: &ExportOptions) -> Result<(Vec<u8>, ExportInfo), Error> {
    write_pdf_picture(&ExportLayer::of_document(doc), opts)
}

/// [`write_pdf`] of a picture whose layers may be SVG mesh gradients written as they are
/// ([`ExportLayer::SvgMesh`]: their shadings in DeviceRGB, whatever [`ExportOptions::colour`]
/// says, since their colours are bilinear in sRGB).
pub fn write_pdf_picture(
    layers: &[ExportLayer],
    opts: &ExportOptions,
) -> Result<(Vec<u8>, ExportInfo), Error> {
    let target = match opts.colour {
        PdfColour::Lab => Target::Lab,
        PdfColour::Srgb => Target::Srgb,
    };
    let (layers, mut info) = layer_patches(layers, opts, target)?;
    let start = std::time::Instant::now();
    let bytes = pdf_bytes(&layers, opts, target)?;
    info.seconds += start.elapsed().as_secs_f64();
    Ok((bytes, info))
}

/// Ids handed out in order.
struct Ids(i32);

impl Ids {
    fn next(&mut self) -> Ref {
        self.0 += 1;
        Ref::new(self.0)
    }
}

/// The PDF file of `layers`.
fn pdf_bytes(
    layers: &[LayerPatches],
    opts: &ExportOptions,
    target: Target,
) -> Result<Vec<u8>, Error> {
    let mut pdf = Pdf::new();
    let mut ids = Ids(0);
    let (catalog, tree, page_id, content_id) = (ids.next(), ids.next(), ids.next(), ids.next());
    pdf.catalog(catalog).pages(tree);
    pdf.pages(tree).kids([page_id]).count(1);
    let (w, h) = (opts.width as f32, opts.height as f32);
    // The picture's pixels, and the page in points.
    let pixel_rect = Rect::new(0.0, 0.0, w, h);
    let (page_w, page_h) = opts.page_size_px();
    let (page_w, page_h) = (
        (page_w * POINTS_PER_PIXEL) as f32,
        (page_h * POINTS_PER_PIXEL) as f32,
    );
    let page_rect = Rect::new(0.0, 0.0, page_w, page_h);

    let mut content = Content::new();
    content.save_state();
    // Pixel coordinates: y down from the top edge.
    content.transform([page_w / w, 0.0, 0.0, -page_h / h, 0.0, page_h]);
    let mut shadings = Vec::new();
    let mut states = Vec::new();
    for (k, layer) in layers.iter().enumerate() {
        if layer.patches.is_empty() {
            continue;
        }
        let colour_name = format!("Sh{k}");
        let shading = ids.next();
        write_shading(
            &mut pdf,
            shading,
            &layer.patches,
            ShadingKind::Colour(layer.colour.unwrap_or(target)),
        )?;
        shadings.push((colour_name.clone(), shading));
        content.save_state();
        if layer.masked {
            let (alpha, form, state) = (ids.next(), ids.next(), ids.next());
            write_shading(&mut pdf, alpha, &layer.patches, ShadingKind::Opacity)?;
            let alpha_name = format!("Sa{k}");
            let mut mask = Content::new();
            mask.shading(Name(alpha_name.as_bytes()));
            let mask = mask.finish();
            let mut group = pdf.form_xobject(form, &mask);
            group.bbox(pixel_rect);
            group
                .resources()
                .shadings()
                .pair(Name(alpha_name.as_bytes()), alpha);
            group
                .group()
                .transparency()
                .isolated(true)
                .color_space()
                .device_gray();
            group.finish();
            let mut gs = pdf.ext_graphics(state);
            gs.soft_mask()
                .subtype(MaskType::Luminosity)
                .group(form)
                .backdrop([0.0]);
            gs.finish();
            let state_name = format!("Gs{k}");
            content.set_parameters(Name(state_name.as_bytes()));
            states.push((state_name, state));
        }
        clip_to(&mut content, &layer.outline, layer.clip_rule);
        content.shading(Name(colour_name.as_bytes()));
        content.restore_state();
    }
    content.restore_state();
    pdf.stream(content_id, &content.finish());

    let mut page = pdf.page(page_id);
    page.media_box(page_rect).parent(tree).contents(content_id);
    page.group().transparency().color_space().device_rgb();
    let mut resources = page.resources();
    let mut dict = resources.shadings();
    for (name, id) in &shadings {
        dict.pair(Name(name.as_bytes()), *id);
    }
    dict.finish();
    let mut dict = resources.ext_g_states();
    for (name, id) in &states {
        dict.pair(Name(name.as_bytes()), *id);
    }
    dict.finish();
    resources.finish();
    page.finish();
    Ok(pdf.finish())
}

/// Sets the clip to the loops of `outline`, inside by `rule` (a layer's own outline is
/// nonzero: its holes run the other way).
fn clip_to(content: &mut Content, outline: &[Vec<Curve>], rule: FillRule) {
    for curves in outline {
        let Some(first) = curves.first() else {
            continue;
        };
        content.move_to(first[0][0] as f32, first[0][1] as f32);
        for c in curves {
            content.cubic_to(
                c[1][0] as f32,
                c[1][1] as f32,
                c[2][0] as f32,
                c[2][1] as f32,
                c[3][0] as f32,
                c[3][1] as f32,
            );
        }
        content.close_path();
    }
    match rule {
        FillRule::NonZero => content.clip_nonzero(),
        FillRule::EvenOdd => content.clip_even_odd(),
    };
    content.end_path();
}

/// What a shading carries at the corners.
#[derive(Clone, Copy)]
enum ShadingKind {
    /// Colour in the target's space.
    Colour(Target),
    /// Opacity as grey.
    Opacity,
}

impl ShadingKind {
    /// The decode ranges of the components.
    fn ranges(self) -> Vec<[f64; 2]> {
        match self {
            ShadingKind::Colour(Target::Lab) => {
                vec![[0.0, 100.0], [-128.0, 127.0], [-128.0, 127.0]]
            }
            ShadingKind::Colour(Target::Srgb) => vec![[0.0, 1.0]; 3],
            ShadingKind::Opacity => vec![[0.0, 1.0]],
        }
    }

    /// The components of corner `c` of `p`.
    fn components(self, p: &OutPatch, c: usize) -> Vec<f64> {
        match self {
            ShadingKind::Colour(_) => p.colours[c].to_vec(),
            ShadingKind::Opacity => vec![p.opacity[c]],
        }
    }
}

/// Writes the type 7 shading of `patches` as object `id`.
fn write_shading(
    pdf: &mut Pdf,
    id: Ref,
    patches: &[OutPatch],
    kind: ShadingKind,
) -> Result<(), Error> {
    let (lo, hi) = coordinate_range(patches);
    // A step of at most 1/256 pixel.
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let bits: u32 = if extent <= 256.0 {
        16
    } else if extent <= 65536.0 {
        24
    } else {
        32
    };
    let ranges = kind.ranges();
    let data = records(patches, kind, &ranges, (lo, hi), bits);
    let compressed = compress(&data)?;
    let mut decode = vec![lo[0] as f32, hi[0] as f32, lo[1] as f32, hi[1] as f32];
    decode.extend(ranges.iter().flat_map(|r| [r[0] as f32, r[1] as f32]));
    let mut shading = pdf.stream_shading(id, &compressed);
    shading.filter(Filter::FlateDecode);
    shading.shading_type(StreamShadingType::TensorProductPatch);
    match kind {
        ShadingKind::Colour(Target::Lab) => shading.color_space().lab(D65, None, Some(LAB_RANGE)),
        ShadingKind::Colour(Target::Srgb) => shading.color_space().device_rgb(),
        ShadingKind::Opacity => shading.color_space().device_gray(),
    }
    shading
        .bits_per_coordinate(bits as i32)
        .bits_per_component(16)
        .bits_per_flag(8)
        .decode(decode);
    shading.finish();
    Ok(())
}

/// The box around every control point, widened to a pixel where it is thinner, and rounded
/// outward to what `f32` holds (the decode array's numbers).
fn coordinate_range(patches: &[OutPatch]) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in patches.iter().flat_map(|p| p.points.iter().flatten()) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    for k in 0..2 {
        if hi[k] - lo[k] < 1.0 {
            hi[k] = lo[k] + 1.0;
        }
        lo[k] = (lo[k] - 0.5).floor();
        hi[k] = (hi[k] + 0.5).ceil();
    }
    (lo, hi)
}

/// The patch records: an 8-bit flag (0: every point given), the 16 points of `bits` bits a
/// coordinate, and the four corners' 16-bit components, each record a whole number of bytes.
fn records(
    patches: &[OutPatch],
    kind: ShadingKind,
    ranges: &[[f64; 2]],
    (lo, hi): ([f64; 2], [f64; 2]),
    bits: u32,
) -> Vec<u8> {
    let per_record = 1 + 32 * bits as usize / 8 + 8 * ranges.len();
    let mut data = Vec::with_capacity(patches.len() * per_record);
    let coordinate_max = ((1u64 << bits) - 1) as f64;
    let quantise = |x: f64, a: f64, b: f64, max: f64| -> u64 {
        (((x - a) / (b - a)).clamp(0.0, 1.0) * max).round() as u64
    };
    for p in patches {
        data.push(0);
        for &(i, j) in &POINT_ORDER {
            let point = p.points[j][i];
            for k in 0..2 {
                let q = quantise(point[k], lo[k], hi[k], coordinate_max);
                data.extend_from_slice(&q.to_be_bytes()[8 - bits as usize / 8..]);
            }
        }
        for &c in &CORNER_ORDER {
            for (value, range) in kind.components(p, c).into_iter().zip(ranges) {
                let q = quantise(value, range[0], range[1], 65535.0) as u16;
                data.extend_from_slice(&q.to_be_bytes());
            }
        }
    }
    data
}

fn compress(data: &[u8]) -> Result<Vec<u8>, Error> {
    let mut encoder = ZlibEncoder::new(Vec::new(), Compression::default());
    encoder
        .write_all(data)
        .and_then(|_| encoder.finish())
        .map_err(|e| ErrorKind::Io(format!("cannot compress a shading: {e}")).into())
}
