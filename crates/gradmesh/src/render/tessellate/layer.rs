//! One layer made ready to draw: refinement level chosen, limit data tessellated into
//! triangles, outline flattened, everything binned into bands of rows.

use std::time::Instant;

use rayon::prelude::*;

use crate::colour::ColourSpace;
use crate::error::{Error, Warning};
use crate::formats::svg::FillRule;
use crate::limit_surface;
use crate::mesh::GradientMesh;
use crate::refine::{RefinedData, Refinement};
use crate::size_limits::Limits;
use crate::topology::Topology;
use crate::validate::{BaseMesh, VertexData};

use super::adaptive;
use super::clip::clip_lines;
use super::nearest::{NearestSegments, Segment};
use super::outline::outline;
use crate::limit_surface::boundary::boundary_loops;
use crate::limit_surface::patches::ShapeCache;
use crate::render::info::{LayerInfo, LayerTimings};
use crate::render::options::RenderOptions;
use crate::render::plan::measure::{measure, Measure, Thresholds, MIN_QUAD_PX};
use crate::render::raster::coverage::Line;
use crate::render::raster::triangles::{
    screen_triangle_px, snap, Bounds, Triangle, TriangleList, UNBOUNDED,
};
use crate::view::ToPixels;

/// Rows per band: the unit of parallel work.
pub(crate) const BAND: usize = 16;

/// Reference mode: quads at most this wide (diagonal, pixels)...
const REFERENCE_QUAD_PX: f64 = 0.5;
/// ...the boundary edges within this distance of the outline (pixels)...
const REFERENCE_TOLERANCE_PX: f64 = 0.01;
/// ...and the colours within this (approximately Delta E)...
const REFERENCE_COLOUR_TOLERANCE: f64 = 0.002;
/// ...counted in quads at least this wide (pixels).
const REFERENCE_MIN_QUAD_PX: f64 = 0.1;
/// Flattening tolerance of the outline (pixels): coverage error at most this per pixel.
const OUTLINE_TOLERANCE_PX: f64 = 0.002;
const REFERENCE_OUTLINE_TOLERANCE_PX: f64 = 0.0002;

/// The first and last band holding rows `r0..r1` of an image `h` rows high, which they must
/// overlap. Triangles, outline lines and the edits' changes are binned alike.
fn bands_of_rows((r0, r1): (i64, i64), h: i64) -> (usize, usize) {
    debug_assert!(r0 < r1 && r1 > 0 && r0 < h);
    (r0.max(0) as usize / BAND, (r1.min(h) - 1) as usize / BAND)
}

/// Item indices grouped by band (compressed rows).
#[derive(Clone, Debug, Default)]
pub(crate) struct Bins {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Bins {
    /// Bins items given as `(index, first band, last band inclusive)`, keeping index order
    /// within each band.
    fn new(bands: usize, ranges: &[(u32, usize, usize)]) -> Bins {
        let mut offsets = vec![0u32; bands + 1];
        for &(_, a, b) in ranges {
            for band in a..=b {
                offsets[band + 1] += 1;
            }
        }
        for k in 0..bands {
            offsets[k + 1] += offsets[k];
        }
        let mut fill = offsets.clone();
        let mut items = vec![0u32; offsets[bands] as usize];
        for &(i, a, b) in ranges {
            for band in a..=b {
                items[fill[band] as usize] = i;
                fill[band] += 1;
            }
        }
        Bins { offsets, items }
    }

