//! The 13 SVG mesh-gradient test files (7 W3C, 6 Inkscape samples) drawn classically and
//! through the scheme, against Inkscape 1.2.2's renders in
//! `../shared/realdata/meshgradient/inkscape-1.2.2-renders/`: CIEDE2000 over the pixels the
//! meshes alone cover.
//!
//! Inkscape paints through Cairo, which gives each pixel the colour of some point inside it
//! (the last of its forward samples to land there), not of its centre, and rounds to 8 bits.
//! Where colour changes fast, a pixel's colour can therefore differ from the centre's by up to
//! the change across a pixel. Besides each pixel's difference, the *excess* is measured: the
//! difference less the largest difference between the classic render's pixel and its four
//! neighbours (the colour change across one pixel there), floored at zero.
//!
//! `cargo test -p gradmesh --test integration svg_inkscape_table -- --ignored --nocapture`
//! prints the table of `docs/svg.md`.

use gradmesh::export::{write_pdf_picture, write_svg_picture, ExportLayer, ExportOptions};
use gradmesh::formats::svg;
use gradmesh::render::{render_svg_scene, Image, RenderOptions, SvgMeshRendering, View};
use gradmesh::ColourSpace;
use palette::color_difference::Ciede2000;
use palette::{white_point::D65, Lab};

use crate::export::Tool;
use crate::realdata;

/// The files, as paths under `meshgradient/`, with the name of their Inkscape render.
const FILES: [(&str, &str); 13] = [
    ("wpt/meshgradient-basic-001.svg", "meshgradient-basic-001"),
    ("wpt/meshgradient-basic-002.svg", "meshgradient-basic-002"),
    ("wpt/meshgradient-basic-003.svg", "meshgradient-basic-003"),
    ("wpt/meshgradient-basic-004.svg", "meshgradient-basic-004"),
    ("wpt/meshgradient-basic-005.svg", "meshgradient-basic-005"),
    (
        "wpt/meshgradient-bicubic-001.svg",
        "meshgradient-bicubic-001",
    ),
    (
        "wpt/meshgradient-complex-001.svg",
        "meshgradient-complex-001",
    ),
    ("zectorio-mesh-gradient-js/sample1.svg", "sample1"),
    ("zectorio-mesh-gradient-js/sample2.svg", "sample2"),
    ("zectorio-mesh-gradient-js/sample3.svg", "sample3"),
    ("zectorio-mesh-gradient-js/sample4.svg", "sample4"),
    ("zectorio-mesh-gradient-js/sample5.svg", "sample5"),
    ("zectorio-mesh-gradient-js/sample6.svg", "sample6"),
];

/// Pixels compared lie at least this far (pixels, in x and y) inside what the classic render
/// and Inkscape's both cover opaquely: the anti-aliased edges, and the strokes the files draw
/// along their shapes (at most 5.3 units wide, so 2.65 inside), are left out.
const MARGIN: i64 = 4;

/// The classic render's largest mean CIEDE2000 on any file, and the largest 99th percentile
/// of its excess (see `docs/svg.md`, "Against Inkscape", for why these).
const CLASSIC_MEAN: f64 = 1.5;
const CLASSIC_EXCESS_P99: f64 = 1.0;

/// How far one render is from Inkscape's: CIEDE2000 over the pixels compared, its mean and
/// 99th percentile, and the 99th percentile of the excess.
struct Difference {
    pixels: usize,
    mean: f64,
    p99: f64,
    excess_p99: f64,
}

/// The mean and the 99th percentile of `values`.
fn mean_and_p99(mut values: Vec<f64>) -> (f64, f64) {
    values.sort_by(f64::total_cmp);
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    (mean, values[(0.99 * (values.len() - 1) as f64) as usize])
}

