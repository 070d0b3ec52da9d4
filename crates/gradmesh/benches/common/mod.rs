//! The meshes the benchmarks share.

// Each bench uses part of this.
#![allow(dead_code)]

pub mod jittered_grid;
pub mod wavy_grid;

use gradmesh::render::{
    render_document_into_cached, GamutMapping, OutputPixel, RenderCache, RenderInfo, RenderOptions,
};
use gradmesh::{ColourSpace, Document, GradientMesh};
use kurbo::Point;

/// The drawing stage alone: renders `doc` through `cache`, whose layers stay prepared, with
/// every pixel drawn again. Each call switches the gamut mapping between chroma reduction and
/// clipping: a drawing-only option, so the cache keeps the prepared layers but not the last
/// image. (Only out-of-gamut pixels, none in an sRGB scene and 131 of Tucan's at 1024 px,
/// cost differently under the two.)
pub fn draw_again<P: OutputPixel>(
    doc: &Document,
    opts: &mut RenderOptions,
    cache: &mut RenderCache,
    buffer: &mut [P],
) -> RenderInfo {
    opts.gamut = match opts.gamut {
        GamutMapping::Chroma => GamutMapping::Clip,
        GamutMapping::Clip => GamutMapping::Chroma,
    };
    render_document_into_cached(doc, opts, cache, buffer).expect("a render")
}

/// Checks that [`draw_again`] draws every pixel of `opts`' image from prepared layers only.
pub fn check_draws_only<P: OutputPixel>(
    doc: &Document,
    opts: &mut RenderOptions,
    cache: &mut RenderCache,
    buffer: &mut [P],
) {
    render_document_into_cached(doc, opts, cache, buffer).expect("a render");
    let info = draw_again(doc, opts, cache, buffer);
    assert!(
        info.layers.iter().all(|l| l.reused),
        "layers prepared again"
    );
    assert_eq!(
        info.drawn_pixels,
        u64::from(opts.width) * u64::from(opts.height),
        "not every pixel drawn"
    );
}

/// A jittered grid of `n` x `n` cells, every third cell split into two triangles: about
/// 1.33 n^2 faces of mixed sizes.
pub fn mesh(n: u32) -> GradientMesh {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=n {
        for i in 0..=n {
            let jitter = ((i * 7 + j * 13) % 10) as f64 * 0.02;
            m.add_point(
                Point::new(i as f64 + jitter, j as f64 - jitter),
                [(i % 100) as f64, (j % 50) as f64, 0.0],
            );
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            let (a, b, c, d) = (v, v + 1, v + n + 2, v + n + 1);
            if (i + j) % 3 == 0 {
                m.add_face(vec![a, b, c]);
                m.add_face(vec![a, c, d]);
            } else {
                m.add_face(vec![a, b, c, d]);
            }
        }
    }
    m
}