    pub fn get(&self, band: usize) -> &[u32] {
        &self.items[self.offsets[band] as usize..self.offsets[band + 1] as usize]
    }
}

/// Everything needed to draw one layer.
pub(crate) struct DrawableLayer {
    pub space: ColourSpace,
    pub triangles: TriangleList,
    pub triangle_bins: Bins,
    pub lines: Vec<Line>,
    pub line_bins: Bins,
    pub nearest: NearestSegments,
    /// Columns `[start, end)` where coverage can be non-zero.
    pub columns: (usize, usize),
    /// The colour bounds of a layer with quadratic triangles (see [`Bounds`]).
    pub bounds: Option<Bounds>,
    /// Whether the colours of the control points the layer is drawn from (whose convex hull
    /// holds every colour it shows, up to rounding) have all their channels in `0..=1`: in an
    /// sRGB layer, hardly any pixel then needs gamut mapping.
    pub colours_in_unit_range: bool,
    /// The outline the layer is clipped to, if any.
    pub clip: Option<Clip>,
    /// Whether a pixel whose centre a triangle covers counts as covered whatever the
    /// outline's coverage: the layer is the union of its triangles, also where it folds over
    /// its outline (the classic painting of an SVG mesh, whose clip gives the edge).
    pub covered_by_triangles: bool,
}

/// The outline a layer is clipped to, ready to draw (see `clip.rs`): a pixel's coverage is
/// the smaller of the layer's and the clip's.
#[derive(Clone, Debug)]
pub(crate) struct Clip {
    /// Closed loops of line segments, in pixels.
    pub lines: Vec<Line>,
    pub line_bins: Bins,
    /// Columns `[start, end)` where the clip's coverage can be non-zero.
    pub columns: (usize, usize),
    /// Whether the even-odd rule decides the inside (else the non-zero rule).
    pub even_odd: bool,
}

impl Clip {
    /// `path` (in the plane) in the pixels of `opts`, with its fill rule.
    pub fn new(path: &kurbo::BezPath, rule: FillRule, xf: &ToPixels, opts: &RenderOptions) -> Clip {
        let bands = (opts.height as usize).div_ceil(BAND);
        let (lines, line_bins, columns) = visible_outline(clip_lines(path, xf), opts, bands);
        Clip {
            lines,
            line_bins,
            columns,
            even_odd: rule == FillRule::EvenOdd,
        }
    }
}

/// Columns `[start, end)` of a band that may draw differently: empty when `start >= end`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Columns {
    pub start: usize,
    pub end: usize,
}

impl Columns {
    /// No column.
    pub const NONE: Columns = Columns {
        start: usize::MAX,
        end: 0,
    };

    /// Every column of a `width`-pixel image.
    pub fn all(width: usize) -> Columns {
        Columns {
            start: 0,
            end: width,
        }
    }

    pub fn is_empty(self) -> bool {
        self.start >= self.end
    }

    /// How many columns.
    pub fn len(self) -> usize {
        self.end.saturating_sub(self.start)
    }

    /// Widens these columns to hold `start..end` too (nothing if that is empty).
    pub fn include(&mut self, start: usize, end: usize) {
        if start < end {
            self.start = self.start.min(start);
            self.end = self.end.max(end);
        }
    }
}