/// The ellipses and circles (centre, radii, in user units) painted after the first
/// mesh-gradient fill of `text` with another paint: content gradmesh does not draw that may
/// cover a mesh in Inkscape's render. The test files place them without transforms.
fn later_ellipses(text: &str) -> Vec<([f64; 2], [f64; 2])> {
    let doc = roxmltree::Document::parse(text).unwrap();
    let mut seen_mesh = false;
    let mut out = Vec::new();
    for node in doc.descendants().filter(|n| n.is_element()) {
        let style = node.attribute("style").unwrap_or("");
        let fill = node.attribute("fill").unwrap_or("");
        if style.contains("fill:url(") || fill.starts_with("url(") {
            seen_mesh = true;
            continue;
        }
        let tag = node.tag_name().name();
        if !(seen_mesh && (tag == "ellipse" || tag == "circle")) {
            continue;
        }
        assert!(
            node.ancestors().all(|a| a.attribute("transform").is_none()),
            "a transformed {tag}: not handled here"
        );
        let num = |name: &str| {
            node.attribute(name)
                .map_or(0.0, |v| v.parse::<f64>().unwrap())
        };
        let radii = if tag == "circle" {
            [num("r"), num("r")]
        } else {
            [num("rx"), num("ry")]
        };
        out.push(([num("cx"), num("cy")], radii));
    }
    out
}

/// Inkscape's render `name` as straight-alpha sRGB in 0..1, with its size.
fn inkscape_render(name: &str) -> Image {
    let path = realdata::meshgradient(&format!("inkscape-1.2.2-renders/{name}.png"));
    let mut decoder =
        png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut buf).unwrap();
    let channels = frame.color_type.samples();
    let mut image = Image::new(frame.width, frame.height);
    for (k, px) in buf[..frame.buffer_size()]
        .chunks_exact(channels)
        .enumerate()
    {
        let v = |c: usize| f32::from(px[c]) / 255.0;
        let rgba = match channels {
            4 => [v(0), v(1), v(2), v(3)],
            3 => [v(0), v(1), v(2), 1.0],
            2 => [v(0), v(0), v(0), v(1)],
            _ => [v(0), v(0), v(0), 1.0],
        };
        image.data[4 * k..4 * k + 4].copy_from_slice(&rgba);
    }
    image
}

fn delta_e(a: [f32; 4], b: [f32; 4]) -> f64 {
    let lab = |p: [f32; 4]| {
        let c = ColourSpace::Srgb.convert(
            ColourSpace::Lab,
            [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])],
        );
        Lab::<D65, f64>::new(c[0], c[1], c[2])
    };
    lab(a).difference(lab(b))
}

/// Whether every pixel within [`MARGIN`] of (x, y) is opaque in `img`.
fn opaque_around(img: &Image, x: i64, y: i64) -> bool {
    (-MARGIN..=MARGIN).all(|dy| {
        (-MARGIN..=MARGIN).all(|dx| {
            let (px, py) = (x + dx, y + dy);
            px >= 0
                && py >= 0
                && px < i64::from(img.width)
                && py < i64::from(img.height)
                && img.pixel(px as u32, py as u32)[3] >= 1.0
        })
    })
}

/// The classic and the scheme render of `file` against Inkscape's render `name`, at its
/// size, over the pixels well inside both the classic render and Inkscape's (and opaque in
/// the scheme's), away from ellipses drawn over the meshes ([`later_ellipses`]).
fn compare(file: &str, name: &str) -> [Difference; 2] {
    let mut out = compare_with(file, name, false).into_iter();
    [out.next().unwrap(), out.next().unwrap()]
}

