//! An editor's loop over multi-resolution edits: the topology is refined once, then every change
//! of an edit re-evaluates the data only.
//!
//! `cargo run --release -p gradmesh --example multires_edit [FILE.json] [LEVELS]` (default:
//! `examples/multires.json`, 5 levels) prints the time of a rebuild from scratch and of a
//! re-evaluation after an edit.

use std::time::Instant;

use gradmesh::formats::read_path;
use gradmesh::{ColourEdit, Edit, Refinement, VertexAddress};

fn main() -> Result<(), gradmesh::Error> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/multires.json").to_string()
    });
    let levels: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(5);
    let doc = read_path(std::path::Path::new(&path))?;
    let mut mesh = doc.layers[0].clone();

    let start = Instant::now();
    let (mut refinement, _) = Refinement::new(&mesh, levels)?;
    let data = refinement.evaluate();
    let rebuild = start.elapsed();
    let vertices = data.levels[levels].len();

    // Drag a colour edit about: a new colour at the centre of face 0, evaluated each time.
    let corner = mesh.faces[0][0];
    let centre = VertexAddress::new(2, 0, corner, [3, 3]);
    let rounds = 20;
    let start = Instant::now();
    for k in 0..rounds {
        let lightness = 20.0 + 3.0 * k as f64;
        mesh.set_edit(Edit {
            colour: Some(ColourEdit::Set([lightness, 0.0, 0.0])),
            ..Edit::new(centre)
        });
        refinement.set_edits(&mesh.edits, mesh.fine_edits)?;
        let data = refinement.evaluate();
        assert_eq!(data.levels[levels].len(), vertices);
    }
    let reevaluate = start.elapsed() / rounds;
    println!(
        "{path}: level {levels}, {vertices} vertices, {} edits",
        mesh.edits.len()
    );
    println!("rebuild (validation, topology, stencils, data): {rebuild:.2?}");
    println!("re-evaluation after an edit (data only):       {reevaluate:.2?}");
    Ok(())
}
