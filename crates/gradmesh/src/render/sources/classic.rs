//! The classic painting of an SVG mesh gradient, as the SVG 2 draft and Inkscape define it: a
//! source of triangles for the same rasteriser and compositor that draw the scheme.
//!
//! Each patch is a Coons patch of its four cubic sides (the tensor-product patch with the
//! Coons interior points is the same surface). Its colour is bilinear in the patch's
//! parameters, in sRGB-encoded values, and so is its opacity (stop-opacity times
//! fill-opacity and the group opacity). With `type="bicubic"` the colours are smoothed across
//! patches as Inkscape does (see `formats::svg::paint`'s `bicubic_lattices`): the colour of each patch becomes
//! bilinear over an 8 x 8 lattice of Hermite-interpolated values.
//!
//! Tessellation: every patch is cut into a grid of cells in its parameters, each cell into two
//! triangles whose corners carry the patch's position and colour there. All patches of a grid
//! column share their count across, all patches of a grid row their count down, and samples on
//! a side are evaluated from that side's own curve: neighbouring patches meet at bit-identical
//! vertices, so the rasteriser's top-left rule leaves no crack. Counts are multiples of the
//! colour lattice, so no cell straddles a line where the colour's slope breaks. The triangles
//! are drawn in patch order, and within a patch in the order Cairo paints (higher `v`, along
//! the top side, later; then higher `u`), so that where patches fold, the later one shows.
//!
//! The mesh covers the union of its triangles (where patches fold beyond the mesh's outline
//! too, as Cairo paints them) and, along its outline, the outline's exact area; the clip to
//! the shape, which SVG always has, decides the anti-aliased edge.

use std::time::Instant;

use kurbo::{BezPath, CubicBez, ParamCurve, Point, Shape};
use rayon::prelude::*;

use crate::colour::ColourSpace;
use crate::error::{Error, ErrorKind};
use crate::formats::svg::paint::{colour_lattices, Lattice, BICUBIC_SPLIT};
use crate::formats::svg::{MeshFill, MeshGrid, MeshType};
use crate::render::info::{LayerInfo, LayerTimings};
use crate::render::options::RenderOptions;
use crate::render::raster::triangles::{screen_triangle_px, Triangle, TriangleList, UNBOUNDED};
use crate::render::tessellate::clip::clip_lines;
use crate::render::tessellate::layer::{
    bin_triangles, visible_outline, DrawableLayer, LayerPreparation, BAND,
};
use crate::render::tessellate::nearest::{NearestSegments, Segment};
use crate::view::ToPixels;

/// The widest a cell may be (pixels, along each parameter): colour is bilinear in the patch's
/// parameters, and a cell's two triangles interpolate it linearly in the plane; over a cell of
/// this size the difference is far under an 8-bit step for any patch larger than a few cells.
const CELL_PX: f64 = 4.0;
/// ... in reference mode.
const REFERENCE_CELL_PX: f64 = 1.0;
/// The most cells along one side of a patch.
const MAX_CELLS_PER_SIDE: usize = 1024;

/// The cells [`prepare`] tessellates `fill`'s mesh into with `opts`: each holds two triangles
/// and its share of the bands' bins, what the layer's drawing keeps in memory.
pub(crate) fn cells(fill: &MeshFill, opts: &RenderOptions, xf: &ToPixels) -> usize {
    let k = match fill.mesh.kind {
        MeshType::Bicubic => BICUBIC_SPLIT,
        MeshType::Bilinear | MeshType::Coons => 1,
    };
    CellCounts::new(&fill.mesh, k, opts, xf).cells()
}

