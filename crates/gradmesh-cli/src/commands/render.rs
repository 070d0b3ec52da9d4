//! `gradmesh render`: the limit surface of every layer, to a PNG, a PDF or an SVG.

use std::time::Instant;

use gradmesh::export::{self, ExportOptions};
use gradmesh::formats;
use gradmesh::parse_css_colour;
use gradmesh::render::{
    self, LayerSource, PictureLayer, PngDepth, RenderOptions, SvgMeshRendering, View,
};
use gradmesh::{ColourSpace, Document, Error, ErrorKind, Warning, WarningKind};

use crate::args::RenderArgs;

use super::WarningReport;

fn invalid(what: &str, message: String) -> Error {
    Error::new(ErrorKind::Invalid {
        what: what.into(),
        message,
    })
}

/// Turns the flags into render options for `doc`. Without `--view`, the view is the first
/// input's viewport (an SVG file's view box) or else the document's bounds; without a size
/// either, the picture is that viewport's size in pixels, or one pixel per unit.
fn options(
    args: &RenderArgs,
    doc: &Document,
    viewport: Option<super::Viewport>,
) -> Result<RenderOptions, Error> {
    let view = match (&args.view, viewport) {
        (Some(v), _) => View::new(v[0], v[1], v[2], v[3]),
        (None, Some((view, _))) => view,
        (None, None) => View::fit(doc, 0.0),
    };
    if !(view.width() > 0.0 && view.height() > 0.0) {
        return Err(invalid(
            "--view",
            format!("X1 must exceed X0 and Y1 must exceed Y0, found {view:?}"),
        ));
    }
    let aspect = view.width() / view.height();
    let side = |x: f64| (x.round().max(1.0)).min(u32::MAX as f64) as u32;
    let (width, height) = match (args.width, args.height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, side(w as f64 / aspect)),
        (None, Some(h)) => (side(h as f64 * aspect), h),
        (None, None) => match (&args.view, viewport) {
            (None, Some((_, (w, h)))) => (side(w), side(h)),
            // One pixel per unit of the plane.
            _ => (side(view.width()), side(view.height())),
        },
    };
    let mut opts = RenderOptions::new(width, height, view);
    if let Some(bg) = &args.background {
        let (rgb, alpha) = parse_css_colour(bg, ColourSpace::Srgb)
            .map_err(|e| invalid("--background", format!("{bg:?}: {e}")))?;
        opts.background = Some([rgb[0], rgb[1], rgb[2], alpha]);
    }
    opts.colour_space_override = args.colour_space.map(Into::into);
    opts.gamut = args.gamut.into();
    opts.reference = args.reference;
    opts.level = args.level;
    opts.dither = !args.no_dither;
    opts.quadratic = !args.linear_colour;
    opts.max_pixels = args.max_pixels;
    Ok(opts)
}

/// What the output's extension asks for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Output {
    Png,
    Pdf,
    Svg,
}

fn output_kind(path: &std::path::Path) -> Option<Output> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "png" => Some(Output::Png),
        "pdf" => Some(Output::Pdf),
        "svg" => Some(Output::Svg),
        _ => None,
    }
}