impl DrawableLayer {
    /// Widens, in `dirty` (columns per band of a `width`-pixel image), the columns where this
    /// layer may draw differently from `old`, its last preparation:
    /// - where a triangle of either lies that the other does not hold, bit for bit, at the
    ///   same place ([`TriangleList::for_each_moved`]);
    /// - from the leftmost to the rightmost outline line that differs in any bit (coverage is
    ///   a prefix sum along the row, in fixed point: to the left of a change it is the same sum,
    ///   and to the right too, to the unit, since both outlines are closed: see
    ///   [`coverage`](crate::render::raster::coverage));
    /// - within `reach[band]` of a boundary segment that changed (the farthest its outline
    ///   pixels there took their colour from when last drawn);
    ///
    /// and every column of every band when something the whole layer's drawing reads changed
    /// (its colour space, columns or colour bounds), or when either is clipped.
    pub fn mark_changed_columns(
        &self,
        old: &DrawableLayer,
        reach: &[f64],
        width: usize,
        dirty: &mut [Columns],
    ) {
        let all = Columns::all(width);
        let bounds = |b: &Option<Bounds>| b.map(|b| b.map(|r| r.map(f32::to_bits)));
        let alike = self.clip.is_none()
            && old.clip.is_none()
            && !self.covered_by_triangles
            && !old.covered_by_triangles
            && self.space == old.space
            && self.columns == old.columns
            && bounds(&self.bounds) == bounds(&old.bounds)
            && self.colours_in_unit_range == old.colours_in_unit_range;
        if !alike {
            dirty.fill(all);
            return;
        }
        let segments = self.nearest.changed_boxes(&old.nearest);
        let column = |x: f64| x.clamp(0.0, width as f64) as usize;
        // The rows of the bands (the last may reach past the image: the bands are the same).
        let rows = (dirty.len() * BAND) as i64;
        for (layer, other) in [(self, old), (old, self)] {
            layer.triangles.for_each_moved(&other.triangles, |t| {
                let (r0, r1) = t.rows();
                if r1 <= r0.max(0) || r0 >= rows {
                    return;
                }
                let (first, last) = bands_of_rows((r0, r1), rows);
                let (a, b) = t.columns(width);
                for dirty in &mut dirty[first..=last] {
                    dirty.include(a, b);
                }
            });
        }
        let line = |l: &Line| [l.p0, l.p1].map(|p| p.map(f64::to_bits));
        for (band, dirty) in dirty.iter_mut().enumerate() {
            if *dirty == all {
                continue;
            }
            // A changed segment farther from every pixel centre of the band than the answers
            // its outline pixels took (plus a pixel, for rounding) changes none of them.
            let (top, bottom) = ((band * BAND) as f64 + 0.5, ((band + 1) * BAND) as f64 - 0.5);
            let margin = reach[band] + 1.0;
            for &[[x0, x1], [y0, y1]] in &segments {
                if y0 <= bottom + margin && y1 >= top - margin {
                    let (a, b) = (x0 - margin, x1 + margin);
                    dirty.include(column(a.floor()), column(b.ceil() + 1.0));
                }
            }

            // The lines in neither the common start nor the common end of the two bins.
            let (a, b) = (self.line_bins.get(band), old.line_bins.get(band));
            let same = |(&i, &j): (&u32, &u32)| {
                line(&self.lines[i as usize]) == line(&old.lines[j as usize])
            };
            let prefix = a.iter().zip(b).take_while(|&p| same(p)).count();
            let rest = a.len().min(b.len()) - prefix;
            let suffix = a
                .iter()
                .rev()
                .zip(b.iter().rev())
                .take(rest)
                .take_while(|&p| same(p))
                .count();
            // The columns of the lines that differ: `(left, right)`.
            let middle = |bin: &[u32], layer: &DrawableLayer| {
                bin[prefix..bin.len() - suffix].iter().fold(
                    (f64::INFINITY, f64::NEG_INFINITY),
                    |(left, right), &i| {
                        let l = &layer.lines[i as usize];
                        (
                            left.min(l.p0[0].min(l.p1[0])),
                            right.max(l.p0[0].max(l.p1[0])),
                        )
                    },
                )
            };
            let ((left_new, right_new), (left_old, right_old)) = (middle(a, self), middle(b, old));
            let (left, right) = (left_new.min(left_old), right_new.max(right_old));
            if left < f64::INFINITY {
                // The cells a line changes run from the one holding its left end to the one
                // after its right end (clamped to the image as the accumulation clamps them);
                // the sums right of those are the same.
                let end = right.clamp(0.0, width as f64).ceil() as usize + 2;
                dirty.include(
                    column(left.floor() - 1.0),
                    end.min(self.columns.1).min(width),
                );
            }
        }
    }
}

/// The mesh with its colours converted to `space` (so that they are interpolated there).
fn in_space(mesh: &GradientMesh, space: ColourSpace) -> GradientMesh {
    let mut m = mesh.clone();
    if space == mesh.colour_space {
        return m;
    }
    for p in &mut m.points {
        p.colour = mesh.colour_space.convert(space, p.colour);
        p.colour_text = None;
    }
    for w in &mut m.wedges {
        w.colour = mesh.colour_space.convert(space, w.colour);
        w.colour_text = None;
    }
    m.colour_space = space;
    m
}

