//! A PDF patch-mesh shading (types 6 and 7) painted as the PDF specification defines it: a
//! source of triangles for the same rasteriser and compositor that draw the scheme.
//!
//! Each patch is its tensor-product surface; its colour is the corner components interpolated
//! bilinearly in the patch's parameters, in the shading's colour space, and only then converted
//! (through the shading's function when it has one). The conversion is made at every vertex of
//! the tessellation, so that a non-affine one (CMYK, Lab, a function) is exact there and
//! linear in sRGB within cells of a few pixels.
//!
//! Tessellation: every patch of a shading is cut into the same `n x n` grid of cells in its
//! parameters, each cell into two triangles, drawn in stream order and within a patch in the
//! order the specification gives fold-overs (larger `v` later, then larger `u`). A sample on a
//! side is evaluated from that side's own cubic, from whichever end is nearer, so two patches
//! sharing a side (by an edge flag, or by equal points) meet at bit-identical vertices and the
//! rasteriser's top-left rule leaves no crack.
//!
//! Coverage: the union of the triangles, and along the outline the exact area inside the
//! patches' sides (sides that two patches run in opposite directions cancel and are left out);
//! the clipping path, when there is one, decides the anti-aliased edge.

use std::collections::HashMap;
use std::time::Instant;

use kurbo::{BezPath, PathEl, Point};
use rayon::prelude::*;

use crate::colour::ColourSpace;
use crate::error::{Error, ErrorKind};
use crate::formats::pdf::{Patch, ShadingFill};
use crate::render::info::{LayerInfo, LayerTimings};
use crate::render::options::RenderOptions;
use crate::render::raster::coverage::Line;
use crate::render::raster::triangles::{screen_triangle_px, Triangle, TriangleList, UNBOUNDED};
use crate::render::tessellate::layer::{
    bin_triangles, visible_outline, DrawableLayer, LayerPreparation, BAND,
};
use crate::render::tessellate::nearest::{NearestSegments, Segment};
use crate::view::ToPixels;

/// The widest a cell may be (pixels, along each parameter).
const CELL_PX: f64 = 4.0;
/// ... in reference mode.
const REFERENCE_CELL_PX: f64 = 1.0;
/// The most cells along one side of a patch.
const MAX_CELLS_PER_SIDE: usize = 1024;
/// Flattening tolerance of the outline (pixels), as for a layer's own outline.
const OUTLINE_TOLERANCE_PX: f64 = 0.002;

/// Prepares `fill` for drawing with `opts` (never clipped: the caller adds the clip). A
/// shading with more patches than [`RenderOptions::max_quads`] is refused before any cell is
/// made.
pub(crate) fn prepare(
    fill: &ShadingFill,
    opts: &RenderOptions,
    xf: &ToPixels,
) -> Result<LayerPreparation, Error> {
    let start = Instant::now();
    let count = fill.patches.len() as u64;
    if count > opts.max_quads as u64 {
        return Err(ErrorKind::LimitExceeded {
            what: format!("cells of the patches of {}", fill.object),
            found: count,
            limit: opts.max_quads as u64,
        }
        .into());
    }
    let patches: Vec<PixelPatch> = fill
        .patches
        .iter()
        .map(|p| PixelPatch::new(p, xf))
        .collect();
    let (n, capped) = cells_per_side(&patches, opts);
    let size = (opts.width as i64, opts.height as i64);
    let chunks = patches
        .par_iter()
        .zip(&fill.patches)
        .enumerate()
        .map(|(index, (pixel, patch))| pixel.triangles((index, patch), fill, n, size))
        .collect();
    let triangles = TriangleList::from_chunks(chunks);
    let bands = (opts.height as usize).div_ceil(BAND);
    let triangle_bins = bin_triangles(&triangles, bands, opts.height as i64);
    let outer = outer_sides(&patches);
    let lines: Vec<Line> = outer
        .iter()
        .flat_map(|&(p, s)| {
            let mut side = patches[p].sides[s];
            if patches[p].reversed {
                side.reverse();
            }
            side_lines(&side)
        })
        .collect();
    let segments = outer
        .iter()
        .flat_map(|&(p, s)| side_segments(&patches[p], (p, &fill.patches[p]), fill, s, n))
        .collect();
    let (lines, line_bins, columns) = visible_outline(lines, opts, bands);
    let info = LayerInfo {
        level: 0,
        capped,
        quads: fill.patches.len() * n * n,
        triangles: triangles.len(),
        max_quad_px: f64::NAN,
        max_outline_deviation_px: f64::NAN,
        max_colour_error: f64::NAN,
        estimated: false,
        timings: LayerTimings {
            tessellate: start.elapsed(),
            ..LayerTimings::default()
        },
        reused: false,
        reused_faces: 0,
    };
    if lines.is_empty() || columns.0 >= columns.1 {
        return Ok((info, None, Vec::new()));
    }
    let layer = DrawableLayer {
        space: ColourSpace::Srgb,
        triangles,
        triangle_bins,
        lines,
        line_bins,
        nearest: NearestSegments::new(segments),
        columns,
        bounds: None,
        colours_in_unit_range: true,
        clip: None,
        covered_by_triangles: true,
    };
    Ok((info, Some(layer), Vec::new()))
}

