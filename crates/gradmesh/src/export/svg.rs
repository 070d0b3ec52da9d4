//! SVG output: one SVG 2 `<meshgradient>` per split patch grid, in sRGB, each filling its
//! box inside a group clipped to the layer's outline, over an optional PNG of the whole
//! document for viewers without mesh gradients.
//!
//! A mesh gradient's patches are Coons patches: their four sides are the limit surface's
//! Bézier boundary curves, exactly, but their inner control points are implied by the sides
//! rather than the surface's, so colours inside a patch sit up to a fraction of a pixel from
//! where the PDF (type 7, all sixteen points) puts them.
//!
//! A translucent layer's meshes are written opaque, and its opacity goes into a luminance mask
//! of the same meshes in grey (as the PDF's soft mask): Inkscape paints each mesh gradient
//! separately, and two translucent ones overlap along their common side, which would show as
//! a grid of darker seams. Opaque ones overlapping repaint the same colour.
//!
//! The PNG fallback is masked so that only viewers without mesh gradients show it: the mask is
//! a rectangle painted with a black mesh gradient whose fallback colour is white. A viewer that
//! draws mesh gradients (Inkscape) paints the mask black and hides the PNG; one that does not
//! (browsers, resvg) paints it white and shows the PNG. The meshes and the PNG never both show,
//! which would draw translucent layers twice.

use std::fmt::Write as _;

use super::split::{OutPatch, Target};
use super::surface::Curve;
use super::{layer_patches, ExportInfo, ExportLayer, ExportOptions, LayerPatches};
use crate::error::Error;
use crate::formats::svg::FillRule;
use crate::mesh::Document;
use crate::render::{
    encode_png, render_picture_into, Image, LayerSource, PictureLayer, PngDepth, RenderOptions,
};

/// What a mesh gradient paints: a layer's colours, or its opacity as grey (in the layer's
/// luminance mask).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Paint {
    Colour,
    Opacity,
}

/// The document as an SVG of the page size ([`ExportOptions::page_size_px`]) in CSS pixels,
/// drawn on a grid of `opts.width` x `opts.height`, and what was written. With `fallback`, a
/// PNG of the render lies beneath the meshes for viewers that do not draw mesh gradients
/// (browsers); a mask hides it from those that do (Inkscape).
pub fn write_svg(
    doc: &Document,
    opts: &ExportOptions,
    fallback: bool,
) -> Result<(Vec<u8>, ExportInfo), Error> {
    write_svg_picture(&ExportLayer::of_document(doc), opts, fallback)
}

/// [`write_svg`] of a picture whose layers may be SVG mesh gradients written as they are
/// ([`ExportLayer::SvgMesh`]: each patch a mesh patch of the same sides and corner colours,
/// oriented as in the source; a `type="bicubic"` one as the cells of its smoothed colours), the
/// fallback drawn by the renderer's classic painting of them.
pub fn write_svg_picture(
    picture: &[ExportLayer],
    opts: &ExportOptions,
    fallback: bool,
) -> Result<(Vec<u8>, ExportInfo), Error> {
    let (mut layers, mut info) = layer_patches(picture, opts, Target::Srgb)?;
    for layer in layers.iter_mut().filter(|l| l.colour.is_some()) {
        transpose(layer);
    }
    let start = std::time::Instant::now();
    let (w, h) = (opts.width, opts.height);
    let (page_w, page_h) = opts.page_size_px();
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="{page_w}" height="{page_h}" viewBox="0 0 {w} {h}">"#
    );
    if fallback {
        write_fallback(&mut out, picture, opts)?;
    }
    let mut mesh_id = 0usize;
    for (k, layer) in layers.iter().enumerate() {
        if !layer.patches.is_empty() {
            write_layer(&mut out, k, layer, (w, h), &mut mesh_id);
        }
    }
    out.push_str("</svg>\n");
    info.seconds += start.elapsed().as_secs_f64();
    Ok((out.into_bytes(), info))
}

/// Swaps the parameters of every patch of `layer`: the patches of an SVG mesh gradient
/// ([`super::classic`]) run `u` down the grid, as PDF's painting order wants, and the mesh
/// gradients written here run `u` along the rows. Their cells stay in order: row by row down
/// the grid.
fn transpose(layer: &mut LayerPatches) {
    for cell in &mut layer.patches {
        let corners = [0, 3, 2, 1];
        *cell = OutPatch {
            points: std::array::from_fn(|j| std::array::from_fn(|i| cell.points[i][j])),
            colours: corners.map(|c| cell.colours[c]),
            opacity: corners.map(|c| cell.opacity[c]),
        };
    }
}

