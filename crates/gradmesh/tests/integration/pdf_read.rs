//! Reading PDF patch-mesh shadings, checked against other renderers: gradmesh's own PDF
//! export read back against the render of the same document, and Inkscape's PDF export of the
//! SVG mesh gradients in `../shared/realdata/meshgradient` against poppler's `pdftoppm` of the
//! same file. Figures are CIEDE2000 over the mesh pixels (those a few pixels inside the
//! outline of what gradmesh covers), on white.

use std::path::{Path, PathBuf};
use std::process::Command;

use gradmesh::export::{write_pdf, ExportOptions, PdfColour};
use gradmesh::formats::{self, pdf};
use gradmesh::render::{
    pdf_picture_layers, render_image, render_picture_into, Image, RenderOptions, SvgMeshRendering,
    View,
};
use gradmesh::{ColourSpace, Document, Limits};
use palette::color_difference::Ciede2000;
use palette::{white_point::D65, Lab};

use super::export::{Raster, Tool};
use super::fuzz_entry::pdf::{pdf_file, stream_object};
use super::realdata;

/// Pixels this close to the covered area's edge are not mesh pixels.
const ERODE_PX: i64 = 3;

/// ΔE00 figures over the mesh pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Figures {
    pub mean: f64,
    pub p99: f64,
    pub pixels: usize,
}