pub fn run(args: &RenderArgs, report: &mut WarningReport) -> Result<(), Error> {
    let Some(kind) = output_kind(&args.output) else {
        return Err(invalid(
            "output",
            format!(
                "{}: render writes .png, .pdf or .svg",
                args.output.display()
            ),
        ));
    };
    let inputs: Vec<&std::path::Path> = args.inputs.iter().map(|p| p.as_path()).collect();
    super::check_not_input(&args.output, &inputs, args.force)?;

    // The thread pool starts while the files are read, rather than at the first parallel
    // step of the render.
    rayon::spawn(|| ());
    let start = Instant::now();
    let mut doc = Document::default();
    // For each layer of the document: the file it came from and its index there.
    let mut origins = Vec::new();
    let limits = args.limits.limits();
    let mut viewport = None;
    // For each layer: the SVG fill it was converted from, if any.
    let mut fills = Vec::new();
    // What the inputs left out, printed once it is known whether resvg draws it.
    let mut left_out = Vec::new();
    for (k, path) in args.inputs.iter().enumerate() {
        let read = super::read_with_viewport(path, &limits, args.page.page)?;
        if k == 0 {
            viewport = read.viewport;
        }
        left_out.push((path.as_path(), read.warnings));
        let layers = read.document.layers;
        origins.extend((0..layers.len()).map(|i| (path.as_path(), i)));
        match read.fills {
            Some(f) => fills.extend(f.into_iter().map(Some)),
            None => fills.extend(layers.iter().map(|_| None)),
        }
        doc.layers.extend(layers);
    }
    args.variant.apply(&mut doc);
    let read = start.elapsed();
    let locate = |mut e: Error| {
        if let Some(&(path, i)) = e.location.layer.and_then(|l| origins.get(l)) {
            e.location.layer = Some(i);
            e = e.in_file(path);
        }
        e
    };

    let opts = options(args, &doc, viewport)?;
    // A lone SVG input rendered to PNG is drawn whole: resvg draws what is not a mesh fill.
    let whole = kind == Output::Png
        && args.inputs.len() == 1
        && fills
            .iter()
            .any(|f| matches!(f, Some(super::ClassicFill::Svg(_))));
    if !whole {
        for (path, warnings) in left_out.iter_mut() {
            report.add(Some(*path), std::mem::take(warnings));
        }
    }
    if kind != Output::Png {
        let pdf = kind == Output::Pdf;
        // The page has the file's own size, not rounded to whole pixels, unless the flags
        // give a size or a view.
        let sized_by_flags = args.width.is_some() || args.height.is_some() || args.view.is_some();
        let page_px = viewport.filter(|_| !sized_by_flags).map(|(_, size)| size);
        let svg_mesh: SvgMeshRendering = args.svg_mesh.into();
        let classic = (svg_mesh == SvgMeshRendering::Classic).then_some(fills.as_slice());
        let output = VectorOutput {
            pdf,
            page_px,
            classic,
        };
        return vector(args, &doc, &opts, output, &origins, read, report).map_err(locate);
    }
    // The image's size and view are checked before its buffer is allocated.
    opts.check()?;
    let start = Instant::now();
    let channels = 4 * opts.width as usize * opts.height as usize;
    // Straight into the output's channel type, unless outlines are drawn on top (on the `f32`
    // image): an `f32` image is four times the memory of 8-bit output.
    let picture = picture_layers(&doc, &fills, args.svg_mesh.into());
    let picture = picture.as_deref();
    let whole_picture = match (whole, picture) {
        (true, Some(layers)) => {
            let path = &args.inputs[0];
            let text = std::fs::read_to_string(path)
                .map_err(|e| Error::new(ErrorKind::Io(format!("{}: {e}", path.display()))))?;
            let sixteen = args.bits == 16;
            let drawn = whole_svg_picture((path, &text), layers, &opts, (args.max_memory, sixteen))
                .map_err(|e| locate(e).in_file(path))?;
            report.add(Some(path), left_out_of(&mut left_out[0].1, drawn.is_ok()));
            if let Err(message) = &drawn {
                eprintln!(
                    "gradmesh: warning: {}: only the mesh fills are drawn: {message}",
                    path.display()
                );
            }
            drawn.ok()
        }
        _ => None,
    };
    let (pixels, info) = if let Some((picture, info)) = whole_picture {
        let pixels = whole_picture_pixels(picture);
        if !args.boundary {
            (pixels, info)
        } else {
            let mut image = pixels.into_float(&opts);
            render::draw_outlines(&doc, &opts, &mut image).map_err(locate)?;
            (Pixels::Float(image), info)
        }
    } else if args.boundary {
        let mut image = render::Image::new(opts.width, opts.height);
        let info = draw(&doc, picture, &opts, &mut image.data).map_err(locate)?;
        render::draw_outlines(&doc, &opts, &mut image).map_err(locate)?;
        (Pixels::Float(image), info)
    } else if args.bits == 16 {
        let mut data = vec![0u16; channels];
        let info = draw(&doc, picture, &opts, &mut data).map_err(locate)?;
        (Pixels::Sixteen(data), info)
    } else {
        let mut data = vec![0u8; channels];
        let info = draw(&doc, picture, &opts, &mut data).map_err(locate)?;
        (Pixels::Eight(data), info)
    };
    let rendered = start.elapsed();
    add_warnings(report, info.warnings, &origins);

    // Encoded straight into a temporary file (the PNG is never held in memory), which is
    // synced to disk and then replaces the output.
    let start = Instant::now();
    let (w, h) = (opts.width, opts.height);
    formats::write_atomic_streamed(&args.output, |out| {
        match &pixels {
            Pixels::Float(image) => {
                let depth = match args.bits {
                    16 => PngDepth::Sixteen,
                    _ => PngDepth::Eight {
                        dither: opts.dither,
                    },
                };
                render::write_png(out, image, depth)
            }
            Pixels::Sixteen(data) => render::write_png_rgba16(out, w, h, data),
            Pixels::Eight(data) => {
                render::write_png_rgba8_with(out, w, h, data, args.png_compression.into())
            }
        }
        .map_err(std::io::Error::other)
    })?;
    let written = start.elapsed();

    if args.timings {
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        eprintln!("read       {:9.2} ms", ms(read));
        eprintln!(
            "render     {:9.2} ms ({}x{})",
            ms(rendered),
            opts.width,
            opts.height
        );
        eprintln!("  prepare  {:9.2} ms", ms(info.timings.prepare));
        eprintln!("  draw     {:9.2} ms", ms(info.timings.draw));
        eprintln!(
            "write      {:9.2} ms (PNG encoded as it is written)",
            ms(written)
        );
        for (i, l) in info.layers.iter().enumerate() {
            eprintln!(
                "layer {i}: level {}{}, {} quads, {} triangles drawn; refine {:.2} ms, evaluate {:.2} ms, tessellate {:.2} ms",
                l.level,
                if l.capped { " (capped)" } else { "" },
                l.quads,
                l.triangles,
                ms(l.timings.refine),
                ms(l.timings.evaluate),
                ms(l.timings.tessellate),
            );
        }
    }
    Ok(())
}