/// The page grown by a pixel on every side, as a mask's region: the edges of what a mask
/// holds then lie outside the page.
fn page_region((w, h): (u32, u32)) -> String {
    format!(r#"x="-1" y="-1" width="{}" height="{}""#, w + 2, h + 2)
}

/// The PNG of the render, masked so that viewers that draw mesh gradients hide it (see the
/// module's notes).
fn write_fallback(
    out: &mut String,
    picture: &[ExportLayer],
    opts: &ExportOptions,
) -> Result<(), Error> {
    let (w, h) = (opts.width, opts.height);
    let layers: Vec<PictureLayer> = picture
        .iter()
        .map(|layer| match *layer {
            ExportLayer::Scheme(mesh) => PictureLayer {
                source: LayerSource::Scheme(mesh),
                clip: None,
            },
            ExportLayer::SvgMesh(fill) => PictureLayer {
                source: LayerSource::Classic(fill),
                clip: Some((&fill.clip, fill.fill_rule)),
            },
        })
        .collect();
    let render_opts = RenderOptions::new(w, h, opts.view);
    render_opts.check()?;
    let mut image = Image::new(w, h);
    render_picture_into(&layers, &render_opts, &mut image.data)?;
    let png = encode_png(&image, PngDepth::Eight { dither: true })?;
    let (bw, bh) = (w + 2, h + 2);
    let black = r##"stop-color="#000000""##;
    let _ = writeln!(
        out,
        r#"<meshgradient id="fallback-hider" gradientUnits="userSpaceOnUse" x="-1" y="-1"><meshrow><meshpatch><stop path="c 0,0 {bw},0 {bw},0" {black}/><stop path="c 0,0 0,{bh} 0,{bh}" {black}/><stop path="c 0,0 -{bw},0 -{bw},0" {black}/><stop path="c 0,0 0,-{bh} 0,-{bh}" {black}/></meshpatch></meshrow></meshgradient>"#
    );
    let region = page_region((w, h));
    let _ = writeln!(
        out,
        r##"<mask id="fallback" maskUnits="userSpaceOnUse" {region}><rect {region} fill="url(#fallback-hider) #ffffff"/></mask>"##
    );
    let _ = writeln!(
        out,
        r#"<image width="{w}" height="{h}" mask="url(#fallback)" xlink:href="data:image/png;base64,{}"/>"#,
        base64(&png)
    );
    Ok(())
}

/// Layer `k`: its outline as a clip path, its meshes (`mesh{id}`, numbered on from `mesh_id`)
/// in a group clipped to it, and for a translucent layer its opacity as a luminance mask of
/// grey meshes (`opacity-mesh{id}`) on that group.
fn write_layer(
    out: &mut String,
    k: usize,
    layer: &LayerPatches,
    page: (u32, u32),
    mesh_id: &mut usize,
) {
    let _ = writeln!(
        out,
        r#"<clipPath id="outline{k}"><path clip-rule="{}" d="{}"/></clipPath>"#,
        match layer.clip_rule {
            FillRule::NonZero => "nonzero",
            FillRule::EvenOdd => "evenodd",
        },
        outline_path(&layer.outline)
    );
    if layer.masked {
        let _ = writeln!(
            out,
            r#"<mask id="layer-opacity{k}" maskUnits="userSpaceOnUse" {}>"#,
            page_region(page)
        );
        write_meshes(out, layer, *mesh_id, Paint::Opacity);
        out.push_str("</mask>\n");
        let _ = writeln!(
            out,
            r#"<g clip-path="url(#outline{k})" mask="url(#layer-opacity{k})">"#
        );
    } else {
        let _ = writeln!(out, r#"<g clip-path="url(#outline{k})">"#);
    }
    write_meshes(out, layer, *mesh_id, Paint::Colour);
    *mesh_id += layer.grids.len();
    out.push_str("</g>\n");
}

/// Every split grid of `layer` as a mesh gradient painting `paint`, numbered from `first`.
fn write_meshes(out: &mut String, layer: &LayerPatches, first: usize, paint: Paint) {
    let prefix = match paint {
        Paint::Colour => "mesh",
        Paint::Opacity => "opacity-mesh",
    };
    for (i, grid) in layer.grids.iter().enumerate() {
        let cells = &layer.patches[grid.first..grid.first + grid.n * grid.m];
        let id = format!("{prefix}{}", first + i);
        write_mesh(out, &id, cells, (grid.n, grid.m), paint);
    }
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

/// The stop colour of corner `c` of `cell`: its colour, or its opacity as grey. Opacity is
/// never a stop's own (`stop-opacity`): see the module's notes.
fn stop(cell: &OutPatch, c: usize, paint: Paint) -> String {
    let rgb = match paint {
        Paint::Colour => cell.colours[c],
        Paint::Opacity => [cell.opacity[c]; 3],
    };
    let hex = rgb.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
    format!(
        r##"stop-color="#{:02x}{:02x}{:02x}""##,
        hex[0], hex[1], hex[2]
    )
}

/// The `n x m` cells (row by row) of one split patch as mesh gradient `id` painting `paint`,
/// and a box it fills.
fn write_mesh(
    out: &mut String,
    id: &str,
    cells: &[OutPatch],
    (n, m): (usize, usize),
    paint: Paint,
) {
    let origin = cells[0].points[0][0];
    let _ = writeln!(
        out,
        r#"<meshgradient id="{id}" gradientUnits="userSpaceOnUse" x="{}" y="{}">"#,
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
                    stop(cell, corner, paint)
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
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="url(#{id}) none"/>"#,
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