/// Prepares `fill`'s mesh for drawing with `opts` (never clipped: the caller adds the clip).
/// A mesh whose patches need more cells than [`RenderOptions::max_quads`] at the least (one
/// per patch, or one per lattice cell of `type="bicubic"`) is refused before any is made.
pub(crate) fn prepare(
    fill: &MeshFill,
    opts: &RenderOptions,
    xf: &ToPixels,
) -> Result<LayerPreparation, Error> {
    let start = Instant::now();
    let grid = &fill.mesh;
    let k = match grid.kind {
        MeshType::Bicubic => BICUBIC_SPLIT,
        MeshType::Bilinear | MeshType::Coons => 1,
    };
    let fewest = (grid.rows * grid.columns) as u64 * (k * k) as u64;
    if fewest > opts.max_quads as u64 {
        return Err(ErrorKind::LimitExceeded {
            what: format!(
                "cells of the patches of mesh gradient {:?}",
                fill.gradient_id
            ),
            found: fewest,
            limit: opts.max_quads as u64,
        }
        .into());
    }
    let lattices = colour_lattices(grid);
    let counts = CellCounts::new(grid, k, opts, xf);
    let opacity = fill.fill_opacity * fill.group_opacity;
    let size = (opts.width as i64, opts.height as i64);
    let patches: Vec<Patch> = (0..grid.rows * grid.columns)
        .map(|p| {
            let (r, c) = (p / grid.columns, p % grid.columns);
            Patch::new(grid, r, c, &lattices[p], opacity, xf)
        })
        .collect();
    let chunks = patches
        .par_iter()
        .map(|patch| patch.triangles(counts.across[patch.c], counts.down[patch.r], size))
        .collect();
    let triangles = TriangleList::from_chunks(chunks);
    let segments = boundary_segments(grid, &patches, &counts);
    let bands = (opts.height as usize).div_ceil(BAND);
    let triangle_bins = bin_triangles(&triangles, bands, opts.height as i64);
    let (lines, line_bins, columns) =
        visible_outline(clip_lines(&grid_outline(grid), xf), opts, bands);
    let elapsed = start.elapsed();
    let info = LayerInfo {
        level: 0,
        capped: counts.capped,
        quads: counts.cells(),
        triangles: triangles.len(),
        max_quad_px: f64::NAN,
        max_outline_deviation_px: f64::NAN,
        max_colour_error: f64::NAN,
        estimated: false,
        timings: LayerTimings {
            tessellate: elapsed,
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

/// Cells per patch: `across[c]` along the rows for every patch of grid column `c`, `down[r]`
/// down the columns for every patch of grid row `r`.
struct CellCounts {
    across: Vec<usize>,
    down: Vec<usize>,
    /// Whether [`RenderOptions::max_quads`] made the cells larger than [`CELL_PX`].
    capped: bool,
}

impl CellCounts {
    /// Counts that keep cells within the cell size (in pixels, the length of the control
    /// polygon of the longest side along that direction), multiples of the lattice's `k`, and
    /// at most [`RenderOptions::max_quads`] cells in all.
    fn new(grid: &MeshGrid, k: usize, opts: &RenderOptions, xf: &ToPixels) -> CellCounts {
        let px = |s: CubicBez| {
            let p = [s.p0, s.p1, s.p2, s.p3].map(|q| xf.apply(q.x, q.y));
            (0..3)
                .map(|i| (p[i + 1][0] - p[i][0]).hypot(p[i + 1][1] - p[i][1]))
                .sum::<f64>()
        };
        let across_px: Vec<f64> = (0..grid.columns)
            .map(|c| {
                (0..=grid.rows)
                    .map(|i| px(grid.row_side(i, c)))
                    .fold(0.0, f64::max)
            })
            .collect();
        let down_px: Vec<f64> = (0..grid.rows)
            .map(|r| {
                (0..=grid.columns)
                    .map(|j| px(grid.column_side(r, j)))
                    .fold(0.0, f64::max)
            })
            .collect();
        let mut cell = if opts.reference {
            REFERENCE_CELL_PX
        } else {
            CELL_PX
        }
        .min(opts.max_quad_px);
        let max_side = MAX_CELLS_PER_SIDE.div_ceil(k) * k;
        let count = |len: f64, cell: f64| {
            let n = (len / cell).ceil();
            let n = if n.is_finite() {
                n.max(1.0) as usize
            } else {
                1
            };
            (n.div_ceil(k) * k).min(max_side)
        };
        let mut capped = false;
        loop {
            let counts = CellCounts {
                across: across_px.iter().map(|&l| count(l, cell)).collect(),
                down: down_px.iter().map(|&l| count(l, cell)).collect(),
                capped,
            };
            if counts.cells() <= opts.max_quads
                || counts.cells() <= grid.rows * grid.columns * k * k
            {
                return counts;
            }
            cell *= 2.0;
            capped = true;
        }
    }

    fn cells(&self) -> usize {
        self.across.iter().sum::<usize>() * self.down.iter().sum::<usize>()
    }
}

/// One patch, ready to be sampled: its sides in the directions the grid stores them, in
/// pixels, its colour lattice and its corner opacities.
struct Patch<'a> {
    r: usize,
    c: usize,
    top: CubicBez,
    bottom: CubicBez,
    left: CubicBez,
    right: CubicBez,
    lattice: &'a Lattice,
    /// Opacity at the corners: top left, top right, bottom left, bottom right.
    opacity: [f64; 4],
}

impl<'a> Patch<'a> {
    fn new(
        grid: &MeshGrid,
        r: usize,
        c: usize,
        lattice: &'a Lattice,
        opacity: f64,
        xf: &ToPixels,
    ) -> Self {
        let px = |s: CubicBez| {
            let p = |q: Point| {
                let [x, y] = xf.apply(q.x, q.y);
                Point::new(x, y)
            };
            CubicBez::new(p(s.p0), p(s.p1), p(s.p2), p(s.p3))
        };
        let alpha = |i, j| grid.corner(r + i, c + j).opacity * opacity;
        Patch {
            r,
            c,
            top: px(grid.row_side(r, c)),
            bottom: px(grid.row_side(r + 1, c)),
            left: px(grid.column_side(r, c)),
            right: px(grid.column_side(r, c + 1)),
            lattice,
            opacity: [alpha(0, 0), alpha(0, 1), alpha(1, 0), alpha(1, 1)],
        }
    }

    /// The vertex at step `a` of `nu` down and `b` of `nv` across: its position in pixels
    /// (on a side, that side's own point) and its attributes (sRGB colour, opacity).
    fn vertex(&self, (a, nu): (usize, usize), (b, nv): (usize, usize)) -> ([f64; 2], [f64; 4]) {
        let (u, v) = (a as f64 / nu as f64, b as f64 / nv as f64);
        let p = if a == 0 {
            self.top.eval(v)
        } else if a == nu {
            self.bottom.eval(v)
        } else if b == 0 {
            self.left.eval(u)
        } else if b == nv {
            self.right.eval(u)
        } else {
            self.coons(u, v)
        };
        let lerp = |x: f64, y: f64, t: f64| x * (1.0 - t) + y * t;
        let k = self.lattice.k;
        // The lattice cell and the place in it, from the integer steps (counts are multiples
        // of k), so that lattice lines fall exactly on cell edges.
        let (mu, mv) = (nu / k, nv / k);
        let (la, lb) = ((a / mu).min(k - 1), (b / mv).min(k - 1));
        let (su, sv) = (
            (a - la * mu) as f64 / mu as f64,
            (b - lb * mv) as f64 / mv as f64,
        );
        let l = |da, db| self.lattice.at(la + da, lb + db);
        let colour: [f64; 3] = std::array::from_fn(|ch| {
            lerp(
                lerp(l(0, 0)[ch], l(0, 1)[ch], sv),
                lerp(l(1, 0)[ch], l(1, 1)[ch], sv),
                su,
            )
        });
        let o = self.opacity;
        let alpha = lerp(lerp(o[0], o[1], v), lerp(o[2], o[3], v), u);
        ([p.x, p.y], [colour[0], colour[1], colour[2], alpha])
    }

    /// The Coons patch at `u` down and `v` across: the two ruled surfaces between opposite
    /// sides, less the bilinear surface of the corners.
    fn coons(&self, u: f64, v: f64) -> Point {
        let (t, b, l, r) = (
            self.top.eval(v).to_vec2(),
            self.bottom.eval(v).to_vec2(),
            self.left.eval(u).to_vec2(),
            self.right.eval(u).to_vec2(),
        );
        let (c00, c01, c10, c11) = (
            self.top.p0.to_vec2(),
            self.top.p3.to_vec2(),
            self.bottom.p0.to_vec2(),
            self.bottom.p3.to_vec2(),
        );
        let corners = c00 * ((1.0 - u) * (1.0 - v))
            + c01 * ((1.0 - u) * v)
            + c10 * (u * (1.0 - v))
            + c11 * (u * v);
        (t * (1.0 - u) + b * u + l * (1.0 - v) + r * v - corners).to_point()
    }

    /// The patch's triangles with `nv` cells across and `nu` down, for an image of `size`
    /// pixels: none when the patch's control points all lie beside the image.
    fn triangles(&self, nv: usize, nu: usize, size: (i64, i64)) -> Vec<Triangle> {
        let bounds = [self.top, self.bottom, self.left, self.right]
            .iter()
            .map(|s| s.bounding_box())
            .reduce(|a, b| a.union(b))
            .expect("four sides");
        let (w, h) = (size.0 as f64, size.1 as f64);
        if bounds.x1 < 0.0 || bounds.y1 < 0.0 || bounds.x0 > w || bounds.y0 > h {
            return Vec::new();
        }
        let mut row: Vec<([f64; 2], [f64; 4])> =
            (0..=nu).map(|a| self.vertex((a, nu), (0, nv))).collect();
        let mut out = Vec::new();
        for b in 0..nv {
            let next: Vec<_> = (0..=nu)
                .map(|a| self.vertex((a, nu), (b + 1, nv)))
                .collect();
            for a in 0..nu {
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

/// The segments of the tessellation along the grid's outline, with the attributes at their
/// ends: outline pixels whose centre no triangle covers take their colour from the nearest.
fn boundary_segments(grid: &MeshGrid, patches: &[Patch], counts: &CellCounts) -> Vec<Segment> {
    let (rows, columns) = (grid.rows, grid.columns);
    let mut segments = Vec::new();
    let mut add = |points: Vec<([f64; 2], [f64; 4])>| {
        for pair in points.windows(2) {
            let c = |v: [f64; 4]| v.map(|x| x as f32);
            segments.push(Segment {
                a: pair[0].0,
                b: pair[1].0,
                ca: c(pair[0].1),
                cb: c(pair[1].1),
                bump: [0.0; 4],
            });
        }
    };
    for p in patches {
        let (nv, nu) = (counts.across[p.c], counts.down[p.r]);
        if p.r == 0 {
            add((0..=nv).map(|b| p.vertex((0, nu), (b, nv))).collect());
        }
        if p.r == rows - 1 {
            add((0..=nv).map(|b| p.vertex((nu, nu), (b, nv))).collect());
        }
        if p.c == 0 {
            add((0..=nu).map(|a| p.vertex((a, nu), (0, nv))).collect());
        }
        if p.c == columns - 1 {
            add((0..=nu).map(|a| p.vertex((a, nu), (nv, nv))).collect());
        }
    }
    segments
}

/// The grid's outline in the plane: the top sides left to right, the right sides down, the
/// bottom sides right to left, the left sides up.
fn grid_outline(grid: &MeshGrid) -> BezPath {
    let (rows, columns) = (grid.rows, grid.columns);
    let reversed = |s: CubicBez| CubicBez::new(s.p3, s.p2, s.p1, s.p0);
    let sides = (0..columns)
        .map(|j| grid.row_side(0, j))
        .chain((0..rows).map(|i| grid.column_side(i, columns)))
        .chain((0..columns).rev().map(|j| reversed(grid.row_side(rows, j))))
        .chain((0..rows).rev().map(|i| reversed(grid.column_side(i, 0))));
    let mut path = BezPath::new();
    path.move_to(grid.corner(0, 0).position);
    for s in sides {
        path.curve_to(s.p1, s.p2, s.p3);
    }
    path.close_path();
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_even_odd_shape_clips_a_translucent_mesh() {
        use crate::render::{render_svg_scene, SvgMeshRendering, View};
        let text = r##"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
          <meshgradient id="m" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
            <stop path="l 100,0" stop-color="#ff0000"/>
            <stop path="l 0,100" stop-color="#00ff00"/>
            <stop path="l -100,0" stop-color="#0000ff"/>
            <stop path="l 0,-100" stop-color="#ffffff"/>
          </meshpatch></meshrow></meshgradient>
          <path d="M10.5,10 H90 V90 H10.5 Z M30,30 H70 V70 H30 Z" fill-rule="evenodd"
                fill="url(#m)" fill-opacity="0.5"/>
        </svg>"##;
        let scene = crate::formats::svg::read_svg(text).unwrap();
        let opts = RenderOptions::new(100, 100, View::new(0.0, 0.0, 100.0, 100.0));
        for mode in [SvgMeshRendering::Classic, SvgMeshRendering::Scheme] {
            let (image, _) = render_svg_scene(&scene, mode, &opts).unwrap();
            assert_eq!(image.pixel(50, 50)[3], 0.0, "{mode:?}: the hole");
            assert_eq!(image.pixel(5, 50)[3], 0.0, "{mode:?}: outside");
            assert!((image.pixel(20, 50)[3] - 0.5).abs() < 1e-5, "{mode:?}");
            assert!(
                (image.pixel(10, 50)[3] - 0.25).abs() < 1e-5,
                "{mode:?}: the edge"
            );
        }
        let (image, _) = render_svg_scene(&scene, SvgMeshRendering::Classic, &opts).unwrap();
        // Pixel (20, 50): v = 0.205 across, u = 0.505 down.
        let (u, v) = (0.505, 0.205);
        let [red, green, blue, white] = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        let px = image.pixel(20, 50);
        for ch in 0..3 {
            let top = (1.0 - v) * red[ch] + v * green[ch];
            let bottom = (1.0 - v) * white[ch] + v * blue[ch];
            let want = (1.0 - u) * top + u * bottom;
            assert!(
                (f64::from(px[ch]) - want).abs() < 2e-3,
                "{px:?} channel {ch}: {want}"
            );
        }
    }

    /// A mesh needing more cells than `max_quads` at the least is refused; within it, the
    /// cells grow until they fit.
    #[test]
    fn cells_stay_within_max_quads() {
        use crate::render::{render_svg_scene, SvgMeshRendering, View};
        let text = r##"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
          <meshgradient id="m" gradientUnits="userSpaceOnUse" type="bicubic"><meshrow><meshpatch>
            <stop path="l 100,0" stop-color="#ff0000"/>
            <stop path="l 0,100" stop-color="#00ff00"/>
            <stop path="l -100,0" stop-color="#0000ff"/>
            <stop path="l 0,-100" stop-color="#ffffff"/>
          </meshpatch></meshrow></meshgradient>
          <rect width="100" height="100" fill="url(#m)"/>
        </svg>"##;
        let scene = crate::formats::svg::read_svg(text).unwrap();
        let mut opts = RenderOptions::new(400, 400, View::new(0.0, 0.0, 100.0, 100.0));
        opts.max_quads = 63;
        let error = render_svg_scene(&scene, SvgMeshRendering::Classic, &opts).unwrap_err();
        assert!(
            error.to_string().contains("above the limit of 63"),
            "{error}"
        );
        opts.max_quads = 1000;
        let (_, info) = render_svg_scene(&scene, SvgMeshRendering::Classic, &opts).unwrap();
        assert!(info.layers[0].quads <= 1000 && info.layers[0].capped);
    }
}
