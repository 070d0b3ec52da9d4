//! Drawing on top of a rendered image: the outline of every layer, as a thin line.

use crate::error::{Error, ErrorKind};
use crate::mesh::Document;
use crate::refine::Refinement;

use super::pixels::Image;
use crate::limit_surface::boundary::boundary_loops;
use crate::render::options::RenderOptions;
use crate::render::raster::coverage::{Accumulator, Line};
use crate::render::tessellate::outline::outline;
use crate::view::ToPixels;

/// The colour of the outline: near-black, opaque (sRGB).
const OUTLINE_COLOUR: [f32; 3] = [0.08, 0.08, 0.08];

/// The four sides of a rectangle of half-width `hw` around segment `l`, extended by `hw` at both
/// ends (so that consecutive segments overlap at joins). All rectangles have the same
/// orientation, so overlaps add up and clamp to full coverage.
fn stroke(l: &Line, hw: f64, out: &mut Vec<Line>) {
    let (dx, dy) = (l.p1[0] - l.p0[0], l.p1[1] - l.p0[1]);
    let len = dx.hypot(dy);
    if len == 0.0 {
        return;
    }
    let (ux, uy) = (dx / len * hw, dy / len * hw);
    let (nx, ny) = (-uy, ux);
    let a = [l.p0[0] - ux + nx, l.p0[1] - uy + ny];
    let b = [l.p1[0] + ux + nx, l.p1[1] + uy + ny];
    let c = [l.p1[0] + ux - nx, l.p1[1] + uy - ny];
    let d = [l.p0[0] - ux - nx, l.p0[1] - uy - ny];
    for (p0, p1) in [(a, b), (b, c), (c, d), (d, a)] {
        out.push(Line { p0, p1 });
    }
}

/// Draws the outline of every layer (the limit boundary curves, discontinuous edges excluded:
/// they are inside the picture) over `image`, one pixel wide, anti-aliased, composited in
/// sRGB-encoded values. `opts` must be the options `image` was rendered with.
pub fn draw_outlines(doc: &Document, opts: &RenderOptions, image: &mut Image) -> Result<(), Error> {
    opts.check()?;
    if image.width != opts.width || image.height != opts.height {
        return Err(ErrorKind::Invalid {
            what: "image".into(),
            message: format!(
                "is {}x{}, the options say {}x{}",
                image.width, image.height, opts.width, opts.height
            ),
        }
        .into());
    }
    let xf = ToPixels::new(&opts.view, opts.width, opts.height);
    let mut lines = Vec::new();
    for (i, mesh) in doc.layers.iter().enumerate() {
        if mesh.faces.is_empty() {
            continue;
        }
        // The boundary curve is the same at every level from 1 on; level 2 is the first with
        // quads everywhere, where the corner rule is final.
        let (refinement, _) = Refinement::new(mesh, 2).map_err(|e| e.in_layer(i))?;
        let data = refinement.evaluate();
        let px: Vec<[f64; 2]> = data.levels[2]
            .iter()
            .map(|d| xf.apply(d.position[0], d.position[1]))
            .collect();
        let loops = boundary_loops(refinement.topology(2));
        for l in outline(refinement.level(2), &loops, &px, 0.02) {
            stroke(&l, 0.5, &mut lines);
        }
    }
    let (w, h) = (opts.width as usize, opts.height as usize);
    let mut acc = Accumulator::new(w, h);
    for l in &lines {
        acc.add(0, h, l);
    }
    let mut cov = vec![0.0f32; w];
    for j in 0..h {
        acc.resolve(j, 0, w, &mut cov);
        for (i, &a) in cov.iter().enumerate() {
            if a == 0.0 {
                continue;
            }
            let px = &mut image.data[4 * (j * w + i)..4 * (j * w + i) + 4];
            let da = px[3];
            let out_a = a + da * (1.0 - a);
            for c in 0..3 {
                let premul = OUTLINE_COLOUR[c] * a + px[c] * da * (1.0 - a);
                px[c] = if out_a > 0.0 { premul / out_a } else { 0.0 };
            }
            px[3] = out_a;
        }
    }
    Ok(())
}
