//! The vectoriser's benchmark on the photographs of `../shared/realdata/images`: for each
//! photograph and point budget, the free-topology fit (`vectorise`) and a regular quad grid of
//! at most as many points with its colours fitted by the same least squares (`fit_colours`),
//! both rendered by gradmesh's renderer at the photograph's size (8-bit, not dithered); and,
//! given a folder of vtracer's SVG files, those rasterised by resvg at the same size. Prints a
//! Markdown table: points, PSNR over 8-bit sRGB (all pixels and channels), mean CIEDE2000,
//! gzip -9 bytes of the JSON (of the SVG for vtracer), time.
//!
//! ```text
//! cargo run --release -p gradmesh --example vectorise_table -- \
//!     [--out DIR] [--vtracer DIR] [--quality fast|default|best] [--budgets 256,1024] [--only NAME]
//!     [--fixed-points] [--unrounded]
//! ```
//!
//! `--fixed-points` leaves the points where the quadtree puts them (`fit_positions` off);
//! `--unrounded` writes positions and colours at full precision (`round_output` off).
//!
//! `--out DIR` writes the renders (`NAME-POINTS-mesh.png`, `NAME-POINTS-grid.png`,
//! `NAME-vtracer-PRESET.png`), the fitted documents (`NAME-POINTS-mesh.json`) and the
//! free-topology fit's error (`NAME-POINTS-mesh-error.png`: the 8-bit sRGB error per pixel,
//! summed over the channels, times two). `--vtracer DIR` reads `NAME-vtracer-PRESET.svg` and
//! the times in `vtracer-times.tsv` (lines `NAME PRESET SECONDS`), as
//! `scripts/vectorise-bench.sh` writes them.

use std::collections::HashMap;
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

const VTRACER_PRESETS: [&str; 3] = ["photo", "poster", "default"];

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

/// The document rendered at the picture's size, 8-bit RGBA, not dithered.
fn render(doc: &Document, w: u32, h: u32) -> Result<Vec<u8>, Box<dyn Error>> {
    let mut opts = RenderOptions::new(w, h, View::new(0.0, 0.0, w as f64, h as f64));
    opts.dither = false;
    let mut out = vec![0u8; 4 * w as usize * h as usize];
    render_document_into(doc, &opts, &mut out)?;
    Ok(out)
}

/// An SVG file rasterised by resvg at `w` x `h` pixels (its own size scaled to that), 8-bit
/// RGBA with straight alpha.
fn render_svg(path: &Path, w: u32, h: u32) -> Result<Vec<u8>, Box<dyn Error>> {
    use resvg::{tiny_skia, usvg};
    let data = std::fs::read(path)?;
    let tree = usvg::Tree::from_data(&data, &usvg::Options::default())?;
    let mut pixmap = tiny_skia::Pixmap::new(w, h).ok_or("an empty picture")?;
    let size = tree.size();
    let scale = tiny_skia::Transform::from_scale(w as f32 / size.width(), h as f32 / size.height());
    resvg::render(&tree, scale, &mut pixmap.as_mut());
    Ok(pixmap
        .pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
        .collect())
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

fn gzip_bytes(bytes: &[u8]) -> usize {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(bytes).expect("writing to memory");
    e.finish().expect("writing to memory").len()
}

fn write_png(path: &Path, w: u32, h: u32, pixels: &[u8]) -> Result<(), Box<dyn Error>> {
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    write_png_rgba8(file, w, h, pixels)?;
    Ok(())
}

/// The 8-bit sRGB error per pixel, summed over the channels, times two, as grey.
fn error_picture(image: &RgbaImage, rendered: &[u8]) -> Vec<u8> {
    image
        .to_rgba8()
        .chunks_exact(4)
        .zip(rendered.chunks_exact(4))
        .flat_map(|(p, q)| {
            let e: i32 = (0..3).map(|k| (p[k] as i32 - q[k] as i32).abs()).sum();
            let v = (255 - 2 * e).max(0) as u8;
            [v, v, v, 255]
        })
        .collect()
}

/// One line of the table.
struct Row {
    points: Option<usize>,
    psnr: f64,
    delta_e: f64,
    bytes: usize,
    seconds: f64,
}

impl Row {
    fn measure(
        image: &RgbaImage,
        pixels: &[u8],
        bytes: usize,
        seconds: f64,
    ) -> Result<Row, Box<dyn Error>> {
        let rendered = RgbaImage::from_rgba8(image.width, image.height, pixels)?;
        Ok(Row {
            points: None,
            psnr: psnr(image, &rendered)?,
            delta_e: mean_delta_e(image, pixels),
            bytes,
            seconds,
        })
    }

    fn print(&self, photo: &str, method: &str) {
        let points = self.points.map_or("–".to_string(), |n| n.to_string());
        println!(
            "| {photo} | {method} | {points} | {:.2} | {:.2} | {} | {:.2} |",
            self.psnr, self.delta_e, self.bytes, self.seconds
        );
    }
}

/// A document measured: rendered, compared, its JSON gzipped.
fn measure_document(
    doc: &Document,
    image: &RgbaImage,
    seconds: f64,
    save: Option<PathBuf>,
) -> Result<(Row, Vec<u8>), Box<dyn Error>> {
    let pixels = render(doc, image.width, image.height)?;
    let text = json::write_document(doc);
    if let Some(path) = save {
        write_png(&path, image.width, image.height, &pixels)?;
        std::fs::write(path.with_extension("json"), &text)?;
    }
    let mut row = Row::measure(image, &pixels, gzip_bytes(text.as_bytes()), seconds)?;
    row.points = Some(doc.layers.iter().map(|l| l.points.len()).sum());
    Ok((row, pixels))
}

struct Args {
    out: Option<PathBuf>,
    vtracer: Option<PathBuf>,
    quality: Quality,
    budgets: Vec<usize>,
    only: Option<String>,
    fit_positions: bool,
    round_output: bool,
}

fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut args = Args {
        out: None,
        vtracer: None,
        quality: Quality::Default,
        budgets: vec![256, 1024],
        only: None,
        fit_positions: true,
        round_output: true,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "--out" => args.out = Some(value()?.into()),
            "--vtracer" => args.vtracer = Some(value()?.into()),
            "--only" => args.only = Some(value()?),
            "--fixed-points" => args.fit_positions = false,
            "--unrounded" => args.round_output = false,
            "--quality" => {
                args.quality = match value()?.as_str() {
                    "fast" => Quality::Fast,
                    "default" => Quality::Default,
                    "best" => Quality::Best,
                    q => return Err(format!("--quality {q}: fast, default or best").into()),
                }
            }
            "--budgets" => {
                args.budgets = value()?
                    .split(',')
                    .map(|s| s.parse())
                    .collect::<Result<_, _>>()?
            }
            _ => return Err(format!("unknown argument {flag}").into()),
        }
    }
    Ok(args)
}