/// The layers of the picture when an input is an SVG or PDF file (`fills[i]` is the fill
/// layer `i` of `doc` was converted from): its fills clipped to their shapes, drawn as `mode`
/// says, the other inputs' layers as they are. `None` when no input is an SVG or PDF file.
fn picture_layers<'a>(
    doc: &'a Document,
    fills: &'a [Option<super::ClassicFill>],
    mode: SvgMeshRendering,
) -> Option<Vec<PictureLayer<'a>>> {
    use super::ClassicFill;
    fills.iter().any(Option::is_some).then(|| {
        doc.layers
            .iter()
            .zip(fills)
            .map(|(mesh, fill)| {
                let mesh = std::slice::from_ref(mesh);
                match fill {
                    Some(ClassicFill::Svg(fill)) => {
                        render::svg_picture_layers(std::slice::from_ref(fill), mesh, mode).remove(0)
                    }
                    Some(ClassicFill::Pdf(fill)) => {
                        render::pdf_picture_layers(std::slice::from_ref(fill), mesh, mode).remove(0)
                    }
                    None => PictureLayer {
                        source: LayerSource::Scheme(&mesh[0]),
                        clip: None,
                    },
                }
            })
            .collect()
    })
}

/// What an SVG file's reading left out (`warnings`, emptied), except the content resvg drew
/// (`drawn`): what is not a mesh-gradient fill.
fn left_out_of(warnings: &mut Vec<Warning>, drawn: bool) -> Vec<Warning> {
    let mut warnings = std::mem::take(warnings);
    warnings.retain(|w| !(drawn && w.kind == WarningKind::SvgNotMeshFill));
    warnings
}

