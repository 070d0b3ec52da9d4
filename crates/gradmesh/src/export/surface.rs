//! A layer's limit surface as Bézier patches in pixels, and its outline as Bézier curves.
//!
//! The surface is taken face by face from a refined, all-quad level. A face whose corners are
//! regular is exactly a uniform bicubic B-spline patch ([`regular_patch_with`]), turned into a
//! Bézier net. Any other face is refined locally ([`LocalPatch`]): the descendants that become
//! regular patches are exact too, and those still irregular at the last depth (around an
//! extraordinary vertex, along a crease) become flat patches through their corners' limit
//! points. That depth grows until those flat patches lie within the geometry tolerance of the
//! limit surface and their colours within the colour tolerance, at their side midpoints and
//! centre.

use std::collections::HashMap;

use crate::colour::ColourSpace;
use crate::error::{Error, ErrorKind, Warning};
use crate::level::Level;
use crate::limit_surface::boundary::{boundary_loops, for_each_boundary_segment};
use crate::limit_surface::patches::{regular_corners, regular_patch_with, LocalPatch, ShapeCache};
use crate::mesh::GradientMesh;
use crate::refine::Refinement;
use crate::size_limits::Limits;
use crate::validate::VertexData;
use crate::view::ToPixels;

use super::bezier::{bilinear_net, bspline_to_bezier, BezierNet};
use super::split::delta_e00;

/// The deepest local refinement of an irregular face.
const MAX_LOCAL_DEPTH: usize = 8;
/// Levels deeper than this are not taken to let semi-sharpness on the outline decay.
const DEEPEST_LEVEL: usize = 6;

/// Opacities from this up count as 1: refining a layer whose opacity is 1 everywhere leaves
/// values a few rounding steps below 1 (sums of stencil weights), which are no translucency
/// and would give the layer a mask of no effect.
const OPAQUE: f64 = 1.0 - 1e-9;

/// A cubic Bézier curve in pixels.
pub(crate) type Curve = [[f64; 2]; 4];

/// One layer ready to export.
pub(crate) struct LayerSurface {
    /// The working space of the colours in `nets`.
    pub space: ColourSpace,
    /// Bézier patches in pixels, in the order they are drawn (face by face).
    pub nets: Vec<BezierNet>,
    /// The boundary loops as Bézier curves, in pixels.
    pub outline: Vec<Vec<Curve>>,
    /// Whether every opacity is 1 (at least [`OPAQUE`]).
    pub opaque: bool,
    /// Flat patches standing for irregular descendants.
    pub approximated: usize,
    /// The largest distance in pixels found between a flat patch and the surface.
    pub geometry_error: f64,
    /// The validation's warnings, marked with the layer.
    pub warnings: Vec<Warning>,
}

/// What surface extraction needs to know.
pub(crate) struct SurfaceOptions {
    pub xf: ToPixels,
    pub width: f64,
    pub height: f64,
    pub geometry_tolerance: f64,
    pub colour_tolerance: f64,
    pub limits: Limits,
}