/// Cells along each side of every patch: enough that the longest side's control polygon has
/// cells within the cell size, and at most [`RenderOptions::max_quads`] in all (with whether
/// that limit made them larger).
fn cells_per_side(patches: &[PixelPatch], opts: &RenderOptions) -> (usize, bool) {
    let longest = patches
        .iter()
        .flat_map(|p| p.sides.iter())
        .map(|s| (0..3).map(|k| s[k].distance(s[k + 1])).sum::<f64>())
        .fold(0.0, f64::max);
    let cell = if opts.reference {
        REFERENCE_CELL_PX
    } else {
        CELL_PX
    }
    .min(opts.max_quad_px);
    let wanted = (longest / cell).ceil();
    let wanted = if wanted.is_finite() {
        (wanted.max(1.0) as usize).min(MAX_CELLS_PER_SIDE)
    } else {
        1
    };
    let fit = ((opts.max_quads / patches.len().max(1)) as f64)
        .sqrt()
        .floor() as usize;
    let n = wanted.min(fit.max(1));
    (n, n < wanted)
}

/// A patch in pixels: its 16 points and its four sides (in the order of [`Patch::sides`]).
struct PixelPatch {
    points: [[Point; 4]; 4],
    sides: [[Point; 4]; 4],
    /// Whether the corners run counter-clockwise on the image: the outline is run the other way
    /// round, so that every patch covers with the same sign.
    reversed: bool,
}

impl PixelPatch {
    fn new(patch: &Patch, xf: &ToPixels) -> Self {
        let px = |q: Point| {
            let [x, y] = xf.apply(q.x, q.y);
            Point::new(x, y)
        };
        let points = patch.points.map(|row| row.map(px));
        let shape = Patch {
            points,
            components: Vec::new(),
        };
        PixelPatch {
            points,
            sides: shape.sides(),
            reversed: shape.corner_area() < 0.0,
        }
    }

    /// The position at step `a` of `n` along `u` and `b` of `n` along `v`: on a side, that
    /// side's own point.
    fn position(&self, a: usize, b: usize, n: usize) -> Point {
        match (a, b) {
            (0, _) => side_point(&self.sides[0], b, n),
            (_, _) if b == n => side_point(&self.sides[1], a, n),
            (_, _) if a == n => side_point(&self.sides[2], n - b, n),
            (_, 0) => side_point(&self.sides[3], n - a, n),
            _ => {
                let shape = Patch {
                    points: self.points,
                    components: Vec::new(),
                };
                shape.eval(a as f64 / n as f64, b as f64 / n as f64)
            }
        }
    }

    /// The patch's triangles with `n x n` cells, for an image of `size` pixels: none when its
    /// control points all lie beside the image.
    fn triangles(
        &self,
        (index, patch): (usize, &Patch),
        fill: &ShadingFill,
        n: usize,
        size: (i64, i64),
    ) -> Vec<Triangle> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in self.points.iter().flatten() {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
        let (w, h) = (size.0 as f64, size.1 as f64);
        if hi[0] < 0.0 || hi[1] < 0.0 || lo[0] > w || lo[1] > h {
            return Vec::new();
        }
        let vertex = |a: usize, b: usize| {
            let p = self.position(a, b, n);
            let (u, v) = (a as f64 / n as f64, b as f64 / n as f64);
            let c = fill.srgb_at(patch, u, v);
            ([p.x, p.y], [c[0], c[1], c[2], fill.opacity_at(index, u, v)])
        };
        let mut row: Vec<([f64; 2], [f64; 4])> = (0..=n).map(|a| vertex(a, 0)).collect();
        let mut out = Vec::with_capacity(2 * n * n);
        for b in 0..n {
            let next: Vec<_> = (0..=n).map(|a| vertex(a, b + 1)).collect();
            for a in 0..n {
                let (v00, v01, v10, v11) = (row[a], next[a], row[a + 1], next[a + 1]);
                for tri in [[v00, v01, v11], [v00, v11, v10]] {
                    let exact = tri.map(|v| v.0);
                    let attr = tri.map(|v| v.1);
                    out.extend(screen_triangle_px(exact, attr, None, &UNBOUNDED, size));
                }
            }
            row = next;
        }
        out
    }
}