/// The picture that the whole SVG `text` draws, its mesh fills being `layers`: see
/// `whole_picture`, within `max_memory` bytes (default: the machine's memory).
/// `Ok(Err(message))` says why only the mesh fills are drawn.
#[cfg(feature = "svg-whole-picture")]
fn whole_svg_picture(
    file: (&std::path::Path, &str),
    layers: &[PictureLayer<'_>],
    opts: &RenderOptions,
    (max_memory, sixteen): (Option<u64>, bool),
) -> Result<Result<(WholePicture, render::RenderInfo), String>, Error> {
    let max_memory = max_memory.unwrap_or_else(machine_memory);
    for warning in gradmesh_svg_picture::missing_images(file) {
        eprintln!("gradmesh: warning: {}: {warning}", file.0.display());
    }
    gradmesh_svg_picture::render_whole_picture(file, layers, opts, (max_memory, sixteen))
}

#[cfg(feature = "svg-whole-picture")]
use gradmesh_svg_picture::WholePicture;

/// What the whole picture would be drawn as (never made without resvg).
#[cfg(not(feature = "svg-whole-picture"))]
#[allow(dead_code)]
enum WholePicture {
    Eight(Vec<u8>),
    Sixteen(Vec<u16>),
}

/// Without resvg, only the mesh fills of an SVG file are drawn.
#[cfg(not(feature = "svg-whole-picture"))]
fn whole_svg_picture(
    _file: (&std::path::Path, &str),
    _layers: &[PictureLayer<'_>],
    _opts: &RenderOptions,
    _max_memory: (Option<u64>, bool),
) -> Result<Result<(WholePicture, render::RenderInfo), String>, Error> {
    Ok(Err(
        "this gradmesh was built without resvg, which draws the rest (cargo feature \
         `svg-whole-picture`, on by default)"
            .into(),
    ))
}

/// Draws `picture` when there is one, else `doc`, into `out`.
fn draw<P: render::OutputPixel>(
    doc: &Document,
    picture: Option<&[PictureLayer<'_>]>,
    opts: &RenderOptions,
    out: &mut [P],
) -> Result<render::RenderInfo, Error> {
    match picture {
        Some(layers) => render::render_picture_into(layers, opts, out),
        None => render::render_document_into(doc, opts, out),
    }
}

/// What vector output is written: a PDF (`pdf`) or an SVG, with the page's size in CSS
/// pixels when it is not the render's, and the fills of the layers that an SVG file's meshes
/// were converted from, when they are written as they are.
struct VectorOutput<'a> {
    pdf: bool,
    page_px: Option<(f64, f64)>,
    classic: Option<&'a [Option<super::ClassicFill>]>,
}

/// Writes the document as a PDF or an SVG, with the page and view of `render`.
fn vector(
    args: &RenderArgs,
    doc: &Document,
    render: &RenderOptions,
    VectorOutput {
        pdf,
        page_px,
        classic,
    }: VectorOutput,
    origins: &[(&std::path::Path, usize)],
    read: std::time::Duration,
    report: &mut WarningReport,
) -> Result<(), Error> {
    warn_of_png_flags(args);
    let mut opts = ExportOptions::new(render.width, render.height, render.view);
    opts.page_px = page_px;
    opts.tolerance = args.tolerance;
    opts.geometry_tolerance_px = args.geometry_tolerance;
    opts.colour = args.pdf_colour.into();
    opts.limits = args.limits.limits();
    let start = Instant::now();
    let (bytes, info) = if pdf {
        export::write_pdf_picture(&export_layers(doc, classic), &opts)?
    } else {
        export::write_svg_picture(&export_layers(doc, classic), &opts, !args.no_fallback)?
    };
    let made = start.elapsed();
    add_warnings(report, info.warnings, origins);
    let start = Instant::now();
    formats::write_atomic(&args.output, &bytes)?;
    if args.timings {
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        eprintln!("read       {:9.2} ms", ms(read));
        let (page_w, page_h) = opts.page_size_px();
        let scale = if pdf { export::POINTS_PER_PIXEL } else { 1.0 };
        eprintln!(
            "export     {:9.2} ms ({:.2}x{:.2} {}, {} patches, {} bytes)",
            ms(made),
            page_w * scale,
            page_h * scale,
            if pdf { "pt" } else { "px" },
            info.patches,
            bytes.len()
        );
        eprintln!("write      {:9.2} ms", ms(start.elapsed()));
        eprintln!(
            "flat patches at irregular spots: {}, largest distance {:.4} px",
            info.approximated, info.geometry_error_px
        );
    }
    Ok(())
}

/// The layers of `doc` to export: a layer converted from an SVG mesh gradient as the
/// gradient's own patches when `classic` holds the fills, otherwise the scheme's.
fn export_layers<'a>(
    doc: &'a Document,
    classic: Option<&'a [Option<super::ClassicFill>]>,
) -> Vec<export::ExportLayer<'a>> {
    doc.layers
        .iter()
        .enumerate()
        .map(|(i, mesh)| match classic.and_then(|f| f[i].as_ref()) {
            Some(super::ClassicFill::Svg(fill)) => export::ExportLayer::SvgMesh(fill),
            _ => export::ExportLayer::Scheme(mesh),
        })
        .collect()
}

