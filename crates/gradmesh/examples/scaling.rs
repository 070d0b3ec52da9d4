//! How render time scales: (a) one mesh (`examples/rectangle.json`) at 256² to 4096² pixels,
//! (b) generated meshes of 10, 100, 1,000 and 10,000 faces at 1024². Prints CSV: the median
//! of several runs, in milliseconds. Plot it with `scripts/plot_scaling.py`.
//!
//! ```text
//! cargo run --release -p gradmesh --example scaling -- [runs] > scaling.csv
//! python3 scripts/plot_scaling.py scaling.csv scaling.svg
//! ```

use std::error::Error;
use std::path::PathBuf;
use std::time::Instant;

use gradmesh::formats;
use gradmesh::render::{render_document, RenderOptions};
use gradmesh::{ColourSpace, Document, GradientMesh};
use kurbo::Point;

/// A jittered grid of `w` x `h` quads over a 1000-unit square, with smoothly varying colours.
fn grid(w: u32, h: u32) -> Document {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=h {
        for i in 0..=w {
            let (u, v) = (i as f64 / w as f64, j as f64 / h as f64);
            // Jitter inner points by up to a fifth of a cell, deterministically.
            let inner = i > 0 && i < w && j > 0 && j < h;
            let jitter = if inner { 0.2 } else { 0.0 };
            let (dx, dy) = (
                jitter * ((i * 7 + j * 13) % 11) as f64 / 10.0 - jitter / 2.0,
                jitter * ((i * 5 + j * 3) % 7) as f64 / 6.0 - jitter / 2.0,
            );
            m.add_point(
                Point::new(1000.0 * (u + dx / w as f64), 1000.0 * (v + dy / h as f64)),
                [
                    40.0 + 50.0 * u,
                    60.0 * (6.0 * v).sin(),
                    60.0 * (5.0 * u + 1.0).cos(),
                ],
            );
        }
    }
    for j in 0..h {
        for i in 0..w {
            let a = j * (w + 1) + i;
            m.add_face(vec![a, a + 1, a + w + 2, a + w + 1]);
        }
    }
    Document { layers: vec![m] }
}

/// The median time of `runs` renders, in milliseconds.
fn median_ms(doc: &Document, opts: &RenderOptions, runs: usize) -> Result<f64, Box<dyn Error>> {
    render_document(doc, opts)?; // warm up
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        let start = Instant::now();
        std::hint::black_box(render_document(doc, opts)?);
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

fn main() -> Result<(), Box<dyn Error>> {
    let runs: usize = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => 5,
    };
    println!("series,faces,width,height,pixels,ms");
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/rectangle.json");
    let doc = formats::read_path(&path)?;
    let faces = doc.layers.iter().map(|m| m.faces.len()).sum::<usize>();
    for side in [256, 512, 1024, 2048, 4096] {
        let opts = RenderOptions::fit(&doc, side);
        let ms = median_ms(&doc, &opts, runs)?;
        let (w, h) = (opts.width, opts.height);
        println!("pixels,{faces},{w},{h},{},{ms:.3}", w as u64 * h as u64);
    }
    for (w, h) in [(5, 2), (10, 10), (40, 25), (100, 100)] {
        let doc = grid(w, h);
        let opts = RenderOptions::fit(&doc, 1024);
        let ms = median_ms(&doc, &opts, runs)?;
        let (pw, ph) = (opts.width, opts.height);
        println!(
            "faces,{},{pw},{ph},{},{ms:.3}",
            w * h,
            pw as u64 * ph as u64
        );
    }
    Ok(())
}