/// The result of choosing a level.
struct ChosenLevel {
    level: usize,
    capped: bool,
    measured: Option<Measure>,
    /// Whether `measured` is a prediction from the level above.
    estimated: bool,
}

/// The level drawn when [`RenderOptions::level`] asks for `forced`: at least 2, and deep enough
/// for the edits of level d to show fully (from level d + 1).
fn forced_level(base: &BaseMesh, forced: usize) -> usize {
    forced.max(2).max(base.edits.deepest_level() + 1)
}

/// The limit data of level `k >= 2` (all quads), without copying the level's data.
fn limit_of(refinement: &mut Refinement, data: &RefinedData, k: usize) -> Vec<VertexData> {
    match limit_surface::limit_stencils(refinement.level(k)) {
        Some(st) => st.apply(&data.levels[k]),
        None => refinement.limit(data, k),
    }
}

/// Refines until the triangles of the quads that reach the image show the limit colours within
/// [`RenderOptions::colour_tolerance`], their quads are at most [`RenderOptions::max_quad_px`]
/// across, and the boundary edges lie within [`RenderOptions::tolerance_px`] of the outline (or
/// until a cap is reached). Colour errors in quads under [`MIN_QUAD_PX`] are not counted (see
/// [`measure`]).
///
/// Level 2 is the first all-quad level. Measuring level `k` needs level `k + 1`. When level `k`
/// fails but would pass with its errors halved (colour and size halve at least per level; the
/// outline's distance quarters), level `k + 1`, already built, is drawn, so in most cases no level
/// beyond the drawn one is built. Returns the choice and the limit data of the chosen level.
fn choose_level(
    refinement: &mut Refinement,
    data: &mut RefinedData,
    xf: &ToPixels,
    opts: &RenderOptions,
    space: ColourSpace,
) -> (ChosenLevel, Vec<VertexData>) {
    let (quad, tol, colour_tol, min_quad) = if opts.reference {
        (
            opts.max_quad_px.min(REFERENCE_QUAD_PX),
            opts.tolerance_px.min(REFERENCE_TOLERANCE_PX),
            opts.colour_tolerance.min(REFERENCE_COLOUR_TOLERANCE),
            REFERENCE_MIN_QUAD_PX,
        )
    } else {
        (
            opts.max_quad_px,
            opts.tolerance_px,
            opts.colour_tolerance,
            MIN_QUAD_PX,
        )
    };
    let size = (opts.width as f64, opts.height as f64);
    let extend = |refinement: &mut Refinement, data: &mut RefinedData, k: usize| {
        while data.levels.len() <= k {
            let j = data.levels.len() - 1;
            refinement.extend_to(j + 1);
            let next = refinement.next_level_data(j, &data.levels[j]);
            data.levels.push(next);
        }
    };
    if let Some(forced) = opts.level {
        let k = forced_level(refinement.base(), forced);
        extend(refinement, data, k);
        let lim = limit_of(refinement, data, k);
        let choice = ChosenLevel {
            level: k,
            capped: false,
            measured: None,
            estimated: false,
        };
        return (choice, lim);
    }
    let passes = |m: &Measure| m.extent <= quad && m.colour <= colour_tol && m.outline <= tol;
    // Edits of level k show fully from level k + 1 (their rings are set there).
    let wanted = refinement.base().edits.deepest_level() + 1;
    let mut k = 2;
    extend(refinement, data, k);
    while k < wanted
        && refinement.topology(k).corner_count() <= opts.max_quads
        && k < opts.max_level.max(2)
    {
        k += 1;
        extend(refinement, data, k);
    }
    let mut lim = limit_of(refinement, data, k);
    let mut last: Option<Measure> = None;
    loop {
        let next_faces = refinement.topology(k).corner_count();
        if next_faces > opts.max_quads || k + 1 > opts.max_level.max(2) {
            let choice = ChosenLevel {
                level: k,
                capped: true,
                measured: last,
                estimated: true,
            };
            return (choice, lim);
        }
        extend(refinement, data, k + 1);
        let lim1 = limit_of(refinement, data, k + 1);
        let m = measure(
            refinement.topology(k),
            &lim,
            &lim1,
            xf,
            size,
            space,
            min_quad,
        );
        if passes(&m) {
            let choice = ChosenLevel {
                level: k,
                capped: false,
                measured: Some(m),
                estimated: false,
            };
            return (choice, lim);
        }
        let predicted = Measure {
            extent: 0.5 * m.extent,
            colour: 0.5 * m.colour,
            outline: 0.25 * m.outline,
        };
        if passes(&predicted) {
            let choice = ChosenLevel {
                level: k + 1,
                capped: false,
                measured: Some(predicted),
                estimated: true,
            };
            return (choice, lim1);
        }
        last = Some(predicted);
        k += 1;
        lim = lim1;
    }
}