/// vtracer's times per photograph and preset, from `vtracer-times.tsv`.
fn vtracer_times(dir: &Path) -> Result<HashMap<(String, String), f64>, Box<dyn Error>> {
    let path = dir.join("vtracer-times.tsv");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut times = HashMap::new();
    for line in text.lines() {
        let f: Vec<&str> = line.split('\t').collect();
        if let [stem, preset, seconds] = f[..] {
            times.insert((stem.to_string(), preset.to_string()), seconds.parse()?);
        }
    }
    Ok(times)
}

/// The two fits of one photograph at one budget.
fn fit_rows(
    stem: &str,
    image: &RgbaImage,
    budget: usize,
    args: &Args,
) -> Result<(), Box<dyn Error>> {
    let save = |kind: &str| {
        args.out
            .as_ref()
            .map(|d| d.join(format!("{stem}-{budget}-{kind}.png")))
    };
    let options = VectoriseOptions {
        points: Some(budget),
        quality: args.quality,
        fit_positions: args.fit_positions,
        round_output: args.round_output,
        ..VectoriseOptions::default()
    };
    let start = Instant::now();
    let v = vectorise(image, &options)?;
    let seconds = start.elapsed().as_secs_f64();
    let (mesh, pixels) = measure_document(&v.document, image, seconds, save("mesh"))?;
    if let Some(path) = save("mesh-error") {
        write_png(
            &path,
            image.width,
            image.height,
            &error_picture(image, &pixels),
        )?;
    }
    mesh.print(stem, &format!("quadtree mesh, {budget}"));
    let start = Instant::now();
    let mut g = grid(image.width as f64, image.height as f64, budget);
    fit_colours(&mut g, image, args.quality)?;
    let seconds = start.elapsed().as_secs_f64();
    let grid_doc = Document::new(vec![g]);
    let (grid, _) = measure_document(&grid_doc, image, seconds, save("grid"))?;
    grid.print(stem, &format!("regular grid, {budget}"));
    Ok(())
}

/// vtracer's SVG files of one photograph, rasterised by resvg and measured.
fn vtracer_rows(
    stem: &str,
    image: &RgbaImage,
    dir: &Path,
    times: &HashMap<(String, String), f64>,
    out: Option<&Path>,
) -> Result<(), Box<dyn Error>> {
    for preset in VTRACER_PRESETS {
        let svg = dir.join(format!("{stem}-vtracer-{preset}.svg"));
        let text = std::fs::read(&svg).map_err(|e| format!("{}: {e}", svg.display()))?;
        let pixels = render_svg(&svg, image.width, image.height)?;
        if let Some(out) = out {
            let png = out.join(format!("{stem}-vtracer-{preset}.png"));
            write_png(&png, image.width, image.height, &pixels)?;
        }
        let seconds = *times
            .get(&(stem.to_string(), preset.to_string()))
            .ok_or(format!("no time for {stem} {preset} in vtracer-times.tsv"))?;
        let row = Row::measure(image, &pixels, gzip_bytes(&text), seconds)?;
        row.print(stem, &format!("vtracer {preset}"));
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = parse_args()?;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata/images");
    let times = match &args.vtracer {
        Some(d) => vtracer_times(d)?,
        None => HashMap::new(),
    };
    if let Some(out) = &args.out {
        std::fs::create_dir_all(out)?;
    }
    println!("| photo | method | points | PSNR (dB) | mean ΔE00 | gzip -9 bytes | time (s) |");
    println!("|---|---|---|---|---|---|---|");
    for name in PHOTOS {
        let stem = name.split('.').next().expect("a file name");
        if args.only.as_ref().is_some_and(|o| o != stem) {
            continue;
        }
        let path = dir.join(name);
        let image = RgbaImage::read_path(&path, 1 << 28, 1 << 26)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        for &budget in &args.budgets {
            fit_rows(stem, &image, budget, &args)?;
        }
        if let Some(vt) = &args.vtracer {
            vtracer_rows(stem, &image, vt, &times, args.out.as_deref())?;
        }
    }
    Ok(())
}
