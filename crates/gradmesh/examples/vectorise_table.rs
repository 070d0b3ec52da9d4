//! The vectoriser against a regular grid on the photographs of `../shared/realdata/images`:
//! for each photograph and point budget, the free-topology fit (`vectorise`) and a regular
//! quad grid of at most as many points with its colours fitted by the same least squares
//! (`fit_colours`), both rendered by the same renderer at the photograph's size. Prints a
//! Markdown table: points, PSNR (8-bit sRGB), mean CIEDE2000, gzip -9 bytes of the JSON, time.
//!
//! ```text
//! cargo run --release -p gradmesh --example vectorise_table -- [OUT_DIR] [default|fast|best]
//! ```
//!
//! With `OUT_DIR`, the renders are written there as `NAME-POINTS-mesh.png` and
//! `NAME-POINTS-grid.png`.

use std::error::Error;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use gradmesh::formats::json;
use gradmesh::render::{render_document_into, write_png_rgba8, RenderOptions, View};
use gradmesh::{
    fit_colours, psnr, vectorise, ColourSpace, Document, GradientMesh, Quality, RgbaImage,
    VectoriseOptions,
};
use kurbo::Point;
use palette::color_difference::ImprovedCiede2000;
use palette::{white_point::D65, IntoColor, Lab, Srgb};

const PHOTOS: [&str; 5] = [
    "coffee.png",
    "chelsea.png",
    "rocket.jpg",
    "astronaut.png",
    "grace_hopper.jpg",
];

/// A regular grid of quads over the picture with at most `budget` points, cells near square.
fn grid(width: f64, height: f64, budget: usize) -> GradientMesh {
    let aspect = width / height;
    let mut rows = ((budget as f64 / aspect).sqrt() as usize).max(2);
    let mut cols = ((rows as f64 * aspect).round() as usize).max(2);
    while cols * rows > budget {
        if cols as f64 / aspect > rows as f64 {
            cols -= 1;
        } else {
            rows -= 1;
        }
    }
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    for j in 0..rows {
        for i in 0..cols {
            let x = width * i as f64 / (cols - 1) as f64;
            let y = height * j as f64 / (rows - 1) as f64;
            mesh.add_point(Point::new(x, y), [50.0, 0.0, 0.0]);
        }
    }
    for j in 0..rows - 1 {
        for i in 0..cols - 1 {
            let a = (j * cols + i) as u32;
            let c = cols as u32;
            mesh.add_face(vec![a, a + 1, a + c + 1, a + c]);
        }
    }
    mesh
}

/// The document rendered at the picture's size (8-bit, as `gradmesh render` writes it).
fn render(doc: &Document, w: u32, h: u32) -> Result<Vec<u8>, Box<dyn Error>> {
    let opts = RenderOptions::new(w, h, View::new(0.0, 0.0, w as f64, h as f64));
    let mut out = vec![0u8; 4 * w as usize * h as usize];
    render_document_into(doc, &opts, &mut out)?;
    Ok(out)
}

fn mean_delta_e(a: &RgbaImage, b: &[u8]) -> f64 {
    let lab =
        |p: [f32; 3]| -> Lab<D65, f32> { Srgb::new(p[0], p[1], p[2]).into_linear().into_color() };
    let sum: f64 = a
        .pixels
        .iter()
        .zip(b.chunks_exact(4))
        .map(|(p, q)| {
            let x = lab([p[0], p[1], p[2]]);
            let y = lab([q[0], q[1], q[2]].map(|c| c as f32 / 255.0));
            x.improved_difference(y) as f64
        })
        .sum();
    sum / a.pixels.len() as f64
}

fn gzip_bytes(doc: &Document) -> usize {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(json::write_document(doc).as_bytes()).unwrap();
    e.finish().unwrap().len()
}

struct Row {
    points: usize,
    psnr: f64,
    delta_e: f64,
    bytes: usize,
    seconds: f64,
}

fn measure(
    doc: &Document,
    image: &RgbaImage,
    seconds: f64,
    save: Option<PathBuf>,
) -> Result<Row, Box<dyn Error>> {
    let pixels = render(doc, image.width, image.height)?;
    if let Some(path) = save {
        let file = std::fs::File::create(path)?;
        write_png_rgba8(
            std::io::BufWriter::new(file),
            image.width,
            image.height,
            &pixels,
        )?;
    }
    let rendered = RgbaImage::from_rgba8(image.width, image.height, &pixels)?;
    Ok(Row {
        points: doc.layers.iter().map(|l| l.points.len()).sum(),
        psnr: psnr(image, &rendered)?,
        delta_e: mean_delta_e(image, &pixels),
        bytes: gzip_bytes(doc),
        seconds,
    })
}

fn main() -> Result<(), Box<dyn Error>> {
    let out_dir = std::env::args().nth(1).map(PathBuf::from);
    let quality = match std::env::args().nth(2).as_deref() {
        Some("fast") => Quality::Fast,
        Some("best") => Quality::Best,
        _ => Quality::Default,
    };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata/images");
    println!("| photo | budget | mesh: points, PSNR, mean ΔE00, gzip bytes, time | regular grid: points, PSNR, mean ΔE00, gzip bytes |");
    println!("|---|---|---|---|");
    for name in PHOTOS {
        let path = dir.join(name);
        let image = RgbaImage::read_path(&path, 1 << 28, 1 << 26)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let stem = name.split('.').next().unwrap();
        for budget in [256, 1024] {
            let save = |kind: &str| {
                out_dir
                    .as_ref()
                    .map(|d| d.join(format!("{stem}-{budget}-{kind}.png")))
            };
            let options = VectoriseOptions {
                points: Some(budget),
                quality,
                ..VectoriseOptions::default()
            };
            let start = Instant::now();
            let v = vectorise(&image, &options)?;
            let mesh = measure(
                &v.document,
                &image,
                start.elapsed().as_secs_f64(),
                save("mesh"),
            )?;
            let start = Instant::now();
            let mut g = grid(image.width as f64, image.height as f64, budget);
            fit_colours(&mut g, &image, quality)?;
            let seconds = start.elapsed().as_secs_f64();
            let grid_doc = Document { layers: vec![g] };
            let grid = measure(&grid_doc, &image, seconds, save("grid"))?;
            println!(
                "| {stem} | {budget} | {} pts, {:.2} dB, {:.2}, {} B, {:.2} s | {} pts, {:.2} dB, {:.2}, {} B |",
                mesh.points, mesh.psnr, mesh.delta_e, mesh.bytes, mesh.seconds,
                grid.points, grid.psnr, grid.delta_e, grid.bytes,
            );
        }
    }
    Ok(())
}