/// The limit surface of `mesh` (layer `index`) as patches; `None` for a layer without faces.
pub(crate) fn layer_surface(
    mesh: &GradientMesh,
    index: usize,
    opts: &SurfaceOptions,
) -> Result<Option<LayerSurface>, Error> {
    if mesh.faces.is_empty() {
        return Ok(None);
    }
    let in_layer = |e: Error| e.in_layer(index);
    let (mut refinement, warnings) =
        Refinement::new_with_limits(mesh, 1, &opts.limits).map_err(in_layer)?;
    let mut k = 2.max(refinement.base().edits.deepest_level() + 1);
    loop {
        opts.limits
            .check_refinement(refinement.base(), k)
            .map_err(in_layer)?;
        refinement.extend_to(k);
        if !refinement.level(k).semi_sharp_on_boundary() || k >= DEEPEST_LEVEL {
            break;
        }
        k += 1;
    }
    let data = refinement.evaluate_to(refinement.base(), k);
    let px: Vec<VertexData> = data.levels[k]
        .iter()
        .map(|d| {
            let position = opts.xf.apply(d.position[0], d.position[1]);
            VertexData { position, ..*d }
        })
        .collect();
    let level = refinement.level(k);
    let mut surface = LayerSurface {
        space: mesh.colour_space,
        nets: Vec::new(),
        outline: outline_curves(level, &px),
        opaque: px.iter().all(|d| d.opacity >= OPAQUE),
        approximated: 0,
        geometry_error: 0.0,
        warnings: warnings
            .into_iter()
            .map(|w| Warning {
                layer: Some(index),
                ..w
            })
            .collect(),
    };
    let regular = regular_corners(level);
    let shapes = ShapeCache::default();
    let t = &level.topology;
    for f in 0..t.face_count() {
        if !reaches_page(level, &px, f, opts) {
            continue;
        }
        if let Some(cp) = regular_patch_with(level, &px, f, |v| regular[v]) {
            surface.nets.push(bspline_to_bezier(&cp));
            continue;
        }
        let unsupported = || {
            Error::new(ErrorKind::Invalid {
                what: format!("face {f} of refinement level {k}"),
                message: "its neighbourhood cannot be refined on its own for export".into(),
            })
            .in_layer(index)
        };
        let mut patch = LocalPatch::new(level, &px, &[f], &shapes).ok_or_else(unsupported)?;
        local_nets(&mut patch, surface.space, opts, &mut surface).ok_or_else(unsupported)?;
    }
    Ok(Some(surface))
}

/// Whether the limit surface of face `f` can reach the page: it lies in the convex hull of the
/// points of the faces around its corners.
fn reaches_page(level: &Level, px: &[VertexData], f: usize, opts: &SurfaceOptions) -> bool {
    let t = &level.topology;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &c in t.face_vertices(f) {
        for &g in t.vertex_faces(c as usize) {
            for &v in t.face_vertices(g as usize) {
                let p = px[v as usize].position;
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
    }
    hi[0] >= -1.0 && lo[0] <= opts.width + 1.0 && hi[1] >= -1.0 && lo[1] <= opts.height + 1.0
}

/// Appends the pieces of a locally refined face (its root 0) to `surface`: exact patches, and
/// flat ones at the first depth where they pass the tolerances. `None` if the refinement
/// fails.
fn local_nets(
    patch: &mut LocalPatch,
    space: ColourSpace,
    opts: &SurfaceOptions,
    surface: &mut LayerSurface,
) -> Option<()> {
    for depth in 1..=MAX_LOCAL_DEPTH {
        let pieces = patch.pieces(0, depth)?;
        let mut flat = Vec::with_capacity(pieces.irregular.len());
        let mut worst = (0.0f64, 0.0f64);
        if !pieces.irregular.is_empty() {
            let n = 1usize << (depth + 1);
            let fine = patch.grid(0, n)?;
            let at = |p: [i64; 2]| fine[(p[1] * (n as i64 + 1) + p[0]) as usize];
            for tile in &pieces.irregular {
                let corners = tile.map(|p| at([2 * p[0], 2 * p[1]]));
                let mid = |a: usize, b: usize| [tile[a][0] + tile[b][0], tile[a][1] + tile[b][1]];
                let samples = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2)];
                for (a, b) in samples {
                    let truth = at(mid(a, b));
                    let flat_at = if (a, b) == (0, 2) {
                        average(&corners)
                    } else {
                        average(&[corners[a], corners[b]])
                    };
                    let (g, c) = difference(space, &truth, &flat_at);
                    worst = (worst.0.max(g), worst.1.max(c));
                }
                flat.push(corners);
            }
        }
        let passes = worst.0 <= opts.geometry_tolerance && worst.1 <= opts.colour_tolerance;
        if passes || depth == MAX_LOCAL_DEPTH {
            surface
                .nets
                .extend(pieces.patches.iter().map(bspline_to_bezier));
            surface.approximated += flat.len();
            surface.nets.extend(flat.into_iter().map(bilinear_net));
            surface.geometry_error = surface.geometry_error.max(worst.0);
            return Some(());
        }
    }
    Some(())
}

fn average(points: &[VertexData]) -> VertexData {
    let n = points.len() as f64;
    let mut out = VertexData::ZERO;
    for p in points {
        out += p.map(|x| x / n);
    }
    out
}