/// The uniform path's triangles: every quad of level `t` with the limit data `lim` at its
/// corners, in face order (the draw order where the surface folds over itself), and the
/// boundary edges of that tessellation.
fn uniform_triangles(
    t: &Topology,
    lim: &[VertexData],
    xf: &ToPixels,
    size: (i64, i64),
) -> (TriangleList, Vec<Segment>) {
    let exact: Vec<[f64; 2]> = lim
        .iter()
        .map(|d| xf.apply(d.position[0], d.position[1]))
        .collect();
    let attr = |v: u32| lim[v as usize].attributes();
    let face_triangles = |f: usize| -> Vec<Triangle> {
        let fv = t.face_vertices(f);
        (1..fv.len() - 1)
            .filter_map(|i| {
                let idx = [fv[0], fv[i], fv[i + 1]];
                screen_triangle_px(
                    idx.map(|i| exact[i as usize]),
                    idx.map(attr),
                    None,
                    &UNBOUNDED,
                    size,
                )
            })
            .collect()
    };
    // Built in parallel, kept in face order.
    let triangles = TriangleList::from_chunks(
        (0..t.face_count())
            .into_par_iter()
            .map(face_triangles)
            .collect(),
    );

    // Boundary edges of the tessellation, for outline pixels no triangle reaches.
    let snappable = |p: [f64; 2]| snap(p[0]).is_some() && snap(p[1]).is_some();
    let mut segments = Vec::new();
    for lp in &boundary_loops(t) {
        for i in 0..lp.len() {
            let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
            if snappable(exact[a as usize]) && snappable(exact[b as usize]) {
                let c = |v: u32| attr(v).map(|x| x as f32);
                segments.push(Segment {
                    a: exact[a as usize],
                    b: exact[b as usize],
                    ca: c(a),
                    cb: c(b),
                    bump: [0.0; 4],
                });
            }
        }
    }
    (triangles, segments)
}

/// What [`prepare`] returns: the layer's description, the layer ready to draw (`None` when
/// nothing of it reaches the image) and the warnings of its validation.
pub(crate) type LayerPreparation = (LayerInfo, Option<DrawableLayer>, Vec<Warning>);