/// Warns of the flags given that only PNG output uses.
fn warn_of_png_flags(args: &RenderArgs) {
    let given = [
        (args.background.is_some(), "--background"),
        (args.bits != 8, "--bits"),
        (args.no_dither, "--no-dither"),
        (args.linear_colour, "--linear-colour"),
        (args.boundary, "--boundary"),
        (args.colour_space.is_some(), "--colour-space"),
        (
            !matches!(args.gamut, crate::args::GamutArg::Chroma),
            "--gamut",
        ),
        (args.reference, "--reference"),
        (args.level.is_some(), "--level"),
    ];
    let ignored: Vec<&str> = given
        .iter()
        .filter(|(given, _)| *given)
        .map(|(_, flag)| *flag)
        .collect();
    if !ignored.is_empty() {
        eprintln!(
            "gradmesh: warning: {}: {} only apply to PNG output: ignored",
            args.output.display(),
            ignored.join(", ")
        );
    }
}

/// Adds `warnings` (about layers of the document) to `report`, each about the file and layer
/// its layer came from (`origins`).
fn add_warnings(
    report: &mut WarningReport,
    warnings: Vec<Warning>,
    origins: &[(&std::path::Path, usize)],
) {
    for w in warnings {
        match w.layer.and_then(|l| origins.get(l)) {
            Some(&(path, i)) => report.add(
                Some(path),
                [Warning {
                    layer: Some(i),
                    ..w
                }],
            ),
            None => report.add(None, [w]),
        }
    }
}

/// The machine's memory in bytes (MemTotal in /proc/meminfo), or no limit where it is not
/// known.
#[cfg(feature = "svg-whole-picture")]
fn machine_memory() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
            let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(kib.saturating_mul(1024))
        })
        .unwrap_or(u64::MAX)
}

/// The rendered picture, in the type it was drawn in.
enum Pixels {
    Float(render::Image),
    Sixteen(Vec<u16>),
    Eight(Vec<u8>),
}

fn whole_picture_pixels(picture: WholePicture) -> Pixels {
    match picture {
        WholePicture::Eight(data) => Pixels::Eight(data),
        WholePicture::Sixteen(data) => Pixels::Sixteen(data),
    }
}

impl Pixels {
    /// The picture as an `f32` image of `opts`'s size (to draw outlines on).
    fn into_float(self, opts: &RenderOptions) -> render::Image {
        let data = match self {
            Pixels::Float(image) => return image,
            Pixels::Sixteen(data) => data.iter().map(|&v| f32::from(v) / 65535.0).collect(),
            Pixels::Eight(data) => data.iter().map(|&v| f32::from(v) / 255.0).collect(),
        };
        render::Image {
            width: opts.width,
            height: opts.height,
            data,
        }
    }
}
