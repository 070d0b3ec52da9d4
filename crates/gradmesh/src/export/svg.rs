//! SVG output: one SVG 2 `<meshgradient>` per split patch grid, in sRGB, each filling its
//! box inside a group clipped to the layer's outline, over an optional PNG of the whole
//! document for viewers without mesh gradients.
//!
//! A mesh gradient's patches are Coons patches: their four sides are the limit surface's
//! Bézier boundary curves, exactly, but their inner control points are implied by the sides
//! rather than the surface's, so colours inside a patch sit up to a fraction of a pixel from
//! where the PDF (type 7, all sixteen points) puts them.

use std::fmt::Write as _;

use super::split::{OutPatch, Target};
use super::surface::Curve;
use super::{layer_patches, ExportInfo, ExportOptions};
use crate::error::Error;
use crate::mesh::Document;
use crate::render::{encode_png, render_image, PngDepth, RenderOptions};

/// The document as an SVG of the page size ([`ExportOptions::page_size_px`]) in CSS pixels,
/// drawn on a grid of `opts.width` x `opts.height`, with a PNG of the render
/// beneath the meshes when `fallback` is set (browsers show it; Inkscape draws the meshes
/// over it), and what was written.
pub fn write_svg(
    doc: &Document,
    opts: &ExportOptions,
    fallback: bool,
) -> Result<(Vec<u8>, ExportInfo), Error> {
    let (layers, mut info) = layer_patches(doc, opts, Target::Srgb)?;
    let start = std::time::Instant::now();
    let (w, h) = (opts.width, opts.height);
    let (page_w, page_h) = opts.page_size_px();
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="{page_w}" height="{page_h}" viewBox="0 0 {w} {h}">"#
    );
    if fallback {
        let (image, _) = render_image(doc, &RenderOptions::new(w, h, opts.view))?;
        let png = encode_png(&image, PngDepth::Eight { dither: true })?;
        let _ = writeln!(
            out,
            r#"<image width="{w}" height="{h}" xlink:href="data:image/png;base64,{}"/>"#,
            base64(&png)
        );
    }
    let mut mesh_id = 0usize;
    for (k, layer) in layers.iter().enumerate() {
        if layer.patches.is_empty() {
            continue;
        }
        let _ = writeln!(
            out,
            r#"<clipPath id="outline{k}"><path clip-rule="nonzero" d="{}"/></clipPath>"#,
            outline_path(&layer.outline)
        );
        let _ = writeln!(out, r#"<g clip-path="url(#outline{k})">"#);
        for grid in &layer.grids {
            let cells = &layer.patches[grid.first..grid.first + grid.n * grid.m];
            write_mesh(&mut out, mesh_id, cells, grid.n, grid.m);
            mesh_id += 1;
        }
        out.push_str("</g>\n");
    }
    out.push_str("</svg>\n");
    info.seconds += start.elapsed().as_secs_f64();
    Ok((out.into_bytes(), info))
}

/// The loops of `outline` as path data.
fn outline_path(outline: &[Vec<Curve>]) -> String {
    let mut d = String::new();
    for curves in outline {
        let Some(first) = curves.first() else {
            continue;
        };
        let _ = write!(d, "M{} {}", num(first[0][0]), num(first[0][1]));
        for c in curves {
            let _ = write!(
                d,
                "C{} {} {} {} {} {}",
                num(c[1][0]),
                num(c[1][1]),
                num(c[2][0]),
                num(c[2][1]),
                num(c[3][0]),
                num(c[3][1])
            );
        }
        d.push('Z');
    }
    d
}

/// A coordinate with 1/1000 pixel, without trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{:.3}", x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// The side of `cell` from corner `a` to corner `b` (`(i, j)` places in its net) through the
/// two points between, as a relative `c` command.
fn side(cell: &OutPatch, points: [(usize, usize); 4]) -> String {
    let p = points.map(|(i, j)| cell.points[j][i]);
    let rel = |q: [f64; 2]| format!("{},{}", num(q[0] - p[0][0]), num(q[1] - p[0][1]));
    format!("c {} {} {}", rel(p[1]), rel(p[2]), rel(p[3]))
}

/// The stop colour of corner `c` of `cell`.
fn stop(cell: &OutPatch, c: usize) -> String {
    let hex = cell.colours[c].map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
    let colour = format!("#{:02x}{:02x}{:02x}", hex[0], hex[1], hex[2]);
    let alpha = cell.opacity[c].clamp(0.0, 1.0);
    if alpha < 1.0 {
        format!(r#"stop-color="{colour}" stop-opacity="{}""#, num(alpha))
    } else {
        format!(r#"stop-color="{colour}""#)
    }
}

/// The `n x m` cells (row by row) of one split patch as a mesh gradient, and a box it fills.
fn write_mesh(out: &mut String, id: usize, cells: &[OutPatch], n: usize, m: usize) {
    let origin = cells[0].points[0][0];
    let _ = writeln!(
        out,
        r#"<meshgradient id="mesh{id}" gradientUnits="userSpaceOnUse" x="{}" y="{}">"#,
        num(origin[0]),
        num(origin[1])
    );
    const TOP: [(usize, usize); 4] = [(0, 0), (1, 0), (2, 0), (3, 0)];
    const RIGHT: [(usize, usize); 4] = [(3, 0), (3, 1), (3, 2), (3, 3)];
    const BOTTOM: [(usize, usize); 4] = [(3, 3), (2, 3), (1, 3), (0, 3)];
    const LEFT: [(usize, usize); 4] = [(0, 3), (0, 2), (0, 1), (0, 0)];
    for r in 0..m {
        out.push_str("<meshrow>");
        for c in 0..n {
            let cell = &cells[r * n + c];
            out.push_str("<meshpatch>");
            // The sides not shared with the patch above or to the left, each with the colour
            // of the corner it starts from (corners (0, 0), (1, 0), (1, 1), (0, 1)).
            let mut put = |points, corner| {
                let _ = write!(
                    out,
                    r#"<stop path="{}" {}/>"#,
                    side(cell, points),
                    stop(cell, corner)
                );
            };
            if r == 0 {
                put(TOP, 0);
            }
            put(RIGHT, 1);
            put(BOTTOM, 2);
            if c == 0 {
                put(LEFT, 3);
            }
            out.push_str("</meshpatch>");
        }
        out.push_str("</meshrow>\n");
    }
    out.push_str("</meshgradient>\n");
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in cells.iter().flat_map(|c| c.points.iter().flatten()) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    // A pixel wider than the mesh: its edge's anti-aliasing falls where the mesh paints nothing.
    let _ = writeln!(
        out,
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="url(#mesh{id}) none"/>"#,
        num(lo[0] - 1.0),
        num(lo[1] - 1.0),
        num(hi[0] - lo[0] + 2.0),
        num(hi[1] - lo[1] + 2.0)
    );
}

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let v = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(v >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_of_known_strings() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(num(1.5), "1.5");
        assert_eq!(num(2.0), "2");
        assert_eq!(num(-0.0001), "0");
        assert_eq!(num(12.3456), "12.346");
    }
}
