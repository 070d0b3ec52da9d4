//! Rendering into numpy arrays (the interpreter released while it draws) and exporting PNG,
//! PDF and SVG files.

use std::borrow::Cow;
use std::path::PathBuf;

use gradmesh::export::{self, ExportOptions, PdfColour};
use gradmesh::formats;
use gradmesh::render::{self, OutputPixel, PngCompression, RenderOptions, View};
use gradmesh::{parse_css_colour, ColourSpace};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::mesh::{Document, Mesh};
use crate::{error, invalid, warn};

/// The document to draw: a `Document`, or a `Mesh` as a document of one layer.
fn document_of<'a>(obj: &'a Bound<'_, PyAny>) -> PyResult<Cow<'a, gradmesh::Document>> {
    if let Ok(doc) = obj.cast::<Document>() {
        return Ok(Cow::Borrowed(&doc.get().doc));
    }
    if let Ok(mesh) = obj.cast::<Mesh>() {
        let layers = vec![mesh.get().mesh.clone()];
        return Ok(Cow::Owned(gradmesh::Document::new(layers)));
    }
    Err(invalid(format!(
        "expected a gradmesh.Document or gradmesh.Mesh, not {}",
        obj.get_type().name()?
    )))
}

/// A background from a CSS colour string or (r, g, b[, a]) in 0..1 (sRGB).
fn background(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 4]> {
    if let Ok(text) = obj.extract::<String>() {
        let (rgb, alpha) = parse_css_colour(&text, ColourSpace::Srgb)
            .map_err(|e| invalid(format!("background: {text:?}: {e}")))?;
        return Ok([rgb[0], rgb[1], rgb[2], alpha]);
    }
    let values: Vec<f64> = obj.extract().map_err(|_| {
        invalid("background: expected a CSS colour string or (r, g, b[, a]) in 0..1")
    })?;
    match values[..] {
        [r, g, b] => Ok([r, g, b, 1.0]),
        [r, g, b, a] => Ok([r, g, b, a]),
        _ => Err(invalid(format!(
            "background: {} numbers, expected 3 or 4",
            values.len()
        ))),
    }
}

/// The picture's size and view, as the command line chooses them: without a view, the
/// document's bounds; without a size, one pixel per unit; one side derives the other.
fn frame(
    doc: &gradmesh::Document,
    width: Option<u32>,
    height: Option<u32>,
    view: Option<(f64, f64, f64, f64)>,
) -> PyResult<(u32, u32, View)> {
    let view = match view {
        Some((x0, y0, x1, y1)) => View::new(x0, y0, x1, y1),
        None => View::fit(doc, 0.0),
    };
    if !(view.width() > 0.0 && view.height() > 0.0) {
        return Err(invalid(format!(
            "view: x1 must exceed x0 and y1 must exceed y0, found ({}, {}, {}, {})",
            view.x0, view.y0, view.x1, view.y1
        )));
    }
    let aspect = view.width() / view.height();
    let side = |x: f64| (x.round().max(1.0)).min(u32::MAX as f64) as u32;
    let (w, h) = match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, side(w as f64 / aspect)),
        (None, Some(h)) => (side(h as f64 * aspect), h),
        (None, None) => (side(view.width()), side(view.height())),
    };
    Ok((w, h, view))
}

/// Renders `doc` into `out` (an existing array) or a new array, the interpreter released.
fn draw<'py, P: OutputPixel + numpy::Element + Default>(
    py: Python<'py>,
    doc: &gradmesh::Document,
    opts: &RenderOptions,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    opts.check().map_err(error)?;
    let (w, h) = (opts.width as usize, opts.height as usize);
    let Some(obj) = out else {
        let mut pixels = vec![P::default(); 4 * w * h];
        let info = py
            .detach(|| render::render_document_into(doc, opts, &mut pixels))
            .map_err(error)?;
        warn(py, &info.warnings)?;
        let array = Array3::from_shape_vec((h, w, 4), pixels).expect("4 channels a pixel");
        return Ok(array.into_pyarray(py).into_any());
    };
    let array = obj.cast::<PyArrayDyn<P>>().map_err(|_| {
        invalid(format!(
            "out: expected a numpy array of dtype {}",
            std::any::type_name::<P>()
        ))
    })?;
    if array.shape() != [h, w, 4] {
        return Err(invalid(format!(
            "out: shape {:?}, expected ({h}, {w}, 4)",
            array.shape()
        )));
    }
    let mut pixels = array
        .try_readwrite()
        .map_err(|e| invalid(format!("out: not writeable ({e})")))?;
    let slice = pixels
        .as_slice_mut()
        .map_err(|_| invalid("out: not C-contiguous"))?;
    let info = py
        .detach(|| render::render_document_into(doc, opts, slice))
        .map_err(error)?;
    drop(pixels);
    warn(py, &info.warnings)?;
    Ok(obj.clone())
}

/// Renders a document (or one mesh) into an (H, W, 4) RGBA array: straight alpha,
/// sRGB-encoded, uint8 (`bits=8`, dithered unless `dither=False`), uint16 (16) or float32
/// (32). `view` is (x0, y0, x1, y1) of the plane (y down); without it, the document's bounds.
/// Without `width` and `height`, one pixel per unit; one of them derives the other. `out`, an
/// existing C-contiguous array of that shape and dtype, is drawn into instead of a new one.
/// The interpreter is released while the picture is drawn.
#[pyfunction(name = "render")]
#[pyo3(signature = (doc, width=None, height=None, view=None, *, bits=8, background=None,
    dither=true, out=None))]