/// The file's meshes exported as they are ([`ExportLayer::SvgMesh`]) at the size of `opts`:
/// the PDF rasterised by poppler and by MuPDF at 96 dpi, the SVG (without its PNG fallback)
/// by Inkscape.
fn export_rasters(scene: &svg::SvgScene, opts: &RenderOptions, name: &str) -> [Image; 3] {
    let layers: Vec<ExportLayer> = scene.fills.iter().map(ExportLayer::SvgMesh).collect();
    let export = ExportOptions::new(opts.width, opts.height, opts.view);
    let (pdf, _) = write_pdf_picture(&layers, &export).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (svg, _) =
        write_svg_picture(&layers, &export, false).unwrap_or_else(|e| panic!("{name}: {e}"));
    let dir = std::env::temp_dir().join(format!("gradmesh-svgpdf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (pdf_path, svg_path) = (
        dir.join(format!("{name}.pdf")),
        dir.join(format!("{name}.svg")),
    );
    std::fs::write(&pdf_path, pdf).unwrap();
    std::fs::write(&svg_path, svg).unwrap();
    [
        (Tool::Pdftoppm, &pdf_path),
        (Tool::Mutool, &pdf_path),
        (Tool::Inkscape, &svg_path),
    ]
    .map(|(tool, path)| {
        let raster = tool.rasterise(path);
        let mut image = Image::new(raster.width, raster.height);
        for (k, p) in raster.rgba.iter().enumerate() {
            image.data[4 * k..4 * k + 4].copy_from_slice(&p.map(|c| c as f32));
        }
        image
    })
}

/// [`compare`], followed with `pdf` by the file's export of its meshes as they are, the PDF
/// rasterised by poppler and MuPDF and the SVG by Inkscape ([`export_rasters`]).
fn compare_with(file: &str, name: &str, pdf: bool) -> Vec<Difference> {
    let text = std::fs::read_to_string(realdata::meshgradient(file)).unwrap();
    let scene = svg::read_svg(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
    let reference = inkscape_render(name);
    let (w, h) = (reference.width, reference.height);
    let (pw, ph) = scene.pixel_size();
    assert_eq!((pw.round() as u32, ph.round() as u32), (w, h), "{file}");
    let view = View::from_rect(scene.view_rect());
    let mut opts = RenderOptions::new(w, h, view);
    opts.dither = false;
    let render = |mode| {
        render_svg_scene(&scene, mode, &opts)
            .unwrap_or_else(|e| panic!("{file}: {e}"))
            .0
    };
    let (classic, scheme) = (
        render(SvgMeshRendering::Classic),
        render(SvgMeshRendering::Scheme),
    );
    let mut images = vec![scheme];
    if pdf {
        images.extend(export_rasters(&scene, &opts, name));
    }
    for image in &images[1..] {
        assert_eq!((image.width, image.height), (w, h), "{name}: PDF page size");
    }
    let ellipses = later_ellipses(&text);
    let (sx, sy) = (view.width() / f64::from(w), view.height() / f64::from(h));
    let covered_by_other_content = |x: u32, y: u32| {
        let p = [
            view.x0 + (f64::from(x) + 0.5) * sx,
            view.y0 + (f64::from(y) + 0.5) * sy,
        ];
        let margin = MARGIN as f64 * sx.max(sy);
        ellipses.iter().any(|&(c, r)| {
            ((p[0] - c[0]) / (r[0] + margin)).powi(2) + ((p[1] - c[1]) / (r[1] + margin)).powi(2)
                <= 1.0
        })
    };
    let mut errors = vec![Vec::new(); images.len() + 1];
    let mut excess = vec![Vec::new(); images.len() + 1];
    for y in 0..h {
        for x in 0..w {
            let (xi, yi) = (i64::from(x), i64::from(y));
            if !(opaque_around(&classic, xi, yi) && opaque_around(&reference, xi, yi))
                || covered_by_other_content(x, y)
            {
                continue;
            }
            let ink = reference.pixel(x, y);
            let ours = classic.pixel(x, y);
            // Inside the margin, the four neighbours exist.
            let across_a_pixel = [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)]
                .iter()
                .map(|&(nx, ny)| delta_e(ours, classic.pixel(nx, ny)))
                .fold(0.0, f64::max);
            for (k, image) in std::iter::once(&classic).chain(&images).enumerate() {
                let px = image.pixel(x, y);
                if px[3] >= 1.0 {
                    let e = delta_e(px, ink);
                    errors[k].push(e);
                    excess[k].push((e - across_a_pixel).max(0.0));
                }
            }
        }
    }
    errors
        .into_iter()
        .zip(excess)
        .map(|(e, x)| {
            assert!(!e.is_empty(), "{file}: no pixel to compare");
            let pixels = e.len();
            let ((mean, p99), (_, excess_p99)) = (mean_and_p99(e), mean_and_p99(x));
            Difference {
                pixels,
                mean,
                p99,
                excess_p99,
            }
        })
        .collect()
}

/// The classic rendering is within the tolerance of Inkscape's on every file.
#[test]
fn classic_renders_match_inkscape() {
    let mut failures = Vec::new();
    for (file, name) in FILES {
        let [classic, _] = compare(file, name);
        if classic.mean > CLASSIC_MEAN || classic.excess_p99 > CLASSIC_EXCESS_P99 {
            failures.push(format!(
                "{name}: mean {:.3}, 99th percentile of the excess {:.3} over {} pixels",
                classic.mean, classic.excess_p99, classic.pixels
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "CIEDE2000 against Inkscape beyond mean {CLASSIC_MEAN} / excess 99th percentile {CLASSIC_EXCESS_P99}:\n{}",
        failures.join("\n")
    );
}

/// The largest mean CIEDE2000 against Inkscape of the PDF export of an SVG file's meshes as
/// they are, rasterised by poppler and by MuPDF; or, on a file where the classic render is
/// farther than that from Inkscape's (basic-005, whose colour changes by several units
/// across a pixel, where Cairo's sampling inside each pixel decides), at most
/// [`PDF_BEYOND_CLASSIC`] farther than the classic render.
const PDF_MEAN: f64 = 1.0;
const PDF_BEYOND_CLASSIC: f64 = 0.5;
/// The largest mean CIEDE2000 of the SVG export of the meshes as they are, drawn by Inkscape,
/// against Inkscape's render of the source: the same patches, so nearly the same pixels.
const SVG_MEAN: f64 = 0.25;

/// `render in.svg -o out.pdf` and `-o out.svg` write the meshes' own patches (Coons patches as
/// PDF patches, bicubic ones cut into the cells of their smoothed colours): poppler's and
/// MuPDF's rasterisations of the PDF are within [`PDF_MEAN`] of Inkscape's render on average
/// on every file (see [`PDF_BEYOND_CLASSIC`] for the one exception), and Inkscape's of the SVG
/// within [`SVG_MEAN`].
#[test]
fn export_of_the_patches_matches_inkscape() {
    let mut failures = Vec::new();
    for (file, name) in FILES {
        let d = compare_with(file, name, true);
        let pdf_bar = PDF_MEAN.max(d[0].mean + PDF_BEYOND_CLASSIC);
        for ((tool, bar), d) in [
            ("PDF, pdftoppm", pdf_bar),
            ("PDF, mutool", pdf_bar),
            ("SVG, Inkscape", SVG_MEAN),
        ]
        .iter()
        .zip(&d[2..])
        {
            if d.mean > *bar {
                failures.push(format!(
                    "{name} ({tool}): mean {:.3}, 99th percentile {:.3} over {} pixels",
                    d.mean, d.p99, d.pixels
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "CIEDE2000 against Inkscape beyond the bar:\n{}",
        failures.join("\n")
    );
}

/// Prints the table of `docs/svg.md`.
#[test]
#[ignore = "prints the table of docs/svg.md"]
fn svg_inkscape_table() {
    println!("| file | pixels | classic mean | classic 99th | classic excess 99th | scheme mean | scheme 99th | PDF: poppler mean / 99th | PDF: MuPDF mean / 99th | SVG: Inkscape mean / 99th |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (file, name) in FILES {
        let d = compare_with(file, name, true);
        let (c, s, p, m, i) = (&d[0], &d[1], &d[2], &d[3], &d[4]);
        println!(
            "| {name} | {} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.2} / {:.2} | {:.2} / {:.2} | {:.2} / {:.2} |",
            c.pixels, c.mean, c.p99, c.excess_p99, s.mean, s.p99, p.mean, p.p99, m.mean, m.p99, i.mean, i.p99
        );
    }
}