/// The picture of `picture` drawn by gradmesh at `width` x `height` (on white when `white`).
pub(crate) fn render_pdf(picture: &pdf::PdfPicture, width: u32, height: u32, white: bool) -> Image {
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
pub(crate) fn mesh_pixels(alpha: &Image) -> Vec<bool> {
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

pub(crate) fn figures(ours: &Raster, theirs: &Raster, inside: &[bool], name: &str) -> Figures {
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

pub(crate) fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gradmesh-pdfin-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Keeps a picture when `GRADMESH_KEEP_EXPORTS` is set.
pub(crate) fn keep(image: &Image, path: &Path) {
    if std::env::var_os("GRADMESH_KEEP_EXPORTS").is_some() {
        let mut png = Vec::new();
        gradmesh::render::write_png(
            &mut png,
            image,
            gradmesh::render::PngDepth::Eight { dither: false },
        )
        .unwrap();
        std::fs::write(path, png).unwrap();
    }
}

/// gradmesh's own PDF export (Lab and sRGB shadings, a soft mask for opacity) read back: within 0.5 ΔE00 on average of
/// the render of the same document.
#[test]
fn own_export_reads_back_as_the_render() {
    let names = [
        "irregular-vertex.json",
        "annulus.json",
        "edge-kinds.json",
        "non-rectangular.json",
        "translucent",
    ];
    for name in names {
        let doc = if name == "translucent" {
            // Opacity from 1 to 0.2 across a layer: a luminosity soft mask in the export.
            super::export::translucent_document()
        } else {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../examples")
                .join(name);
            formats::read_path(&path).unwrap()
        };
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

/// The SVG test files of `../shared/realdata/meshgradient`.
const SVG_FILES: [&str; 13] = [
    "wpt/meshgradient-basic-001.svg",
    "wpt/meshgradient-basic-002.svg",
    "wpt/meshgradient-basic-003.svg",
    "wpt/meshgradient-basic-004.svg",
    "wpt/meshgradient-basic-005.svg",
    "wpt/meshgradient-bicubic-001.svg",
    "wpt/meshgradient-complex-001.svg",
    "zectorio-mesh-gradient-js/sample1.svg",
    "zectorio-mesh-gradient-js/sample2.svg",
    "zectorio-mesh-gradient-js/sample3.svg",
    "zectorio-mesh-gradient-js/sample4.svg",
    "zectorio-mesh-gradient-js/sample5.svg",
    "zectorio-mesh-gradient-js/sample6.svg",
];

/// `inkscape SVG --export-type=pdf` into `dir`; the PDF's path.
pub(crate) fn inkscape_pdf(name: &str, dir: &Path) -> PathBuf {
    let svg = realdata::meshgradient(name);
    let stem = Path::new(name)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    let pdf_path = dir.join(format!("{stem}.pdf"));
    let out = Command::new("inkscape")
        .arg(&svg)
        .arg("--export-type=pdf")
        .arg(format!("--export-filename={}", pdf_path.display()))
        .output()
        .unwrap_or_else(|e| {
            panic!("inkscape could not be run ({e}): install it (apt-get install inkscape)")
        });
    assert!(
        out.status.success() && pdf_path.exists(),
        "inkscape failed on {name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    pdf_path
}

/// The pixels where poppler shows a shading of the PDF at `path`: those that change when every
/// shading's colours are inverted (`Decode` ranges of three components `0 1` swapped, in a
/// copy of the file of the same length), a pixel in from their edge.
pub(crate) fn visible_in_poppler(path: &Path, plain: &Raster) -> Vec<bool> {
    let bytes = std::fs::read(path).unwrap();
    let (from, to) = (b"0 1 0 1 0 1 ]".as_slice(), b"1 0 1 0 1 0 ]".as_slice());
    let mut inverted = bytes.clone();
    let mut k = 0;
    let mut found = 0;
    while k + from.len() <= inverted.len() {
        if &inverted[k..k + from.len()] == from {
            inverted[k..k + from.len()].copy_from_slice(to);
            found += 1;
        }
        k += 1;
    }
    assert!(
        found > 0,
        "{}: no RGB Decode ranges to invert",
        path.display()
    );
    let copy = path.with_extension("inverted.pdf");
    std::fs::write(&copy, inverted).unwrap();
    let other = Tool::Pdftoppm.rasterise(&copy);
    let (w, h) = (plain.width as i64, plain.height as i64);
    let changed: Vec<bool> = plain
        .rgba
        .iter()
        .zip(&other.rgba)
        .map(|(a, b)| (0..3).any(|k| (a[k] - b[k]).abs() > 0.02))
        .collect();
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            (-1..=1).all(|dy| {
                (-1..=1).all(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..w).contains(&u) && (0..h).contains(&v) && changed[(v * w + u) as usize]
                })
            })
        })
        .collect()
}

/// Inkscape's PDF export of the 13 SVG test files (Cairo writes their meshes as type 7
/// shadings), rendered by gradmesh and by `pdftoppm` at 96 dpi (a CSS pixel a pixel), over the mesh pixels (covered
/// by gradmesh and showing a shading in poppler's page: other content painted over a mesh is
/// left out): mean at most 1 ΔE00 and 99th percentile at most 4, or no farther from poppler
/// than MuPDF (`mutool draw`) is on both. Two of the files export to PDF as nothing; then
/// poppler's page must be blank.
#[test]
fn inkscape_pdfs_match_pdftoppm() {
    let dir = scratch("inkscape");
    let mut failures = Vec::new();
    for name in SVG_FILES {
        let pdf_path = inkscape_pdf(name, &dir);
        let bytes = std::fs::read(&pdf_path).unwrap();
        let picture =
            pdf::read_pdf(&bytes, 1, &Limits::DEFAULT).unwrap_or_else(|e| panic!("{name}: {e}"));
        let poppler = Tool::Pdftoppm.rasterise(&pdf_path);
        if picture.fills.is_empty() {
            // Inkscape exports some meshes as nothing: then poppler's page must be blank too.
            let blank = poppler
                .rgba
                .iter()
                .all(|p| p[..3].iter().all(|&c| c > 0.999));
            eprintln!("{name}: Inkscape's PDF paints no shading; poppler's page blank: {blank}");
            if !blank {
                failures.push(format!(
                    "{name}: no shading read, but poppler paints something"
                ));
            }
            continue;
        }
        let mupdf = Tool::Mutool.rasterise(&pdf_path);
        let (w, h) = (poppler.width, poppler.height);
        let ours = render_pdf(&picture, w, h, true);
        let alpha = render_pdf(&picture, w, h, false);
        keep(&ours, &pdf_path.with_extension("gradmesh.png"));
        let visible = visible_in_poppler(&pdf_path, &poppler);
        let inside: Vec<bool> = mesh_pixels(&alpha)
            .iter()
            .zip(&visible)
            .map(|(a, b)| *a && *b)
            .collect();
        let ours = Raster::from_image(&ours);
        let f = figures(&ours, &poppler, &inside, name);
        let m = figures(&ours, &mupdf, &inside, name);
        let spread = figures(&mupdf, &poppler, &inside, name);
        eprintln!(
            "{name}: {} shadings, {} pixels; against pdftoppm mean {:.2}, 99th {:.2}; against mutool mean {:.2}, 99th {:.2}; mutool against pdftoppm mean {:.2}, 99th {:.2}",
            picture.fills.len(), f.pixels, f.mean, f.p99, m.mean, m.p99, spread.mean, spread.p99
        );
        // The bar, or closer to poppler than MuPDF is: where poppler's flat cells or
        // its order at fold-overs stand apart from every other renderer.
        let within_bar = f.mean <= 1.0 && f.p99 <= 4.0;
        let as_close_as_mupdf = f.mean <= spread.mean && f.p99 <= spread.p99;
        if !(within_bar || as_close_as_mupdf) {
            failures.push(format!("{name}: {f:?}; MuPDF against poppler {spread:?}"));
        }
    }
    if std::env::var_os("GRADMESH_KEEP_EXPORTS").is_none() {
        std::fs::remove_dir_all(&dir).ok();
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Inkscape's PDF of sample5 (a grid of patches whose neighbours share corners and colours)
/// read into the scheme: one layer per shading, a face per patch, points shared.
#[test]
fn inkscape_pdf_converts_into_the_scheme() {
    let dir = scratch("convert");
    let pdf_path = inkscape_pdf("zectorio-mesh-gradient-js/sample5.svg", &dir);
    let read = pdf::read_path_with_limits(&pdf_path, 1, &Limits::DEFAULT).unwrap();
    let doc: &Document = &read.document;
    assert_eq!(doc.layers.len(), read.picture.fills.len());
    for (mesh, fill) in doc.layers.iter().zip(&read.picture.fills) {
        assert!(fill.patches.len() > 1);
        assert_eq!(mesh.faces.len(), fill.patches.len());
        // A grid of r x c patches has (r + 1)(c + 1) corners: far fewer than 4 a patch.
        assert!(
            mesh.points.len() < 2 * fill.patches.len() + 4,
            "{} points for {} patches",
            mesh.points.len(),
            fill.patches.len()
        );
        gradmesh::validate(mesh).unwrap();
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The page entries of a page of 255 x 255 points.
const SQUARE_PAGE: &str = "/MediaBox [0 0 255 255]";

/// A one-page PDF file whose content paints the shading `dict` (object 5, its stream `data`)
/// with `sh`; `page_entries` (the boxes, say) are added to the page's dictionary and `more`
/// objects are numbered from 6. The cross-reference table is correct.
fn one_shading_pdf(dict: &str, data: &[u8], page_entries: &str, more: &[Vec<u8>]) -> Vec<u8> {
    let stream = stream_object;
    let page = format!(
        "<< /Type /Page /Parent 2 0 R /Contents 4 0 R \
         /Resources << /Shading << /S0 5 0 R >> >> {page_entries} >>"
    );
    let mut objects = vec![
        b"<< /Type /Catalog /Pages 2 0 R >>".to_vec(),
        b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_vec(),
        page.into_bytes(),
        stream("", b"/S0 sh"),
        stream(dict, data),
    ];
    objects.extend(more.iter().cloned());
    pdf_file(&objects)
}

/// A type 6 record of one patch over the whole 255-point page (u along x, v along y up), one
/// byte a component: `corners`, the components of c00, c03, c33 and c30 (stream order).
fn page_patch_record(corners: &[u8]) -> Vec<u8> {
    let sides: [(u8, u8); 12] = [
        (0, 0),
        (0, 85),
        (0, 170),
        (0, 255),
        (85, 255),
        (170, 255),
        (255, 255),
        (255, 170),
        (255, 85),
        (255, 0),
        (170, 0),
        (85, 0),
    ];
    let mut data = vec![0u8];
    data.extend(sides.iter().flat_map(|&(x, y)| [x, y]));
    data.extend(corners);
    data
}

/// The shading dictionary of [`page_patch_record`]'s records in `space`, its component
/// decoded to `range`.
fn page_patch_shading(space: &str, range: &str) -> String {
    format!(
        "/ShadingType 6 /ColorSpace {space} /BitsPerCoordinate 8 /BitsPerComponent 8 \
         /BitsPerFlag 8 /Decode [0 255 0 255 {range}]"
    )
}

/// The largest difference, in 8-bit levels, between `image` (sRGB-encoded values in 0..1) and
/// `expected` (an sRGB colour in 0..1 of the patch's parameters `(u, v)`), over a grid of pixels away from the edges; the
/// patch fills the page, `u` along x and `v` up.
fn largest_level_error(image: &Image, expected: impl Fn(f64, f64) -> [f64; 3]) -> f64 {
    let (w, h) = (image.width as usize, image.height as usize);
    let mut worst = 0.0f64;
    for y in (4..h - 4).step_by(7) {
        for x in (4..w - 4).step_by(7) {
            let (u, v) = (
                (x as f64 + 0.5) / w as f64,
                1.0 - (y as f64 + 0.5) / h as f64,
            );
            let pixel = &image.data[4 * (y * w + x)..4 * (y * w + x) + 3];
            for (got, want) in pixel.iter().zip(expected(u, v)) {
                worst = worst.max((f64::from(*got) - want).abs() * 255.0);
            }
        }
    }
    worst
}

/// Renders the PDF `bytes` (written to `path`) as gradmesh and as pdftoppm do: the largest
/// error in 8-bit levels against `expected` and the ΔE00 figures against poppler.
fn against_hand_and_poppler(
    bytes: &[u8],
    path: &Path,
    expected: impl Fn(f64, f64) -> [f64; 3],
) -> (f64, Figures) {
    std::fs::write(path, bytes).unwrap();
    let name = path.display().to_string();
    let picture =
        pdf::read_pdf(bytes, 1, &Limits::DEFAULT).unwrap_or_else(|e| panic!("{name}: {e}"));
    let poppler = Tool::Pdftoppm.rasterise(path);
    let ours = render_pdf(&picture, poppler.width, poppler.height, true);
    let alpha = render_pdf(&picture, poppler.width, poppler.height, false);
    keep(&ours, &path.with_extension("gradmesh.png"));
    let worst = largest_level_error(&ours, expected);
    let f = figures(
        &Raster::from_image(&ours),
        &poppler,
        &mesh_pixels(&alpha),
        &name,
    );
    (worst, f)
}

/// An Indexed shading (a 256-entry ramp) and a Separation one (through a type 4 tint
/// transform into RGB), drawn within two 8-bit levels of the colours computed by hand, and
/// within the bar of poppler's rendering.
#[test]
fn indexed_and_separation_shadings_render_as_computed() {
    let dir = scratch("special-spaces");
    // Entry i is (i, 255 - i, 128); the index runs 0 to 255 with v.
    let ramp: Vec<u8> = (0..=255u8).flat_map(|i| [i, 255 - i, 128]).collect();
    let hex: String = ramp.iter().map(|b| format!("{b:02X}")).collect();
    let space = format!("[/Indexed /DeviceRGB 255 <{hex}>]");
    let indexed = one_shading_pdf(
        &page_patch_shading(&space, "0 255"),
        &page_patch_record(&[0, 255, 255, 0]),
        SQUARE_PAGE,
        &[],
    );
    let ramp_at = |_u: f64, v: f64| {
        let i = (255.0 * v).round() / 255.0;
        [i, 1.0 - i, 128.0 / 255.0]
    };
    // tint t -> RGB (1, 1 - t, 1 - t / 2); t bilinear over the corners 0, 0.2, 1, 0.4. (An
    // alternate space of RGB: poppler's CMYK is not the naive conversion gradmesh documents.)
    let tint = stream_object(
        "/FunctionType 4 /Domain [0 1] /Range [0 1 0 1 0 1]",
        b"{ 1 exch dup 1 exch sub exch 0.5 mul 1 exch sub }",
    );
    let separation = one_shading_pdf(
        &page_patch_shading("[/Separation /Spot /DeviceRGB 6 0 R]", "0 1"),
        &page_patch_record(&[0, 51, 255, 102]),
        SQUARE_PAGE,
        &[tint],
    );
    let tinted_at = |u: f64, v: f64| {
        let t = (1.0 - u) * v * 0.2 + u * v + u * (1.0 - v) * 0.4;
        [1.0, 1.0 - t, 1.0 - t / 2.0]
    };
    let indexed = against_hand_and_poppler(&indexed, &dir.join("indexed.pdf"), ramp_at);
    let separation = against_hand_and_poppler(&separation, &dir.join("separation.pdf"), tinted_at);
    for (name, (worst, f)) in [("indexed", indexed), ("separation", separation)] {
        eprintln!(
            "{name}: largest error against the hand computation {worst:.1} levels; against pdftoppm over {} pixels: mean {:.2}, 99th {:.2}",
            f.pixels, f.mean, f.p99
        );
        assert!(
            worst <= 2.0,
            "{name}: {worst} levels from the hand computation"
        );
        assert!(
            f.mean <= 1.0 && f.p99 <= 4.0,
            "{name}: against pdftoppm {f:?}"
        );
    }
    if std::env::var_os("GRADMESH_KEEP_EXPORTS").is_none() {
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// Pages turned by `/Rotate` against pdftoppm, which turns them as viewers do: a page of
/// 255 x 150 points shows as 150 x 255 for a quarter turn, and the colours land where
/// poppler puts them.
#[test]
fn rotated_pages_match_pdftoppm() {
    let dir = scratch("rotate");
    // Red, green, blue and white corners: a turn the wrong way shows.
    let record = page_patch_record(&[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]);
    let shading = page_patch_shading("/DeviceRGB", "0 1 0 1 0 1");
    for rotate in [90, 180, 270, -90] {
        let entries = format!("/MediaBox [0 0 255 150] /Rotate {rotate}");
        let bytes = one_shading_pdf(&shading, &record, &entries, &[]);
        let path = dir.join(format!("rotate{rotate}.pdf"));
        std::fs::write(&path, &bytes).unwrap();
        let picture = pdf::read_pdf(&bytes, 1, &Limits::DEFAULT).unwrap();
        let view = picture.view_rect();
        let quarter = rotate % 180 != 0;
        let size = if quarter {
            (150.0, 255.0)
        } else {
            (255.0, 150.0)
        };
        assert_eq!((view.width(), view.height()), size, "/Rotate {rotate}");
        let poppler = Tool::Pdftoppm.rasterise(&path);
        assert_eq!(
            poppler.width > poppler.height,
            !quarter,
            "/Rotate {rotate}: poppler's page is {} x {}",
            poppler.width,
            poppler.height
        );
        let ours = render_pdf(&picture, poppler.width, poppler.height, true);
        let alpha = render_pdf(&picture, poppler.width, poppler.height, false);
        keep(&ours, &path.with_extension("gradmesh.png"));
        let name = format!("/Rotate {rotate}");
        let f = figures(
            &Raster::from_image(&ours),
            &poppler,
            &mesh_pixels(&alpha),
            &name,
        );
        eprintln!(
            "/Rotate {rotate}: {} x {} px, against pdftoppm over {} pixels: mean {:.2}, 99th {:.2}",
            poppler.width, poppler.height, f.pixels, f.mean, f.p99
        );
        assert!(f.mean <= 1.0 && f.p99 <= 4.0, "{name}: {f:?}");
    }
    if std::env::var_os("GRADMESH_KEEP_EXPORTS").is_none() {
        std::fs::remove_dir_all(&dir).ok();
    }
}
