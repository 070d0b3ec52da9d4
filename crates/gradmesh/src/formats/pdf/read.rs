//! Reading a page of a PDF file: lopdf's objects, the page's content interpreted, its
//! patch-mesh shadings decoded into a [`PdfPicture`] (the `pdf-read` feature).

use std::path::Path;

use kurbo::{Affine, Rect};
use lopdf::{Dictionary, Document as LoDocument, LoadOptions, Object, ObjectId};

use super::content;
use super::is_pdf;
use super::objects::{invalid, object_name, Objects};
use super::picture_to_document;
use super::scene::PdfPicture;
use super::shading::ShadingLimits;
use crate::colour::ColourSpace;
use crate::error::{Error, Warning};
use crate::mesh::Document;
use crate::size_limits::Limits;

/// Reads page `page` (from 1) of the PDF file `bytes` within `limits`: the patches of one
/// page at most [`Limits::faces`], each stream decoded to at most [`Limits::input_bytes`].
pub fn read_pdf(bytes: &[u8], page: usize, limits: &Limits) -> Result<PdfPicture, Error> {
    crate::formats::check_size(bytes.len() as u64, limits.input_bytes)?;
    if !is_pdf(bytes) {
        return Err(invalid(
            "the file",
            "it is not a PDF file (no %PDF- header)",
        ));
    }
    let max_stream = usize::try_from(limits.input_bytes).unwrap_or(usize::MAX);
    let options = LoadOptions {
        max_decompressed_size: Some(max_stream),
        ..LoadOptions::default()
    };
    let doc = LoDocument::load_mem_with_options(bytes, options)
        .map_err(|e| invalid("the file", format!("it cannot be read as PDF: {e}")))?;
    if doc.trailer.get(b"Encrypt").is_ok() || doc.was_encrypted() {
        return Err(invalid(
            "the file",
            "it is encrypted; gradmesh reads only unencrypted PDF files",
        ));
    }
    let pages: Vec<ObjectId> = doc.page_iter().collect();
    if page == 0 || page > pages.len() {
        return Err(invalid(
            "the file",
            format!(
                "it has {} page{}; there is no page {page}",
                pages.len(),
                if pages.len() == 1 { "" } else { "s" }
            ),
        ));
    }
    let objects = Objects { doc: &doc };
    let page_id = pages[page - 1];
    let what = format!("page {page} ({})", object_name(page_id));
    let page_dict = doc
        .get_dictionary(page_id)
        .map_err(|e| invalid(&what, format!("it is not a dictionary: {e}")))?;
    let crop_box = page_box(objects, page_dict, &what)?;
    let mut warnings = Vec::new();
    let rotation = page_rotation(objects, page_dict, &what, &mut warnings)?;
    let resources = inherited(objects, page_dict, b"Resources", &what)?
        .map(|r| objects.dict(r, &format!("{what} /Resources")))
        .transpose()?;
    let data = page_content(objects, page_dict, &what, limits.input_bytes)?;
    let upright = Affine::new([1.0, 0.0, 0.0, -1.0, -crop_box.x0, crop_box.y1]);
    let to_picture = rotation_on_picture(rotation, crop_box) * upright;
    let mut interpreter = content::Interpreter::new(
        objects,
        ShadingLimits {
            patches: limits.faces,
            bytes: limits.input_bytes,
        },
    );
    interpreter.run(&data, &what, resources, to_picture, Vec::new())?;
    warnings.extend(interpreter.warnings());
    Ok(PdfPicture {
        page,
        pages: pages.len(),
        crop_box,
        rotation,
        fills: interpreter.fills,
        warnings,
    })
}

/// A PDF file's patch-mesh shadings as a document, with the part of the plane the page shows.
#[derive(Clone, Debug)]
pub struct PdfDocument {
    /// One layer per shading painted, bottom first.
    pub document: Document,
    /// What was left out or read approximately.
    pub warnings: Vec<Warning>,
    /// The picture the layers were converted from: `picture.fills[i]` for layer `i`.
    pub picture: PdfPicture,
}

/// Reads page `page` of the PDF (or `.ai`) file at `path` and converts its shadings into
/// layers with colours in Lab, within `limits`. A page without a type 6 or 7 shading is an
/// error. Every error is located in the file.
pub fn read_path_with_limits(
    path: &Path,
    page: usize,
    limits: &Limits,
) -> Result<PdfDocument, Error> {
    let located = |e: Error| e.in_file(path);
    let bytes = crate::formats::read_bytes(path, limits.input_bytes).map_err(located)?;
    let picture = read_pdf(&bytes, page, limits).map_err(located)?;
    if picture.fills.is_empty() {
        return Err(located(invalid(
            format!("page {page}"),
            "no shading of type 6 or 7 is painted on it",
        )));
    }
    let (document, warnings) = picture_to_document(&picture, ColourSpace::Lab);
    for (i, mesh) in document.layers.iter().enumerate() {
        limits
            .check_mesh(mesh)
            .map_err(|e| located(e.in_layer(i)))?;
    }
    Ok(PdfDocument {
        document,
        warnings,
        picture,
    })
}