/// Prepares layer `index` of a document for drawing, sharing local refinements through
/// `shapes`, and taking the plans of unchanged regular faces from `memo` (which then holds
/// this preparation's: see [`adaptive::TessellationCache`]).
pub(crate) fn prepare(
    mesh: &GradientMesh,
    index: usize,
    opts: &RenderOptions,
    xf: &ToPixels,
    shapes: &ShapeCache,
    mut memo: Option<&mut adaptive::TessellationCache>,
) -> Result<LayerPreparation, Error> {
    if mesh.faces.is_empty() {
        return Ok((LayerInfo::default(), None, Vec::new()));
    }
    let mut timings = LayerTimings::default();
    let start = Instant::now();
    let space = opts.colour_space_override.unwrap_or(mesh.colour_space);
    let (mut refinement, warnings) = refine_layer(mesh, index, opts, space, memo.as_deref_mut())?;
    let mut data = refinement.evaluate_to(refinement.base(), 1);
    timings.refine = start.elapsed();
    let start = Instant::now();
    let tess = tessellate_layer(
        &mut refinement,
        &mut data,
        xf,
        opts,
        space,
        shapes,
        memo.as_deref_mut(),
    );
    let LayerTriangles {
        level: k,
        triangles,
        segments,
        bounds,
        mut info,
    } = tess;
    info.timings = LayerTimings {
        evaluate: start.elapsed(),
        ..timings
    };
    let start = Instant::now();
    let h = opts.height as i64;
    let bands = (opts.height as usize).div_ceil(BAND);
    let triangle_bins = bin_triangles(&triangles, bands, h);

    // The outline, from the control points of level k.
    let loops = boundary_loops(refinement.topology(k));
    let control_px: Vec<[f64; 2]> = data.levels[k]
        .iter()
        .map(|d| xf.apply(d.position[0], d.position[1]))
        .collect();
    let tolerance = if opts.reference {
        REFERENCE_OUTLINE_TOLERANCE_PX
    } else {
        OUTLINE_TOLERANCE_PX
    };
    let all_lines = outline(refinement.level(k), &loops, &control_px, tolerance);
    if let Some(memo) = memo {
        memo.refinement = Some(refinement);
    }
    let (lines, line_bins, columns) = visible_outline(all_lines, opts, bands);

    let nearest = NearestSegments::new(segments);
    info.timings.tessellate = start.elapsed();
    if lines.is_empty() || columns.0 >= columns.1 {
        return Ok((info, None, warnings));
    }
    let colours_in_unit_range = data.levels[k]
        .iter()
        .all(|d| d.colour.iter().all(|c| (0.0..=1.0).contains(c)));
    let layer = DrawableLayer {
        space,
        triangles,
        triangle_bins,
        lines,
        line_bins,
        nearest,
        columns,
        bounds,
        colours_in_unit_range,
        clip: None,
        covered_by_triangles: false,
    };
    Ok((info, Some(layer), warnings))
}

/// Validates layer `index` in `space` and readies its refinement at level 1, within
/// [`RenderOptions::max_quads`]; with the validation's warnings, marked with the layer.
fn refine_layer(
    mesh: &GradientMesh,
    index: usize,
    opts: &RenderOptions,
    space: ColourSpace,
    memo: Option<&mut adaptive::TessellationCache>,
) -> Result<(Refinement, Vec<Warning>), Error> {
    let original_space = mesh.colour_space;
    let mesh = in_space(mesh, space);
    // Level 1 only: the fast path of a dense layer starts there, and each path builds the
    // levels it needs (level 2 of a dense mesh is costly and often not needed). An edited layer
    // whose topology stayed takes the levels its last preparation built.
    let (base, warnings) = BaseMesh::new(&mesh).map_err(|e| e.in_layer(index))?;
    // Every level built counts against `max_quads`, estimated before anything is built: a
    // forced level, and the levels interpolated positions need down to where no semi-sharp
    // feature is left, whatever the image needs.
    let deepest = opts.level.map_or(1, |forced| forced_level(&base, forced));
    Limits {
        refined_faces: opts.max_quads as u64,
        ..Limits::NONE
    }
    .check_refinement(&base, deepest)
    .map_err(|e| e.in_layer(index))?;
    let kept = memo.and_then(|m| m.refinement.take());
    let mut refinement = Refinement::rebased_or_new(kept, base, 1);
    // The edits' colours stay in the space they were written in.
    refinement.set_edit_colour_space(original_space);
    let warnings = warnings
        .into_iter()
        .map(|w| Warning {
            layer: Some(index),
            ..w
        })
        .collect();
    Ok((refinement, warnings))
}

