//! Measuring how well triangles show the limit surface: the colour error a pixel would see, the
//! size of quads on screen and the outline's distance, per quad and per level, against the
//! thresholds the options ask for. Planning (the uniform level choice, the fast path's faces
//! and their quadratic colour) decides from these figures.

use rayon::prelude::*;

use crate::colour::{ColourSpace, Matrix3};
use crate::topology::Topology;
use crate::validate::VertexData;

use crate::render::arrays::{each3, each4};
use crate::render::options::{RenderOptions, DRAFT_LOOSENING};
use crate::view::ToPixels;

/// Colour errors count in quads at least this wide (diagonal, pixels) in the fast path...
pub(crate) const MIN_QUAD_PX: f64 = 1.0;
/// ...and in smaller cells of the fast path's faces that hold a pixel centre, down to this
/// size. Where the surface folds, the colour error of linear pieces only falls by about 0.6 a
/// level (the map to the screen is singular at the crease), and without a floor a fold can
/// take faces of thousands of cells under a tenth of a pixel. The floor is the largest the
/// accuracy tests against the reference mode allow: larger ones miss colour errors at folds
/// (which sheet shows there).
const ADAPTIVE_MIN_COUNTED_PX: f64 = 0.2;
/// The fast path holds each face's measured colour error to this fraction of the tolerance: the
/// measure samples cell and side centres only, and each face stops right at the threshold
/// instead of at the level the worst spot of the layer asks for (the uniform path's margin).
/// A smaller fraction costs more cells for pictures that the accuracy tests against the
/// reference mode cannot tell apart (limits 0.5 worst and 0.05 mean CIEDE2000).
const ADAPTIVE_COLOUR_MARGIN: f64 = 0.75;
/// What the fast path asks of the triangles (the reference mode has its own, stricter ones).
pub(crate) struct Thresholds {
    /// Largest quad diagonal, pixels.
    pub quad: f64,
    /// Largest colour error.
    pub colour: f64,
    /// Largest outline distance, pixels.
    pub outline: f64,
    /// Colour errors count in quads at least this wide.
    pub min_quad: f64,
    /// Image size, pixels.
    pub size: (f64, f64),
    /// The working colour space.
    pub space: ColourSpace,
    /// Whether faces may take quadratic colour ([`RenderOptions::quadratic`]).
    pub quadratic: bool,
    /// Whether these are a draft's looser thresholds ([`RenderOptions::draft`]).
    pub draft: bool,
}

impl Thresholds {
    pub(crate) fn new(opts: &RenderOptions, space: ColourSpace) -> Thresholds {
        let loosening = if opts.draft { DRAFT_LOOSENING } else { 1.0 };
        Thresholds {
            quad: opts.max_quad_px * loosening.sqrt(),
            colour: ADAPTIVE_COLOUR_MARGIN * opts.colour_tolerance * loosening,
            outline: opts.tolerance_px * loosening,
            min_quad: MIN_QUAD_PX,
            size: (opts.width as f64, opts.height as f64),
            space,
            quadratic: opts.quadratic,
            draft: opts.draft,
        }
    }
}

/// How well the triangles of one level render the limit surface, over the quads that reach
/// the image.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Measure {
    /// Largest quad diagonal, pixels.
    pub extent: f64,
    /// Largest colour error, approximately CIE Lab units (opacity counts 100 per unit).
    pub colour: f64,
    /// Largest distance of the outline from the triangles' boundary edges, pixels.
    pub outline: f64,
}

impl Measure {
    /// The largest of each figure (exact, so any grouping gives the same).
    pub fn max(self, other: Measure) -> Measure {
        Measure {
            extent: self.extent.max(other.extent),
            colour: self.colour.max(other.colour),
            outline: self.outline.max(other.outline),
        }
    }
}

/// A colour difference in approximately CIE Lab units (Delta E 1976), opacity included.
fn colour_error(space: ColourSpace, a: [f64; 4], b: [f64; 4]) -> f64 {
    let d = |x: [f64; 3], y: [f64; 3]| {
        ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt()
    };
    let (ca, cb) = ([a[0], a[1], a[2]], [b[0], b[1], b[2]]);
    let colour = match space {
        ColourSpace::Lab => d(ca, cb),
        // Oklab is not Lab scaled: a hundred times its distance understates differences of
        // chroma about twofold (edge-kinds in Oklab showed 0.46 CIEDE2000 against 0.12 now).
        _ => d(
            space.convert(ColourSpace::Lab, ca),
            space.convert(ColourSpace::Lab, cb),
        ),
    };
    colour.max(100.0 * (a[3] - b[3]).abs())
}