/// The page's crop box (inherited, else the media box, clipped to the media box).
fn page_box(objects: Objects, page: &Dictionary, what: &str) -> Result<Rect, Error> {
    let read = |key: &[u8]| -> Result<Option<Rect>, Error> {
        let label = format!("{what} /{}", String::from_utf8_lossy(key));
        match inherited(objects, page, key, what)? {
            Some(o) => {
                let n = objects.numbers(o, &label)?;
                if n.len() != 4 {
                    return Err(invalid(label, "expected 4 numbers"));
                }
                Ok(Some(Rect::new(n[0], n[1], n[2], n[3]).abs()))
            }
            None => Ok(None),
        }
    };
    let media = read(b"MediaBox")?.ok_or_else(|| invalid(what, "the page has no MediaBox"))?;
    let crop = read(b"CropBox")?.map_or(media, |c| c.intersect(media));
    if crop.width() <= 0.0 || crop.height() <= 0.0 {
        return Err(invalid(what, "the page's crop box is empty"));
    }
    Ok(crop)
}

/// The page's `/Rotate` (inherited), as 0, 90, 180 or 270 degrees clockwise; a value that is
/// not a multiple of 90 is not applied (a warning says so), as poppler and MuPDF do.
fn page_rotation(
    objects: Objects,
    page: &Dictionary,
    what: &str,
    warnings: &mut Vec<String>,
) -> Result<u16, Error> {
    let Some(rotate) = inherited(objects, page, b"Rotate", what)? else {
        return Ok(0);
    };
    let degrees = objects.number(rotate, &format!("{what} /Rotate"))?;
    let turned = degrees.rem_euclid(360.0);
    if turned.rem_euclid(90.0) != 0.0 {
        warnings.push(format!(
            "{what}: /Rotate {degrees} is not a multiple of 90 and is not applied"
        ));
        return Ok(0);
    }
    Ok(turned as u16)
}

/// The picture of the upright page (the crop box `crop`, y down, its top-left corner at the
/// origin) turned `rotation` degrees clockwise, as viewers show a page with `/Rotate`, with
/// the turned picture's top-left corner at the origin.
fn rotation_on_picture(rotation: u16, crop: Rect) -> Affine {
    let (w, h) = (crop.width(), crop.height());
    match rotation {
        90 => Affine::new([0.0, 1.0, -1.0, 0.0, h, 0.0]),
        180 => Affine::new([-1.0, 0.0, 0.0, -1.0, w, h]),
        270 => Affine::new([0.0, -1.0, 1.0, 0.0, 0.0, w]),
        _ => Affine::IDENTITY,
    }
}

/// The entry `key` of the page, or of the nearest ancestor in the page tree that has it.
fn inherited<'a>(
    objects: Objects<'a>,
    page: &'a Dictionary,
    key: &[u8],
    what: &str,
) -> Result<Option<&'a Object>, Error> {
    let mut node = page;
    for _ in 0..64 {
        if let Some(o) = objects.get(node, key, what)? {
            return Ok(Some(o));
        }
        match objects.get(node, b"Parent", what)? {
            Some(parent) => node = objects.dict(parent, what)?,
            None => return Ok(None),
        }
    }
    Err(invalid(
        what,
        "the page tree is deeper than 64 levels, or loops",
    ))
}

/// The page's content streams, decoded and joined.
fn page_content(
    objects: Objects,
    page: &Dictionary,
    what: &str,
    max_bytes: u64,
) -> Result<Vec<u8>, Error> {
    let Some(contents) = objects.get(page, b"Contents", what)? else {
        return Ok(Vec::new());
    };
    let parts: Vec<&Object> = match contents {
        Object::Array(items) => items.iter().collect(),
        other => vec![other],
    };
    let mut data = Vec::new();
    for part in parts {
        let (resolved, id) = objects.resolve(part, what)?;
        let label = id.map_or_else(|| what.to_string(), object_name);
        let stream = objects.stream(resolved, &label)?;
        data.extend(objects.stream_data(stream, &label, max_bytes)?);
        data.push(b'\n');
        crate::formats::check_size(data.len() as u64, max_bytes)?;
    }
    Ok(data)
}
