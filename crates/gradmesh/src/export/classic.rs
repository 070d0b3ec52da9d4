//! The patches of an SVG mesh gradient written as they are, not converted into the scheme: a
//! Coons patch is a PDF tensor-product patch with the interior points its sides imply, with
//! its colour bilinear in sRGB as in PDF's DeviceRGB; a `type="bicubic"` patch is cut into
//! the 8 x 8 cells of its smoothed colour lattice (its colour is bilinear within each), each
//! cell the part of the patch's surface it covers.

use kurbo::{PathEl, Point};

use super::split::{OutPatch, Target};
use super::surface::Curve;
use super::{LayerPatches, SplitGrid};
use crate::formats::pdf::coons_interior;
use crate::formats::svg::paint::{colour_lattices, Lattice};
use crate::formats::svg::{MeshFill, MeshGrid};
use crate::view::ToPixels;

/// The patches of `fill`'s mesh in pixels (`xf`), colours in sRGB, opacity the stops' times
/// the shape's `fill-opacity` and group `opacity`, clipped to the shape.
pub(crate) fn svg_fill_patches(fill: &MeshFill, xf: &ToPixels) -> LayerPatches {
    let grid = &fill.mesh;
    let lattices = colour_lattices(grid);
    let shape_opacity = fill.fill_opacity * fill.group_opacity;
    let mut patches = Vec::new();
    let mut grids = Vec::with_capacity(lattices.len());
    for (p, lattice) in lattices.iter().enumerate() {
        let (r, c) = (p / grid.columns, p % grid.columns);
        let net = patch_points(grid, r, c, xf);
        let opacity = [(0, 0), (1, 0), (1, 1), (0, 1)]
            .map(|(i, j)| grid.corner(r + i, c + j).opacity * shape_opacity);
        let first = patches.len();
        cells(&net, lattice, opacity, &mut patches);
        grids.push(SplitGrid {
            first,
            n: lattice.k,
            m: lattice.k,
        });
    }
    let masked = patches.iter().any(|p| p.opacity.iter().any(|&a| a < 1.0));
    LayerPatches {
        patches,
        grids,
        outline: path_curves(&fill.clip, xf),
        clip_rule: fill.fill_rule,
        colour: Some(Target::Srgb),
        masked,
        approximated: 0,
        geometry_error: 0.0,
        warnings: Vec::new(),
    }
}

/// The 16 points of patch `(r, c)` in pixels, `[i][j]` with `i` down the grid's columns (the
/// patch's `u`, from its top side) and `j` along its rows (`v`): the order in which PDF and
/// Cairo paint where a patch folds (higher `v` over lower, then higher `u`), as Inkscape
/// builds its patches.
fn patch_points(grid: &MeshGrid, r: usize, c: usize, xf: &ToPixels) -> [[Point; 4]; 4] {
    let px = |p: Point| {
        let [x, y] = xf.apply(p.x, p.y);
        Point::new(x, y)
    };
    let cubic = |s: kurbo::CubicBez| [s.p0, s.p1, s.p2, s.p3].map(px);
    let (top, bottom) = (cubic(grid.row_side(r, c)), cubic(grid.row_side(r + 1, c)));
    let (left, right) = (
        cubic(grid.column_side(r, c)),
        cubic(grid.column_side(r, c + 1)),
    );
    let mut p = [[Point::ZERO; 4]; 4];
    for k in 0..4 {
        p[0][k] = top[k];
        p[3][k] = bottom[k];
        p[k][0] = left[k];
        p[k][3] = right[k];
    }
    coons_interior(&mut p);
    p
}