/// The attributes a triangle `p` with attributes `c` shows at `x`: linear inside, and at the
/// nearest point of its sides outside (so that thin or folded triangles, whose planes are
/// ill-conditioned, give bounded answers).
fn interpolate(p: [[f64; 2]; 3], c: [[f64; 4]; 3], x: [f64; 2]) -> [f64; 4] {
    let (e1, e2) = (
        [p[1][0] - p[0][0], p[1][1] - p[0][1]],
        [p[2][0] - p[0][0], p[2][1] - p[0][1]],
    );
    let det = e1[0] * e2[1] - e1[1] * e2[0];
    let scale = (e1[0] * e1[0] + e1[1] * e1[1]).max(e2[0] * e2[0] + e2[1] * e2[1]);
    if det.abs() > 1e-9 * scale {
        let (dx, dy) = (x[0] - p[0][0], x[1] - p[0][1]);
        let u = (dx * e2[1] - dy * e2[0]) / det;
        let v = (e1[0] * dy - e1[1] * dx) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 {
            return each4(|k| c[0][k] + u * (c[1][k] - c[0][k]) + v * (c[2][k] - c[0][k]));
        }
    }
    let mut best = (f64::INFINITY, c[0]);
    for k in 0..3 {
        let (a, b) = (p[k], p[(k + 1) % 3]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((x[0] - a[0]) * dx + (x[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d2 = (x[0] - a[0] - t * dx).powi(2) + (x[1] - a[1] - t * dy).powi(2);
        if d2 < best.0 {
            let (ca, cb) = (c[k], c[(k + 1) % 3]);
            best = (d2, each4(|i| ca[i] + t * (cb[i] - ca[i])));
        }
    }
    best.1
}

/// Measures level `k` of a layer. `lim` holds the limit data of level `k`, `lim1` that of
/// level `k + 1`: its face point `f` and edge point `nf + e` are the surface at the centres of
/// face `f` and edge `e` of level `k`, in position and colour.
///
/// The colour error is what a pixel shows: the limit colour at a centre's true position against
/// the colour the triangles interpolate at that same position (not at the same parameter: the
/// map from the mesh to the plane is not affine within a quad, and that displacement times the
/// colour gradient is usually the larger term). The outline distance is the deviation of the
/// limit boundary from the boundary edges, across the edge.
///
/// Colour errors inside quads less than `min_quad` pixels across are not counted: such a quad
/// holds at most a pixel centre or two. Errors that survive refinement that far sit at
/// extraordinary and degenerate points (a handle of length zero makes a sharp colour step, for
/// example), where uniform refinement converges only linearly and would refine the whole layer
/// for a few pixels.
pub(crate) fn measure(
    t: &Topology,
    lim: &[VertexData],
    lim1: &[VertexData],
    xf: &ToPixels,
    size: (f64, f64),
    space: ColourSpace,
    min_quad: f64,
) -> Measure {
    let nf = t.face_count();
    // Per face, then the largest of each figure: max is exact, so any split gives the same.
    let face = |f: usize| -> Measure {
        let fv = t.face_vertices(f);
        if fv.len() != 4 {
            return Measure::default();
        }
        let fe = t.face_edges(f);
        let corners = [0, 1, 2, 3].map(|i| &lim[fv[i] as usize]);
        let mids = [0, 1, 2, 3].map(|k| &lim1[nf + fe[k] as usize]);
        let boundary = [0, 1, 2, 3].map(|k| t.is_boundary_edge(fe[k] as usize));
        let quad = QuadSamples {
            corners,
            centre: &lim1[f],
            mids,
            boundary,
            jacobians: None,
        };
        measure_quad(&quad, xf, size, space, min_quad, false)
    };
    (0..nf)
        .into_par_iter()
        .map(face)
        .reduce(Measure::default, Measure::max)
}

/// The samples of one quad that [`measure_quad`] needs: the limit data at its corners (wound),
/// at its centre and at the midpoints of its sides (side `k` from corner `k` to `k + 1`), and
/// which sides lie on the outline.
pub(crate) struct QuadSamples<'a> {
    pub corners: [&'a VertexData; 4],
    pub centre: &'a VertexData,
    pub mids: [&'a VertexData; 4],
    pub boundary: [bool; 4],
    /// The derivatives of the working space to Lab at the centre and the midpoints, when the
    /// caller has them: colour errors are then measured through them (see [`sample_error`]).
    pub jacobians: Option<[&'a Matrix3; 5]>,
}

/// The colour error of `shown` against the limit `sample`: exact, or through the derivative
/// `jacobian` of the working space to Lab at the sample. Errors worth measuring are a few Lab
/// units, where the two agree to a fraction of a percent.
pub(crate) fn sample_error(
    space: ColourSpace,
    sample: [f64; 4],
    shown: [f64; 4],
    jacobian: Option<&Matrix3>,
) -> f64 {
    let Some(j) = jacobian else {
        return colour_error(space, sample, shown);
    };
    let d = each3(|k| sample[k] - shown[k]);
    let lab = each3(|r| j[r][0] * d[0] + j[r][1] * d[1] + j[r][2] * d[2]);
    let colour = (lab[0] * lab[0] + lab[1] * lab[1] + lab[2] * lab[2]).sqrt();
    colour.max(100.0 * (sample[3] - shown[3]).abs())
}

/// Measures one quad drawn as the triangles `(0, 1, 2)` and `(0, 2, 3)` (see [`measure`]).
/// A quad entirely off the image counts for nothing. With `adaptive` (the fast path's faces,
/// each with its own density), its centre and midpoints decide that too (a coarse quad may
/// bulge into the image between its corners), and the colour error of a quad under
/// `min_quad` still counts when the quad's box holds a pixel centre (and it is at least
/// [`ADAPTIVE_MIN_COUNTED_PX`] across): such a quad is not refined along with larger ones
/// elsewhere, as in a uniform level.
pub(crate) fn measure_quad(
    q: &QuadSamples,
    xf: &ToPixels,
    size: (f64, f64),
    space: ColourSpace,
    min_quad: f64,
    adaptive: bool,
) -> Measure {
    let px = |d: &VertexData| xf.apply(d.position[0], d.position[1]);
    let attr = |d: &VertexData| d.attributes();
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let mut m = Measure::default();
    let p = each4(|k| px(q.corners[k]));
    let c = each4(|k| attr(q.corners[k]));
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut grow = |x: [f64; 2]| {
        for k in 0..2 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    };
    p.iter().for_each(|&x| grow(x));
    if adaptive {
        grow(px(q.centre));
        q.mids.iter().for_each(|&d| grow(px(d)));
    }
    if hi[0] < -1.0 || hi[1] < -1.0 || lo[0] > size.0 + 1.0 || lo[1] > size.1 + 1.0 {
        return m;
    }
    let extent = dist(p[0], p[2]).max(dist(p[1], p[3]));
    m.extent = m.extent.max(extent);
    let tris = [[0, 1, 2], [0, 2, 3]];
    let holds_centre = || {
        let column = (lo[0] - 0.5).ceil() <= hi[0] - 0.5;
        let row = (lo[1] - 0.5).ceil() <= hi[1] - 0.5;
        column && row
    };
    let counts =
        extent >= min_quad || (adaptive && extent >= ADAPTIVE_MIN_COUNTED_PX && holds_centre());
    // `which`: 0 for the centre, 1 + k for the midpoint of side k.
    let check = |m: &mut Measure, sample: &VertexData, which: usize, tri: usize| {
        if !counts {
            return;
        }
        let t = tris[tri];
        let shown = interpolate(each3(|i| p[t[i]]), each3(|i| c[t[i]]), px(sample));
        let jacobian = q.jacobians.map(|j| j[which]);
        m.colour = m
            .colour
            .max(sample_error(space, attr(sample), shown, jacobian));
    };
    // The quad's centre lies on the shared diagonal: both triangles.
    check(&mut m, q.centre, 0, 0);
    check(&mut m, q.centre, 0, 1);
    for k in 0..4 {
        let sample = q.mids[k];
        check(&mut m, sample, 1 + k, if k < 2 { 0 } else { 1 });
        if q.boundary[k] {
            let (a, b) = (p[k], p[(k + 1) % 4]);
            let x = px(sample);
            let len = dist(a, b);
            let off = if len > 0.0 {
                ((b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0])).abs() / len
            } else {
                dist(a, x)
            };
            m.outline = m.outline.max(off);
        }
    }
    m
}
