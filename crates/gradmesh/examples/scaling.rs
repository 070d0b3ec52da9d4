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
use gradmesh::Document;

#[path = "../benches/common/jittered_grid.rs"]
mod jittered_grid;
use jittered_grid::grid;

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
    for (w, h) in jittered_grid::SIZES {
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