/// Appends the cells of `lattice` over the patch `net` (one cell when the lattice has one),
/// row by row: each the sub-patch of its parameter square, with the lattice's colours and the
/// corners' bilinear opacity at its corners.
fn cells(net: &[[Point; 4]; 4], lattice: &Lattice, opacity: [f64; 4], out: &mut Vec<OutPatch>) {
    let k = lattice.k;
    let bilinear = |u: f64, v: f64| {
        (1.0 - u) * (1.0 - v) * opacity[0]
            + u * (1.0 - v) * opacity[1]
            + u * v * opacity[2]
            + (1.0 - u) * v * opacity[3]
    };
    for a in 0..k {
        for b in 0..k {
            let (u0, u1) = (a as f64 / k as f64, (a + 1) as f64 / k as f64);
            let (v0, v1) = (b as f64 / k as f64, (b + 1) as f64 / k as f64);
            let sub = sub_net(net, (u0, u1), (v0, v1));
            let mut points = [[[0.0; 2]; 4]; 4];
            for (i, row) in sub.iter().enumerate() {
                for (j, q) in row.iter().enumerate() {
                    // OutPatch's points are indexed [v][u].
                    points[j][i] = [q.x, q.y];
                }
            }
            out.push(OutPatch {
                points,
                colours: [
                    lattice.at(a, b),
                    lattice.at(a + 1, b),
                    lattice.at(a + 1, b + 1),
                    lattice.at(a, b + 1),
                ],
                opacity: [
                    bilinear(u0, v0),
                    bilinear(u1, v0),
                    bilinear(u1, v1),
                    bilinear(u0, v1),
                ],
            });
        }
    }
}

/// The part of the tensor-product patch `net` over `[u0, u1] x [v0, v1]`, as a patch of its
/// own (de Casteljau along each parameter: exact).
fn sub_net(net: &[[Point; 4]; 4], u: (f64, f64), v: (f64, f64)) -> [[Point; 4]; 4] {
    if u == (0.0, 1.0) && v == (0.0, 1.0) {
        return *net;
    }
    let columns: [[Point; 4]; 4] =
        std::array::from_fn(|j| segment([net[0][j], net[1][j], net[2][j], net[3][j]], u));
    let mut out = [[Point::ZERO; 4]; 4];
    for (i, row) in out.iter_mut().enumerate() {
        *row = segment(std::array::from_fn(|j| columns[j][i]), v);
    }
    out
}

/// The control points of the part of the cubic `p` over `[a, b]`.
fn segment(p: [Point; 4], (a, b): (f64, f64)) -> [Point; 4] {
    let c = kurbo::CubicBez::new(p[0], p[1], p[2], p[3]);
    let s = kurbo::ParamCurve::subsegment(&c, a..b);
    [s.p0, s.p1, s.p2, s.p3]
}

/// The loops of `path` (in the plane) as cubic curves in pixels, each loop closed.
fn path_curves(path: &kurbo::BezPath, xf: &ToPixels) -> Vec<Vec<Curve>> {
    let px = |p: Point| xf.apply(p.x, p.y);
    let line = |a: Point, b: Point| {
        [
            px(a),
            px(a.lerp(b, 1.0 / 3.0)),
            px(a.lerp(b, 2.0 / 3.0)),
            px(b),
        ]
    };
    let mut loops: Vec<Vec<Curve>> = Vec::new();
    let (mut start, mut at) = (Point::ZERO, Point::ZERO);
    let close = |loops: &mut Vec<Vec<Curve>>, at: Point, start: Point| {
        if let Some(last) = loops.last_mut() {
            if at != start && !last.is_empty() {
                last.push(line(at, start));
            }
        }
    };
    for el in path.elements() {
        match *el {
            PathEl::MoveTo(p) => {
                close(&mut loops, at, start);
                loops.push(Vec::new());
                (start, at) = (p, p);
            }
            PathEl::LineTo(p) => {
                push(&mut loops, line(at, p));
                at = p;
            }
            PathEl::QuadTo(q, p) => {
                let c = kurbo::QuadBez::new(at, q, p).raise();
                push(&mut loops, [c.p0, c.p1, c.p2, c.p3].map(px));
                at = p;
            }
            PathEl::CurveTo(a, b, p) => {
                push(&mut loops, [at, a, b, p].map(px));
                at = p;
            }
            PathEl::ClosePath => {
                close(&mut loops, at, start);
                at = start;
            }
        }
    }
    close(&mut loops, at, start);
    loops.retain(|l| !l.is_empty());
    loops
}

/// Adds `curve` to the last loop (a path that draws before its first move starts one).
fn push(loops: &mut Vec<Vec<Curve>>, curve: Curve) {
    match loops.last_mut() {
        Some(l) => l.push(curve),
        None => loops.push(vec![curve]),
    }
}
