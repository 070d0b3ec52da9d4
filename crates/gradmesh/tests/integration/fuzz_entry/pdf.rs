//! The PDF reader's fuzz entry points: whole files (`parse_pdf`), and shading streams wrapped
//! in a page whose shading dictionary the input's first bytes choose (`parse_pdf_shading`).

use gradmesh::formats::pdf::{self, PdfPicture};
use gradmesh::ColourSpace;

use super::{check_error, check_mesh, fuzz_limits};

/// Reads `data` as a PDF file (page 1): a picture that reads keeps the reader's guarantees
/// ([`check_picture`]), and its layers go through [`check_mesh`] at depth 1; an error has a
/// message.
pub fn parse_pdf(data: &[u8]) {
    match pdf::read_pdf(data, 1, &fuzz_limits()) {
        Ok(picture) => check_picture(&picture),
        Err(e) => check_error(&e),
    }
}

/// The shading dictionaries' choices: the input's first [`HEAD`] bytes pick one of each.
const TYPES: [u8; 2] = [6, 7];
const COORDINATE_BITS: [u32; 8] = [1, 2, 4, 8, 12, 16, 24, 32];
const COMPONENT_BITS: [u32; 6] = [1, 2, 4, 8, 12, 16];
const FLAG_BITS: [u32; 3] = [2, 4, 8];
/// Colour spaces (and functions) with their components' `Decode` ranges; object 6 is a type 4
/// function of one input and four outputs.
const SPACES: [(&str, &str); 7] = [
    ("/ColorSpace /DeviceRGB", "0 1 0 1 0 1"),
    ("/ColorSpace /DeviceGray", "0 1"),
    ("/ColorSpace /DeviceCMYK", "0 1 0 1 0 1 0 1"),
    ("/ColorSpace [/Lab << /WhitePoint [0.9642 1 0.8249] >>]", "0 100 -100 100 -100 100"),
    ("/ColorSpace [/Indexed /DeviceRGB 2 <FF000000FF000000FF>]", "0 3"),
    ("/ColorSpace [/Separation /Spot /DeviceCMYK 6 0 R]", "0 1"),
    (
        "/ColorSpace /DeviceRGB /Function << /FunctionType 2 /Domain [0 1] /C0 [1 0 0] /C1 [0 0 1] /N 2 >>",
        "0 1",
    ),
];
/// The bytes of an input that choose its shading dictionary.
const HEAD: usize = 5;

/// Wraps the bytes after the first [`HEAD`] of `data` as the stream of a type 6 or 7 shading
/// painted by `sh` on a page, with the dictionary the first bytes choose, and reads it as
/// [`parse_pdf`] does.
pub fn parse_pdf_shading(data: &[u8]) {
    let (head, stream) = data.split_at(data.len().min(HEAD));
    let pick = |k: usize, n: usize| head.get(k).map_or(0, |&b| b as usize % n);
    let (space, ranges) = SPACES[pick(4, SPACES.len())];
    let dict = format!(
        "/ShadingType {} {space} /BitsPerCoordinate {} /BitsPerComponent {} /BitsPerFlag {} \
         /Decode [-10 300 -10 300 {ranges}]",
        TYPES[pick(0, TYPES.len())],
        COORDINATE_BITS[pick(1, COORDINATE_BITS.len())],
        COMPONENT_BITS[pick(2, COMPONENT_BITS.len())],
        FLAG_BITS[pick(3, FLAG_BITS.len())],
    );
    parse_pdf(&page_with_shading(&dict, stream));
}

/// A one-page PDF file (300 x 300 points) painting the shading of `dict` and `data` (object
/// 5) with `sh`; object 6 is the type 4 tint transform `{ 0 exch dup 0.5 mul 0 }`.
pub fn page_with_shading(dict: &str, data: &[u8]) -> Vec<u8> {
    let objects = [
        b"<< /Type /Catalog /Pages 2 0 R >>".to_vec(),
        b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_vec(),
        b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 300 300] /Contents 4 0 R \
          /Resources << /Shading << /S0 5 0 R >> >> >>"
            .to_vec(),
        stream_object("", b"/S0 sh"),
        stream_object(dict, data),
        stream_object(
            "/FunctionType 4 /Domain [0 1] /Range [0 1 0 1 0 1 0 1]",
            b"{ 0 exch dup 0.5 mul 0 }",
        ),
    ];
    pdf_file(&objects)
}

/// A PDF file of `objects` (numbered from 1; object 1 the catalogue) with a correct
/// cross-reference table.
pub fn pdf_file(objects: &[Vec<u8>]) -> Vec<u8> {
    let mut out = b"%PDF-1.7\n".to_vec();
    let mut offsets = Vec::new();
    for (k, body) in objects.iter().enumerate() {
        offsets.push(out.len());
        out.extend(format!("{} 0 obj\n", k + 1).as_bytes());
        out.extend(body);
        out.extend(b"\nendobj\n");
    }
    let xref = out.len();
    out.extend(format!("xref\n0 {}\n0000000000 65535 f \n", objects.len() + 1).as_bytes());
    for o in offsets {
        out.extend(format!("{o:010} 00000 n \n").as_bytes());
    }
    let n = objects.len() + 1;
    out.extend(
        format!("trailer\n<< /Size {n} /Root 1 0 R >>\nstartxref\n{xref}\n%%EOF\n").as_bytes(),
    );
    out
}

/// A stream object of the dictionary entries `dict` and the data `data`.
pub fn stream_object(dict: &str, data: &[u8]) -> Vec<u8> {
    let mut s = format!("<< {dict} /Length {} >>\nstream\n", data.len()).into_bytes();
    s.extend(data);
    s.extend(b"\nendstream");
    s
}

/// The guarantees of [`pdf::read_pdf`]: a view of positive, finite size; every fill with at
/// least one patch, finite points and components (as many a corner as its colour takes),
/// colours and opacities in 0..1; and the document converted from it passes [`check_mesh`].
pub fn check_picture(picture: &PdfPicture) {
    let view = picture.view_rect();
    assert!(
        view.width() > 0.0
            && view.height() > 0.0
            && view.width().is_finite()
            && view.height().is_finite(),
        "view {view:?}"
    );
    let unit = |x: f64| (0.0..=1.0).contains(&x);
    for fill in &picture.fills {
        assert!(!fill.patches.is_empty(), "{}: no patch", fill.object);
        assert!(
            unit(fill.opacity),
            "{}: opacity {}",
            fill.object,
            fill.opacity
        );
        let components = 4 * fill.colour.corner_components();
        for (k, patch) in fill.patches.iter().enumerate() {
            let mut points = patch.points.iter().flatten();
            assert!(
                points.all(|p| p.x.is_finite() && p.y.is_finite()),
                "{}: patch {k}",
                fill.object
            );
            assert_eq!(
                patch.components.len(),
                components,
                "{}: patch {k}",
                fill.object
            );
            assert!(patch.components.iter().all(|c| c.is_finite()));
            for (u, v) in [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0)] {
                let colour = fill.srgb_at(patch, u, v);
                assert!(
                    colour.iter().all(|&c| unit(c)),
                    "{}: colour {colour:?}",
                    fill.object
                );
                assert!(unit(fill.opacity_at(k, u, v)));
            }
        }
    }
    let (doc, _warnings) = pdf::picture_to_document(picture, ColourSpace::Lab);
    assert_eq!(doc.layers.len(), picture.fills.len());
    for mesh in &doc.layers {
        check_mesh(mesh, 1);
    }
}
