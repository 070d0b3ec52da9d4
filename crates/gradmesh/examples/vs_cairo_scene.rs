//! Renders the `vs_cairo` bench's scene once into an RGBA buffer, as the bench does, and
//! prints what it drew: a small process whose instructions can be counted.
//!
//! ```text
//! cargo build --release -p gradmesh --example vs_cairo_scene
//! RAYON_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no target/release/examples/vs_cairo_scene
//! ```
//!
//! `--plan-from-bounds` sets [`RenderOptions::plan_from_bounds`].

use gradmesh::render::{render_document_into, RenderOptions, View};

#[path = "../benches/common/wavy_grid.rs"]
mod wavy_grid;

fn main() -> Result<(), gradmesh::Error> {
    const SIZE: u32 = 1024;
    let doc = wavy_grid::document();
    let mut opts = RenderOptions::new(SIZE, SIZE, View::new(0.0, 0.0, SIZE as f64, SIZE as f64));
    opts.dither = false;
    opts.plan_from_bounds = std::env::args().any(|a| a == "--plan-from-bounds");
    let mut buffer = vec![0u8; 4 * (SIZE * SIZE) as usize];
    let info = render_document_into(&doc, &opts, &mut buffer)?;
    let layer = &info.layers[0];
    println!(
        "level {}, {} quads, {} triangles; prepare {:.2} ms, draw {:.2} ms",
        layer.level,
        layer.quads,
        layer.triangles,
        info.timings.prepare.as_secs_f64() * 1e3,
        info.timings.draw.as_secs_f64() * 1e3
    );
    // One pixel printed so that the render cannot be optimised away.
    let middle = 4 * (SIZE * SIZE / 2 + SIZE / 2) as usize;
    println!("middle pixel: {:?}", &buffer[middle..middle + 4]);
    Ok(())
}