/// The distance in pixels between two samples, and the larger of their colour difference
/// (ΔE00) and a hundred times their opacity difference.
fn difference(space: ColourSpace, a: &VertexData, b: &VertexData) -> (f64, f64) {
    let lab = |d: &VertexData| space.convert(ColourSpace::Lab, d.colour);
    let colour = delta_e00(lab(a), lab(b)).max(100.0 * (a.opacity - b.opacity).abs());
    (
        (a.position[0] - b.position[0]).hypot(a.position[1] - b.position[1]),
        colour,
    )
}

/// Outline points are snapped to 2^-16 pixel before conversion, as the renderer's are: the
/// two sides of a discontinuous edge then give bit for bit the same curves, reversed.
const OUTLINE_GRID: f64 = 65536.0;

/// The boundary loops of `level` (control points `px`, in pixels) as closed chains of Bézier
/// curves. The two sides of a discontinuous edge are two boundaries over the same points, run
/// in opposite directions: they cancel, and what is left is chained again into loops, so that
/// no seam is clipped along them.
fn outline_curves(level: &Level, px: &[VertexData]) -> Vec<Vec<Curve>> {
    let mut curves = Vec::new();
    for lp in boundary_loops(&level.topology) {
        let m = lp.len();
        let pos = |i: usize| {
            px[lp[i % m] as usize]
                .position
                .map(|v| (v * OUTLINE_GRID).round() / OUTLINE_GRID)
        };
        for_each_boundary_segment(level, &lp, pos, |q| curves.push(bezier_segment(q)));
    }
    chain(cancel_opposite(curves))
}

/// The Bézier points of the uniform B-spline segment `q`, from sums whose operands commute: the
/// reversed segment gives the reversed points, bit for bit.
fn bezier_segment(q: [[f64; 2]; 4]) -> Curve {
    let c = |f: &dyn Fn(usize) -> f64| [f(0), f(1)];
    [
        c(&|k| ((q[0][k] + q[2][k]) + 4.0 * q[1][k]) / 6.0),
        c(&|k| (2.0 * q[1][k] + q[2][k]) / 3.0),
        c(&|k| (q[1][k] + 2.0 * q[2][k]) / 3.0),
        c(&|k| ((q[1][k] + q[3][k]) + 4.0 * q[2][k]) / 6.0),
    ]
}

type CurveKey = [[u64; 2]; 4];

fn key(c: &Curve) -> CurveKey {
    c.map(|p| p.map(f64::to_bits))
}

/// Removes pairs of a curve and its reverse.
fn cancel_opposite(curves: Vec<Curve>) -> Vec<Curve> {
    let mut open: HashMap<CurveKey, Vec<usize>> = HashMap::new();
    let mut keep = vec![true; curves.len()];
    for (i, c) in curves.iter().enumerate() {
        let mut reversed = *c;
        reversed.reverse();
        match open.get_mut(&key(&reversed)).and_then(|v| v.pop()) {
            Some(j) => {
                keep[i] = false;
                keep[j] = false;
            }
            None => open.entry(key(c)).or_default().push(i),
        }
    }
    curves
        .into_iter()
        .zip(keep)
        .filter_map(|(c, k)| k.then_some(c))
        .collect()
}

/// The curves chained end to start into loops, in the order they come.
fn chain(curves: Vec<Curve>) -> Vec<Vec<Curve>> {
    let bits = |p: [f64; 2]| p.map(f64::to_bits);
    let mut starting: HashMap<[u64; 2], Vec<usize>> = HashMap::new();
    for (i, c) in curves.iter().enumerate().rev() {
        starting.entry(bits(c[0])).or_default().push(i);
    }
    let mut used = vec![false; curves.len()];
    let mut loops = Vec::new();
    for first in 0..curves.len() {
        if used[first] {
            continue;
        }
        let mut lp = Vec::new();
        let mut at = first;
        loop {
            used[at] = true;
            lp.push(curves[at]);
            let end = bits(curves[at][3]);
            let next = starting.get_mut(&end).and_then(|v| {
                while let Some(&i) = v.last() {
                    if used[i] {
                        v.pop();
                    } else {
                        return Some(i);
                    }
                }
                None
            });
            match next {
                Some(i) => at = i,
                None => break,
            }
        }
        loops.push(lp);
    }
    loops
}