#[allow(clippy::too_many_arguments)]
pub fn render_picture<'py>(
    py: Python<'py>,
    doc: &Bound<'py, PyAny>,
    width: Option<u32>,
    height: Option<u32>,
    view: Option<(f64, f64, f64, f64)>,
    bits: u32,
    background: Option<&Bound<'py, PyAny>>,
    dither: bool,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let doc = document_of(doc)?;
    let opts = render_options(&doc, width, height, view, background, dither)?;
    match bits {
        8 => draw::<u8>(py, &doc, &opts, out),
        16 => draw::<u16>(py, &doc, &opts, out),
        32 => draw::<f32>(py, &doc, &opts, out),
        _ => Err(invalid(format!("bits: {bits}, expected 8, 16 or 32"))),
    }
}

fn render_options(
    doc: &gradmesh::Document,
    width: Option<u32>,
    height: Option<u32>,
    view: Option<(f64, f64, f64, f64)>,
    bg: Option<&Bound<'_, PyAny>>,
    dither: bool,
) -> PyResult<RenderOptions> {
    let (w, h, view) = frame(doc, width, height, view)?;
    let mut opts = RenderOptions::new(w, h, view);
    opts.background = bg.map(background).transpose()?;
    opts.dither = dither;
    Ok(opts)
}

/// Writes a document (or one mesh) to `path` as PNG (the render, `bits` 8 or 16), PDF
/// (tensor-product shadings, `pdf_colour` "srgb" or "lab") or SVG (mesh gradients over a PNG
/// fallback), chosen by the extension, with the size and view of `render`. `tolerance` is the
/// largest colour difference (ΔE00) of the PDF and SVG patches. The file is written atomically.
#[pyfunction(name = "export")]
#[pyo3(signature = (doc, path, width=None, height=None, view=None, *, bits=8, background=None,
    dither=true, tolerance=export::DEFAULT_TOLERANCE, pdf_colour="srgb", fallback=true))]
#[allow(clippy::too_many_arguments)]
pub fn export_file(
    py: Python<'_>,
    doc: &Bound<'_, PyAny>,
    path: PathBuf,
    width: Option<u32>,
    height: Option<u32>,
    view: Option<(f64, f64, f64, f64)>,
    bits: u32,
    background: Option<&Bound<'_, PyAny>>,
    dither: bool,
    tolerance: f64,
    pdf_colour: &str,
    fallback: bool,
) -> PyResult<()> {
    let doc = document_of(doc)?;
    let opts = render_options(&doc, width, height, view, background, dither)?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let (bytes, warnings) = match ext.as_deref() {
        Some("png") => png(py, &doc, &opts, bits)?,
        Some(kind @ ("pdf" | "svg")) => {
            let mut e = ExportOptions::new(opts.width, opts.height, opts.view);
            e.tolerance = tolerance;
            e.colour = match pdf_colour {
                "srgb" => PdfColour::Srgb,
                "lab" => PdfColour::Lab,
                _ => {
                    return Err(invalid(format!(
                        "pdf_colour: {pdf_colour:?}, expected \"srgb\" or \"lab\""
                    )))
                }
            };
            let made = py.detach(|| match kind {
                "pdf" => export::write_pdf(&doc, &e),
                _ => export::write_svg(&doc, &e, fallback),
            });
            let (bytes, info) = made.map_err(error)?;
            (bytes, info.warnings)
        }
        _ => {
            return Err(invalid(format!(
                "{}: expected a .png, .pdf or .svg path",
                path.display()
            )))
        }
    };
    warn(py, &warnings)?;
    formats::write_atomic(&path, &bytes).map_err(error)
}

/// The PNG file of a render at `bits` 8 or 16.
fn png(
    py: Python<'_>,
    doc: &gradmesh::Document,
    opts: &RenderOptions,
    bits: u32,
) -> PyResult<(Vec<u8>, Vec<gradmesh::Warning>)> {
    opts.check().map_err(error)?;
    let n = 4 * opts.width as usize * opts.height as usize;
    let (w, h) = (opts.width, opts.height);
    py.detach(|| {
        let mut bytes = Vec::new();
        let info = match bits {
            8 => {
                let mut pixels = vec![0u8; n];
                let info = render::render_document_into(doc, opts, &mut pixels)?;
                render::write_png_rgba8_with(&mut bytes, w, h, &pixels, PngCompression::Fast)?;
                info
            }
            16 => {
                let mut pixels = vec![0u16; n];
                let info = render::render_document_into(doc, opts, &mut pixels)?;
                render::write_png_rgba16(&mut bytes, w, h, &pixels)?;
                info
            }
            _ => {
                return Err(gradmesh::Error::new(gradmesh::ErrorKind::Invalid {
                    what: "bits".into(),
                    message: format!("{bits}: a PNG has 8 or 16"),
                }))
            }
        };
        Ok((bytes, info.warnings))
    })
    .map_err(error)
}