/// The point at step `k` of `n` along the cubic `side`, evaluated from the nearer end, so that
/// the same side run the other way gives the same bits.
fn side_point(side: &[Point; 4], k: usize, n: usize) -> Point {
    if 2 * k <= n {
        de_casteljau(side, k as f64 / n as f64)
    } else {
        let reversed = [side[3], side[2], side[1], side[0]];
        de_casteljau(&reversed, (n - k) as f64 / n as f64)
    }
}

fn de_casteljau(c: &[Point; 4], t: f64) -> Point {
    let l = |a: Point, b: Point| a.lerp(b, t);
    let (a, b, d) = (l(c[0], c[1]), l(c[1], c[2]), l(c[2], c[3]));
    let (e, f) = (l(a, b), l(b, d));
    l(e, f)
}

/// A side by the bits of its four points.
type SideKey = [(u64, u64); 4];
/// A side of a patch: `(patch, side)`.
type SideOf = (usize, usize);

/// The sides `(patch, side)` on the mesh's outline: every side but those that two patches run
/// in opposite directions (shared by neighbours of the same orientation), each run the way
/// that gives every patch the same orientation.
fn outer_sides(patches: &[PixelPatch]) -> Vec<(usize, usize)> {
    let bits = |s: &[Point; 4]| s.map(|p| (p.x.to_bits(), p.y.to_bits()));
    // Sides keyed by their points from the lesser end, with the count of each direction.
    let mut seen: HashMap<SideKey, (Vec<SideOf>, Vec<SideOf>)> = HashMap::new();
    for (p, patch) in patches.iter().enumerate() {
        for (s, side) in patch.sides.iter().enumerate() {
            let forward = bits(side);
            let mut backward = forward;
            backward.reverse();
            let ran_forward = (forward <= backward) != patch.reversed;
            let entry = seen.entry(forward.min(backward)).or_default();
            if ran_forward {
                entry.0.push((p, s));
            } else {
                entry.1.push((p, s));
            }
        }
    }
    let mut out: Vec<(usize, usize)> = seen
        .into_values()
        .flat_map(|(mut f, mut b)| {
            let common = f.len().min(b.len());
            f.drain(..common);
            b.drain(..common);
            f.into_iter().chain(b)
        })
        .collect();
    out.sort_unstable();
    out
}

/// The lines of `side` flattened (in pixels), not closed.
fn side_lines(side: &[Point; 4]) -> Vec<Line> {
    let mut path = BezPath::new();
    path.move_to(side[0]);
    path.curve_to(side[1], side[2], side[3]);
    let mut lines = Vec::new();
    let mut last = side[0];
    kurbo::flatten(&path, OUTLINE_TOLERANCE_PX, |el| {
        if let PathEl::LineTo(p) = el {
            lines.push(Line {
                p0: [last.x, last.y],
                p1: [p.x, p.y],
            });
            last = p;
        }
    });
    lines.retain(|l| l.p0.iter().chain(&l.p1).all(|v| v.is_finite()));
    lines
}

/// The segments of side `s` of a patch with the colours at their ends, for outline pixels
/// whose centre no triangle covers.
fn side_segments(
    pixel: &PixelPatch,
    (index, patch): (usize, &Patch),
    fill: &ShadingFill,
    s: usize,
    n: usize,
) -> Vec<Segment> {
    // Side s in (a, b) steps: u = 0 (v rising), v = 1 (u rising), u = 1 (v falling), v = 0 (u falling).
    let step = |k: usize| match s {
        0 => (0, k),
        1 => (k, n),
        2 => (n, n - k),
        _ => (n - k, 0),
    };
    let vertices: Vec<([f64; 2], [f32; 4])> = (0..=n)
        .map(|k| {
            let (a, b) = step(k);
            let p = pixel.position(a, b, n);
            let (u, v) = (a as f64 / n as f64, b as f64 / n as f64);
            let c = fill.srgb_at(patch, u, v);
            let alpha = fill.opacity_at(index, u, v);
            ([p.x, p.y], [c[0], c[1], c[2], alpha].map(|x| x as f32))
        })
        .collect();
    vertices
        .windows(2)
        .map(|w| Segment {
            a: w[0].0,
            b: w[1].0,
            ca: w[0].1,
            cb: w[1].1,
            bump: [0.0; 4],
        })
        .collect()
}