/// A layer's triangles: the level they were made at, the triangles, the boundary segments of
/// the tessellation, the colour bounds of quadratic triangles, and the layer's description
/// (without timings).
struct LayerTriangles {
    level: usize,
    triangles: TriangleList,
    segments: Vec<Segment>,
    bounds: Option<Bounds>,
    info: LayerInfo,
}

/// Tessellates a layer: by the fast path where it applies and succeeds (sharing local
/// refinements through `shapes`, and taking plans from `memo`), else uniformly.
fn tessellate_layer(
    refinement: &mut Refinement,
    data: &mut RefinedData,
    xf: &ToPixels,
    opts: &RenderOptions,
    space: ColourSpace,
    shapes: &ShapeCache,
    memo: Option<&mut adaptive::TessellationCache>,
) -> LayerTriangles {
    let (w, h) = (opts.width as i64, opts.height as i64);
    let th = Thresholds::new(opts, space);
    // The fast path starts at its base level: a shallower cap is the uniform path's to honour.
    let fast = if opts.reference || opts.level.is_some() || opts.max_level < adaptive::BASE_LEVEL {
        None
    } else {
        adaptive::tessellate(
            refinement,
            data,
            xf,
            &th,
            opts.max_level,
            (w, h),
            adaptive::Caches {
                shapes,
                tessellation: memo,
            },
        )
    };
    if let Some(tess) = fast {
        let info = LayerInfo {
            level: tess.level,
            capped: tess.capped,
            quads: tess.quads,
            triangles: tess.triangles.len(),
            max_quad_px: tess.measured.extent,
            max_outline_deviation_px: tess.measured.outline,
            max_colour_error: tess.measured.colour,
            estimated: tess.estimated,
            timings: LayerTimings::default(),
            reused: false,
            reused_faces: tess.reused_plans,
        };
        return LayerTriangles {
            level: tess.base_level,
            triangles: tess.triangles,
            segments: tess.segments,
            bounds: tess.bounds,
            info,
        };
    }
    let (choice, lim) = choose_level(refinement, data, xf, opts, space);
    let (triangles, segments) =
        uniform_triangles(refinement.topology(choice.level), &lim, xf, (w, h));
    let info = LayerInfo {
        level: choice.level,
        capped: choice.capped,
        quads: refinement.topology(choice.level).face_count(),
        triangles: triangles.len(),
        max_quad_px: choice.measured.map_or(f64::NAN, |m| m.extent),
        max_outline_deviation_px: choice.measured.map_or(f64::NAN, |m| m.outline),
        max_colour_error: choice.measured.map_or(f64::NAN, |m| m.colour),
        estimated: choice.estimated,
        timings: LayerTimings::default(),
        reused: false,
        reused_faces: 0,
    };
    LayerTriangles {
        level: choice.level,
        triangles,
        segments,
        bounds: None,
        info,
    }
}

/// The triangles of each band of rows, of an image `h` rows high.
pub(crate) fn bin_triangles(triangles: &TriangleList, bands: usize, h: i64) -> Bins {
    let ranges: Vec<(u32, usize, usize)> = triangles
        .iter()
        .enumerate()
        .map(|(i, tri)| {
            let (a, b) = bands_of_rows(tri.rows(), h);
            (i as u32, a, b)
        })
        .collect();
    Bins::new(bands, &ranges)
}

