//! Builds a small gradient mesh in code, renders it into a buffer owned by the caller and writes
//! that buffer as a PNG.
//!
//! ```text
//! cargo run --release --example render_buffer -- [out.png] [size]
//! ```

use std::error::Error;

use gradmesh::render::{document_bounds, render_document_into, RenderOptions, View};
use gradmesh::{ColourSpace, Document, EdgeKind, GradientMesh};
use kurbo::Point;

/// A five-petal star around one extraordinary vertex (valence 5), in CIE Lab, with one petal
/// cut off by a discontinuous edge.
fn star() -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    let centre = mesh.add_point(Point::new(0.0, 0.0), [97.0, 0.0, 10.0]);
    let tau = std::f64::consts::TAU;
    let at = |r: f64, k: f64| {
        let a = tau * k / 5.0 - tau / 4.0;
        Point::new(r * a.cos(), r * a.sin())
    };
    let inner: Vec<u32> = (0..5)
        .map(|k| {
            let hue = tau * k as f64 / 5.0;
            mesh.add_point(
                at(60.0, k as f64),
                [70.0, 50.0 * hue.cos(), 50.0 * hue.sin()],
            )
        })
        .collect();
    let outer: Vec<u32> = (0..5)
        .map(|k| {
            let hue = tau * (k as f64 + 0.5) / 5.0;
            mesh.add_point(
                at(130.0, k as f64 + 0.5),
                [45.0, 60.0 * hue.cos(), 60.0 * hue.sin()],
            )
        })
        .collect();
    for k in 0..5 {
        mesh.add_face(vec![centre, inner[k], outer[k], inner[(k + 1) % 5]]);
    }
    // The edge between the centre and the first spoke is discontinuous: both sides keep the same
    // colours here, so it must not show.
    mesh.set_edge(centre, inner[0], EdgeKind::Discontinuous, None);
    mesh
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| "/tmp/render_buffer.png".into());
    let size: u32 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(512);

    let doc = Document::new(vec![star()]);
    let bounds = document_bounds(&doc).ok_or("empty document")?;
    println!("bounds: {bounds:?}");

    // The caller owns the buffer: 8-bit RGBA, straight alpha, sRGB.
    let mut opts = RenderOptions::fit(&doc, size);
    opts.background = Some([1.0, 1.0, 1.0, 1.0]);
    let View { x0, y0, x1, y1 } = opts.view;
    println!(
        "view ({x0:.1}, {y0:.1}) to ({x1:.1}, {y1:.1}) at {}x{}",
        opts.width, opts.height
    );
    let mut buffer = vec![0u8; 4 * opts.width as usize * opts.height as usize];
    let start = std::time::Instant::now();
    let info = render_document_into(&doc, &opts, &mut buffer)?;
    println!("rendered in {:.1} ms", start.elapsed().as_secs_f64() * 1e3);
    for (i, layer) in info.layers.iter().enumerate() {
        println!(
            "layer {i}: level {}, {} quads, largest quad {:.2} px, colour error {:.3}, outline deviation {:.3} px{}",
            layer.level,
            layer.quads,
            layer.max_quad_px,
            layer.max_colour_error,
            layer.max_outline_deviation_px,
            if layer.capped { " (capped)" } else { "" }
        );
    }
    for w in &info.warnings {
        println!("warning: {w}");
    }

    // Write the caller's buffer as an sRGB PNG.
    let file = std::io::BufWriter::new(std::fs::File::create(&path)?);
    let mut encoder = png::Encoder::new(file, opts.width, opts.height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    encoder.write_header()?.write_image_data(&buffer)?;
    println!("wrote {path}");
    Ok(())
}
