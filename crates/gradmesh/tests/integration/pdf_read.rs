//! Reading PDF patch-mesh shadings, checked against a render of the same picture: gradmesh's
//! own PDF export read back against the render of the same document. Figures are CIEDE2000
//! over the mesh pixels (those a few pixels inside the outline of what gradmesh covers), on
//! white.

use std::path::Path;

use gradmesh::export::{write_pdf, ExportOptions, PdfColour};
use gradmesh::formats::{self, pdf};
use gradmesh::render::{
    pdf_picture_layers, render_image, render_picture_into, Image, RenderOptions, SvgMeshRendering,
    View,
};
use gradmesh::{ColourSpace, Limits};
use palette::color_difference::Ciede2000;
use palette::{white_point::D65, Lab};

use super::export::Raster;

/// Pixels this close to the covered area's edge are not mesh pixels.
const ERODE_PX: i64 = 3;

/// ΔE00 figures over the mesh pixels.
#[derive(Debug, Clone, Copy)]
struct Figures {
    mean: f64,
    p99: f64,
    pixels: usize,
}

/// The picture of `picture` drawn by gradmesh at `width` x `height` (on white when `white`).
fn render_pdf(picture: &pdf::PdfPicture, width: u32, height: u32, white: bool) -> Image {
    let (doc, _) = pdf::picture_to_document(picture, ColourSpace::Lab);
    let layers = pdf_picture_layers(&picture.fills, &doc.layers, SvgMeshRendering::Classic);
    let mut opts = RenderOptions::new(width, height, View::from_rect(picture.view_rect()));
    opts.dither = false;
    if white {
        opts.background = Some([1.0, 1.0, 1.0, 1.0]);
    }
    let mut image = Image::new(width, height);
    render_picture_into(&layers, &opts, &mut image.data).unwrap();
    image
}

/// Mesh pixels: covered fully by `alpha` in a window of [`ERODE_PX`] around.
fn mesh_pixels(alpha: &Image) -> Vec<bool> {
    let (w, h) = (alpha.width as i64, alpha.height as i64);
    let a = |x: i64, y: i64| alpha.data[4 * (y * w + x) as usize + 3];
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            (-ERODE_PX..=ERODE_PX).all(|dy| {
                (-ERODE_PX..=ERODE_PX).all(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..w).contains(&u) && (0..h).contains(&v) && a(u, v) >= 0.999
                })
            })
        })
        .collect()
}

fn figures(ours: &Raster, theirs: &Raster, inside: &[bool], name: &str) -> Figures {
    assert_eq!(
        (ours.width, ours.height),
        (theirs.width, theirs.height),
        "{name}: the pictures differ in size"
    );
    let lab = |c: [f64; 3]| Lab::<D65, f64>::new(c[0], c[1], c[2]);
    let mut errors: Vec<f64> = (0..inside.len())
        .filter(|&i| inside[i])
        .map(|i| lab(ours.lab(i)).difference(lab(theirs.lab(i))))
        .collect();
    assert!(
        errors.len() > 500,
        "{name}: only {} mesh pixels",
        errors.len()
    );
    errors.sort_by(f64::total_cmp);
    Figures {
        mean: errors.iter().sum::<f64>() / errors.len() as f64,
        p99: errors[((errors.len() - 1) as f64 * 0.99) as usize],
        pixels: errors.len(),
    }
}

/// gradmesh's own PDF export (Lab and sRGB shadings) read back: within 0.5 ΔE00 on average of
/// the render of the same document.
#[test]
fn own_export_reads_back_as_the_render() {
    for name in [
        "irregular-vertex.json",
        "annulus.json",
        "edge-kinds.json",
        "non-rectangular.json",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples")
            .join(name);
        let doc = formats::read_path(&path).unwrap();
        for colour in [PdfColour::Lab, PdfColour::Srgb] {
            let mut render = RenderOptions::fit(&doc, 256);
            let mut opts = ExportOptions::new(render.width, render.height, render.view);
            opts.colour = colour;
            let (bytes, _) = write_pdf(&doc, &opts).unwrap();
            let picture = pdf::read_pdf(&bytes, 1, &Limits::DEFAULT).unwrap();
            assert_eq!(picture.fills.len(), doc.layers.len(), "{name}");
            assert!(picture.fills.iter().all(|f| f.shading_type == 7));
            let ours = render_pdf(&picture, render.width, render.height, true);
            let alpha = render_pdf(&picture, render.width, render.height, false);
            render.dither = false;
            render.background = Some([1.0, 1.0, 1.0, 1.0]);
            let (reference, _) = render_image(&doc, &render).unwrap();
            let f = figures(
                &Raster::from_image(&ours),
                &Raster::from_image(&reference),
                &mesh_pixels(&alpha),
                name,
            );
            eprintln!(
                "{name} {colour:?}: mean {:.3}, 99th {:.3} over {} pixels",
                f.mean, f.p99, f.pixels
            );
            assert!(f.mean <= 0.5, "{name} {colour:?}: {f:?}");
        }
    }
}