/// The lines of the outline that can change a pixel of the image, binned by band, and the
/// columns where coverage can be non-zero.
pub(crate) fn visible_outline(
    all_lines: Vec<Line>,
    opts: &RenderOptions,
    bands: usize,
) -> (Vec<Line>, Bins, (usize, usize)) {
    let (w, h) = (opts.width as i64, opts.height as i64);
    let mut lines = Vec::new();
    let mut line_ranges = Vec::new();
    let (mut c0, mut c1) = (f64::INFINITY, f64::NEG_INFINITY);
    for l in all_lines {
        let (r0, r1) = l.rows();
        if r1 <= 0 || r0 >= h || r0 == r1 {
            continue;
        }
        // Coverage can be non-zero from the leftmost to the rightmost line crossing the rows,
        // including lines right of the image. Those add nothing visible but are kept: with
        // them each row's lines make closed loops, whose sums a cached render relies on
        // (see `DrawableLayer::mark_changed_columns`).
        c0 = c0.min(l.p0[0]).min(l.p1[0]);
        c1 = c1.max(l.p0[0]).max(l.p1[0]);
        let (a, b) = bands_of_rows((r0, r1), h);
        line_ranges.push((lines.len() as u32, a, b));
        lines.push(l);
    }
    let line_bins = Bins::new(bands, &line_ranges);
    let columns = if lines.is_empty() {
        (0, 0)
    } else {
        (
            c0.floor().clamp(0.0, w as f64) as usize,
            (c1.ceil() + 1.0).clamp(0.0, w as f64) as usize,
        )
    };
    (lines, line_bins, columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Boundary segments one every 8 rows, down the image at x 10 (segment `shift` at 10.5).
    fn segment_list(bands: usize, shift: Option<usize>) -> Vec<Segment> {
        (0..2 * bands)
            .map(|k| {
                let y = 8.0 * k as f64;
                let x = if shift == Some(k) { 10.5 } else { 10.0 };
                Segment {
                    a: [x, y],
                    b: [x, y + 8.0],
                    ca: [50.0, 0.0, 0.0, 1.0],
                    cb: [50.0, 0.0, 0.0, 1.0],
                    bump: [0.0; 4],
                }
            })
            .collect()
    }

    /// A layer of nothing but the boundary segments of [`segment_list`].
    fn segments_only(bands: usize, shift: Option<usize>) -> DrawableLayer {
        DrawableLayer {
            space: ColourSpace::Lab,
            triangles: TriangleList::default(),
            triangle_bins: Bins::new(bands, &[]),
            lines: Vec::new(),
            line_bins: Bins::new(bands, &[]),
            nearest: NearestSegments::new(segment_list(bands, shift)),
            columns: (0, 20),
            bounds: None,
            colours_in_unit_range: false,
            clip: None,
            covered_by_triangles: false,
        }
    }

    /// A changed boundary segment marks the columns of the bands whose outline pixels took
    /// colours from within its reach, and no other.
    #[test]
    fn changed_segments_mark_the_columns_within_reach() {
        let bands = 8;
        let width = 40;
        let (old, new) = (segments_only(bands, None), segments_only(bands, Some(9)));
        let changed = |reach: f64| {
            let mut dirty = vec![Columns::NONE; bands];
            new.mark_changed_columns(&old, &vec![reach; bands], width, &mut dirty);
            dirty
        };
        // Segment 9 spans rows 72 to 80 at x 10 (old) and 10.5 (new); band 4 holds rows 64 to
        // 79, band 5 rows 80 to 95.
        assert_eq!(changed(f64::NEG_INFINITY), [Columns::NONE; 8]);
        let near = |start, end| {
            let cols = Columns { start, end };
            [false, false, false, false, true, true, false, false].map(|n| {
                if n {
                    cols
                } else {
                    Columns::NONE
                }
            })
        };
        // Within 1.5 pixels (the reach and a pixel) of x 10 to 10.5: columns 8 to 12.
        assert_eq!(changed(0.5), near(8, 13));
        let mut far = near(1, 21);
        far[3] = far[4];
        assert_eq!(changed(8.0), far);
        // Another count of segments (segment 9 gone, the others in order): the columns within
        // reach of the segment in neither common end, as if it had moved.
        let mut kept = segment_list(bands, None);
        kept.remove(9);
        let fewer = DrawableLayer {
            nearest: NearestSegments::new(kept),
            ..segments_only(bands, None)
        };
        let mut dirty = vec![Columns::NONE; bands];
        fewer.mark_changed_columns(&old, &[0.5; 8], width, &mut dirty);
        assert_eq!(dirty, near(8, 13));
    }
}
