//! Fitting gradient meshes to pictures: the control colours of a mesh by least squares on its
//! limit surface ([`fit_colours`]), and a whole picture turned into a mesh of free topology
//! ([`vectorise`]).
//!
//! For a fixed topology and fixed edge tags the limit colour of every surface point is a fixed
//! linear combination of the control colours ([`rows`]); the geometry only decides which
//! surface point each pixel sees ([`raster`]). So the best colours for a given geometry solve a
//! sparse linear least-squares problem in the working colour space ([`solve`]).
//!
//! [`vectorise`] starts from a coarse grid of cells over the picture, fits the colours, and
//! splits the cells with the largest error into four ([`quadtree`]): a cell beside split ones
//! becomes an n-gon, which the scheme handles as any other face. It repeats until the point
//! budget or the PSNR asked for is reached. Then the points move by damped Gauss-Newton steps
//! ([`geometry`]), the colours solved again after each, while the error falls and the surface
//! stays free of folds. The mesh is written with its faces along a Hilbert curve and its points
//! numbered as the faces first use them ([`order`]), for a small gzipped file. A picture with
//! transparent pixels keeps the cells that are mostly opaque, splits those its silhouette
//! crosses, and puts the mesh's outline on it ([`silhouette`]).

mod detail;
mod geometry;
mod image;
mod order;
mod quadtree;
mod raster;
mod rows;
mod silhouette;
mod solve;

use std::collections::{HashMap, HashSet};

use crate::colour::{srgb_encode, ColourSpace};
use crate::error::{Error, ErrorKind};
use crate::folds::find_folds;
use crate::limit_surface::limit_stencils;
use crate::mesh::{Document, FirstStep, GradientMesh};
use crate::refine::Refinement;
use crate::render::{render_document_into, RenderOptions, View};
use crate::scheme::BoundaryInterpolation;
use crate::size_limits::Limits;

pub use image::{psnr, RgbaImage, MAX_IMAGE_BYTES, MAX_IMAGE_PIXELS};

pub use detail::{fit_colours_with_detail, DetailFit, DetailOptions};
use image::{psnr_of_sum, Target};
use quadtree::{Key, Quadtree, TreeMesh};
use silhouette::Silhouette;

use detail::DetailEdits;
use raster::Observation;
use rows::SparseRows;
use solve::NormalEquations;

/// How much time a fit may take.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Quality {
    /// A coarse surface sampling and large refinement rounds.
    Fast,
    /// The balance of time and accuracy.
    #[default]
    Default,
    /// A finer sampling, smaller rounds, tighter solves.
    Best,
}

impl Quality {
    /// Refined faces allowed per pixel when choosing the sampling level.
    fn faces_per_pixel(self) -> f64 {
        match self {
            Quality::Fast => 0.25,
            Quality::Default => 0.6,
            Quality::Best => 1.5,
        }
    }

    /// How much the point count may grow in one round of splits.
    fn growth(self) -> f64 {
        match self {
            Quality::Fast => 1.7,
            Quality::Default => 1.35,
            Quality::Best => 1.15,
        }
    }

    /// Rounds of Gauss-Newton steps on the point positions of a mesh of 1024 points or more
    /// ([`position_rounds`] gives smaller meshes more).
    fn position_rounds(self) -> usize {
        match self {
            Quality::Fast => 2,
            Quality::Default => 4,
            Quality::Best => 8,
        }
    }

    fn max_iterations(self) -> usize {
        match self {
            Quality::Fast => 60,
            Quality::Default => 150,
            Quality::Best => 400,
        }
    }
}

/// What [`vectorise`] aims at.
#[derive(Clone, Debug, PartialEq)]
pub struct VectoriseOptions {
    /// The most control points in all (at least 4). Without it or [`VectoriseOptions::psnr`],
    /// 1024.
    pub points: Option<usize>,
    /// Stop once the fit reaches this PSNR (dB), or at [`VectoriseOptions::points`] (or
    /// [`VectoriseOptions::max_points`]) if it comes first.
    pub psnr: Option<f64>,
    /// The time spent.
    pub quality: Quality,
    /// The working colour space of the mesh, in which the least squares are solved.
    pub colour_space: ColourSpace,
    /// The weight of the smoothness term (differences of colour along the mesh's edges),
    /// relative to the average weight a control point gets from its pixels.
    pub smoothness: f64,
    /// The cap on the points when only a PSNR is asked for.
    pub max_points: usize,
    /// Cells are not split below this size, in pixels.
    pub min_cell_px: f64,
    /// Move the points after the last split to cut the error (damped Gauss-Newton steps, the
    /// colours solved again after each, kept only if the surface stays free of folds and the
    /// error falls). Points on the picture's sides slide along them; its corners stay.
    pub fit_positions: bool,
    /// Round the output for a small file: where the fit is below 32 dB PSNR (photographs at
    /// the budgets that pay), positions to half a pixel and colours to a hundredth of the colour
    /// space's lightness range (whole units in Lab), which costs the rendered picture a few
    /// hundredths of a dB and saves about a fifth of the gzipped bytes (the curve is in
    /// `docs/vectorise.md`); above it, both to a tenth of that.
    pub round_output: bool,
}

impl Default for VectoriseOptions {
    fn default() -> Self {
        VectoriseOptions {
            points: None,
            psnr: None,
            quality: Quality::Default,
            colour_space: ColourSpace::Lab,
            smoothness: 1e-3,
            max_points: 1 << 15,
            min_cell_px: 3.0,
            fit_positions: true,
            round_output: true,
        }
    }
}

/// What [`vectorise`] made.
#[derive(Clone, Debug)]
pub struct Vectorised {
    /// One mesh covering the picture, in its pixel coordinates (`0..width` x `0..height`).
    pub document: Document,
    /// Its control points.
    pub points: usize,
    /// PSNR (dB) of the document rendered at the picture's size against the picture.
    pub psnr: f64,
    /// Rounds of fitting and splitting.
    pub rounds: usize,
}

/// Where [`vectorise_with_progress`] has got to, after each round.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Rounds done.
    pub round: usize,
    /// Control points of the mesh fitted.
    pub points: usize,
    /// PSNR (dB) of the fitted surface as the fit samples it.
    pub psnr: f64,
}

fn invalid(what: &str, message: impl Into<String>) -> Error {
    Error::new(ErrorKind::Invalid {
        what: what.into(),
        message: message.into(),
    })
}

/// The colours of the points of a mesh fitted, and how the surface then sees the picture.
struct Fitted {
    colours: Vec<[f64; 3]>,
    /// The limit colour rows of the sampled level's vertices.
    rows: SparseRows,
    observation: Observation,
    /// The limit colours of the sampled level's vertices.
    vertex_colours: Vec<[f64; 3]>,
}

/// Settings of one colour fit.
struct FitSettings {
    faces_per_pixel: f64,
    smoothness: f64,
    tolerance: f64,
    max_iterations: usize,
    /// The weight of the offsets of refined-level edits, relative to the average weight a
    /// control point gets from its pixels.
    ridge: f64,
}

/// The sampling level: the deepest (2 to 6) whose faces number at most `faces_per_pixel` per
/// pixel of the target, and at least level 2.
fn sampling_level(mesh: &GradientMesh, pixels: usize, faces_per_pixel: f64) -> usize {
    let corners = mesh.corner_count() as f64;
    let allowed = pixels as f64 * faces_per_pixel;
    let mut level = 2;
    // Level k >= 2 has 9 * corners * 4^(k - 2) quads.
    while level < 6 && 9.0 * corners * 4f64.powi(level as i32 - 1) <= allowed {
        level += 1;
    }
    level
}

/// Refuses what the colour fit does not model: another first step, edits, wedge overrides.
fn check_fittable(mesh: &GradientMesh) -> Result<(), Error> {
    if mesh.first_step != FirstStep::Ternary {
        return Err(invalid(
            "mesh",
            "the colour fit models the ternary first step only",
        ));
    }
    if !mesh.edits.is_empty() || !mesh.wedges.is_empty() {
        return Err(invalid(
            "mesh",
            "the colour fit does not model multi-resolution edits or wedge colours; remove them first",
        ));
    }
    Ok(())
}

/// The mesh's edges as point pairs, once each.
fn mesh_edges(mesh: &GradientMesh) -> Vec<[u32; 2]> {
    let mut set = HashSet::new();
    for f in &mesh.faces {
        for (i, &a) in f.iter().enumerate() {
            let b = f[(i + 1) % f.len()];
            set.insert([a.min(b), a.max(b)]);
        }
    }
    let mut edges: Vec<[u32; 2]> = set.into_iter().collect();
    edges.sort_unstable();
    edges
}

/// Fits the colours of `mesh` (positions fixed) to `target`, starting from `guess`.
fn fit_mesh(
    mesh: &GradientMesh,
    target: &Target,
    settings: &FitSettings,
    colours: Vec<[f64; 3]>,
) -> Result<Fitted, Error> {
    let refinement = |depth| Refinement::new_with_limits(mesh, depth, &Limits::DEFAULT);
    let depth = sampling_level(mesh, target.width * target.height, settings.faces_per_pixel);
    let (refinement, _) = refinement(depth)?;
    fit_refined(mesh, &refinement, target, settings, colours, None)
}

/// [`fit_mesh`] on the levels of `refinement` (sampled at its deepest level), with the
/// offsets of `detail` as unknowns after the control colours (`colours` holds both).
fn fit_refined(
    mesh: &GradientMesh,
    refinement: &Refinement,
    target: &Target,
    settings: &FitSettings,
    mut colours: Vec<[f64; 3]>,
    detail: Option<&DetailEdits>,
) -> Result<Fitted, Error> {
    let depth = refinement.depth();
    let data = refinement.evaluate_to(refinement.base(), depth);
    let limit = limit_stencils(refinement.level(depth)).expect("levels from 2 on are quads");
    let positions: Vec<[f64; 2]> = limit
        .apply(&data.levels[depth])
        .iter()
        .map(|d| d.position)
        .collect();
    drop(data);
    let points = mesh.points.len();
    let rows = match detail {
        Some(d) => d.limit_colour_rows(refinement, depth, &limit, points),
        None => rows::limit_colour_rows(refinement, depth, &limit, points),
    };
    let observation = Observation::new(refinement, depth, &positions, target);
    let edges = mesh_edges(mesh);
    let mut equations = NormalEquations {
        rows: &rows,
        observation: &observation,
        edges: &edges,
        lambda: 0.0,
        ridge: 0.0,
        ridge_from: points,
    };
    let diagonal = equations.diagonal();
    let mean = diagonal[..points].iter().sum::<f64>() / points.max(1) as f64;
    equations.lambda = settings.smoothness * mean;
    equations.ridge = settings.ridge * mean;
    equations.solve(&mut colours, settings.tolerance, settings.max_iterations);
    let vertex_colours = rows.apply(&colours);
    Ok(Fitted {
        colours,
        rows,
        observation,
        vertex_colours,
    })
}

/// Fits the control colours of `mesh` to `image` by least squares on its limit surface, in
/// the mesh's colour space, with positions, handles and tags kept. The mesh's coordinates are
/// the image's pixels. Pixels weigh by their alpha. Returns the PSNR (dB) of the fitted surface
/// as the fit samples it (over the pixels it covers).
pub fn fit_colours(
    mesh: &mut GradientMesh,
    image: &RgbaImage,
    quality: Quality,
) -> Result<f64, Error> {
    check_fittable(mesh)?;
    let target = Target::new(image, mesh.colour_space);
    let settings = FitSettings {
        faces_per_pixel: quality.faces_per_pixel(),
        smoothness: 0.0,
        tolerance: 1e-10,
        max_iterations: 20 * quality.max_iterations(),
        ridge: 0.0,
    };
    let guess = mesh.points.iter().map(|p| p.colour).collect();
    let fitted = fit_mesh(mesh, &target, &settings, guess)?;
    for (p, c) in mesh.points.iter_mut().zip(&fitted.colours) {
        p.colour = *c;
        p.colour_text = None;
    }
    let errors = pixel_errors(&fitted, &target, image, mesh.colour_space);
    Ok(psnr_of_covered(&errors))
}

/// PSNR of [`pixel_errors`] over the pixels the surface covers.
fn psnr_of_covered(errors: &[Option<f64>]) -> f64 {
    let (sum, count) = errors
        .iter()
        .flatten()
        .fold((0.0, 0), |(s, n), &e| (s + e, n + 3));
    psnr_of_sum(sum, count.max(1))
}

/// Per pixel, the squared 8-bit sRGB error summed over the channels of what the fitted surface
/// shows against the picture, times the pixel's alpha (`None` where the surface does not
/// reach).
fn pixel_errors(
    fitted: &Fitted,
    target: &Target,
    image: &RgbaImage,
    space: ColourSpace,
) -> Vec<Option<f64>> {
    use rayon::prelude::*;
    let eight = |c: f64| (c.clamp(0.0, 1.0) * 255.0).round();
    (0..target.width * target.height)
        .into_par_iter()
        .map(|i| {
            let c = fitted.observation.predict(&fitted.vertex_colours, i)?;
            let rgb = space.to_linear_srgb(c).map(srgb_encode);
            let p = image.pixels[i];
            let error: f64 = (0..3)
                .map(|k| (eight(rgb[k]) - eight(p[k] as f64)).powi(2))
                .sum();
            Some(target.weight[i] * error)
        })
        .collect()
}

/// Turns a picture into a document of one gradient mesh in its pixel coordinates (see the
/// module's documentation), within `options`' budget. Where some pixels are transparent
/// (alpha below one half) the mesh covers the others alone, its outline on their silhouette;
/// a picture with no opaque pixel is an error.
pub fn vectorise(image: &RgbaImage, options: &VectoriseOptions) -> Result<Vectorised, Error> {
    vectorise_with_progress(image, options, |_| {})
}

/// The starting grid: cells of side `min_px` times a power of two, the grid whose point count
/// is nearest `start` in ratio (between half and twice it, or one cell). The cells span the
/// picture, so they are a little larger than that side, never smaller, and halving them reaches
/// cells just above `min_px`: a starting cell of 11.4 px with a 3 px floor could split only
/// once, to 5.7 px.
fn initial_grid(width: f64, height: f64, start: usize, min_px: f64) -> (u32, u32) {
    let start = start.max(4) as f64;
    let along = |extent: f64, side: f64| ((extent / side).floor() as u32).max(1);
    let grid = |side: f64| (along(width, side), along(height, side));
    let points = |(cols, rows): (u32, u32)| (cols as f64 + 1.0) * (rows as f64 + 1.0);
    let mut side = min_px;
    let mut finer = grid(side);
    loop {
        if points(finer) <= start || finer == (1, 1) {
            return finer;
        }
        let coarser = grid(2.0 * side);
        if points(coarser) <= start {
            let nearer = points(finer) / start <= start / points(coarser);
            return if nearer { finer } else { coarser };
        }
        side *= 2.0;
        finer = coarser;
    }
}

/// [`vectorise`], calling `progress` after each round.
pub fn vectorise_with_progress(
    image: &RgbaImage,
    options: &VectoriseOptions,
    mut progress: impl FnMut(&Progress),
) -> Result<Vectorised, Error> {
    let budget = checked_budget(image, options)?;
    let (w, h) = (image.width as f64, image.height as f64);
    let space = options.colour_space;
    let target = Target::new(image, space);
    let quality = options.quality;
    let settings = FitSettings {
        faces_per_pixel: quality.faces_per_pixel(),
        smoothness: options.smoothness,
        tolerance: 1e-4,
        max_iterations: quality.max_iterations(),
        ridge: 0.0,
    };
    let min_px = options.min_cell_px.max(0.5);
    // About a quarter of a point budget; few points when only a PSNR is asked for.
    let start = match options.points {
        Some(n) => n / 4,
        None => 16,
    };
    let (cols, rows) = initial_grid(w, h, start, min_px);
    let mut tree = Quadtree::new(w, h, cols, rows);
    let silhouette = Silhouette::of(image);
    if silhouette.as_ref().is_some_and(Silhouette::is_empty) {
        return Err(invalid(
            "image",
            "every pixel is transparent: there is nothing to trace",
        ));
    }
    let mut known: HashMap<Key, [f64; 3]> = HashMap::new();
    let mut round = 0;
    loop {
        let (shape, leaf_of_face) = faces_of_tree(&tree, silhouette.as_ref());
        if shape.faces.is_empty() {
            // The opaque part is smaller than every cell: split the cells over it.
            let s = silhouette
                .as_ref()
                .expect("an opaque picture keeps every cell");
            let chosen = splits_over_silhouette(&tree, s, min_px, budget);
            if chosen.is_empty() {
                return Err(invalid(
                    "image",
                    format!(
                        "the opaque part of the picture is too small to trace within {budget} points"
                    ),
                ));
            }
            tree.split(&chosen);
            continue;
        }
        let mesh = tree_mesh(&shape, &known, &target, space, silhouette.is_some());
        let guess = mesh.points.iter().map(|p| p.colour).collect();
        let fitted = fit_mesh(&mesh, &target, &settings, guess)?;
        known = shape
            .keys
            .iter()
            .copied()
            .zip(fitted.colours.iter().copied())
            .collect();
        let errors = pixel_errors(&fitted, &target, image, space);
        let leaf_errors = leaf_errors(&tree, &fitted, &errors, &leaf_of_face, silhouette.as_ref());
        let model_psnr = match silhouette {
            None => psnr_of_errors(&errors),
            Some(_) => psnr_of_sum(leaf_errors.iter().sum(), 3 * errors.len()),
        };
        round += 1;
        progress(&Progress {
            round,
            points: mesh.points.len(),
            psnr: model_psnr,
        });
        let reached = options.psnr.is_some_and(|db| model_psnr >= db);
        let chosen = if reached {
            Vec::new()
        } else {
            let chosen = choose_splits(&tree, &leaf_errors, budget, quality.growth(), min_px);
            within_budget(&tree, chosen, budget, silhouette.as_ref())
        };
        if chosen.is_empty() {
            let mut fit = Fit {
                mesh,
                fitted,
                error: psnr_sum(&errors),
            };
            if options.fit_positions {
                round += fit.move_points_rounds(
                    &target,
                    image,
                    &settings,
                    quality,
                    round,
                    &mut progress,
                )?;
            }
            if let Some(s) = &silhouette {
                fit.snap_outline(s, &target, image, &settings)?;
            }
            fit.set_colours();
            if options.round_output {
                let coarse = psnr_of_sum(fit.error, 3 * image.pixels.len()) < COARSE_ROUNDING_DB;
                round_for_output(&mut fit.mesh, coarse)?;
            }
            order::order_for_output(&mut fit.mesh, w, h);
            return finish(fit.mesh, image, round, silhouette.is_some());
        }
        tree.split(&chosen);
    }
}

/// The faces of `tree`'s mesh: one per leaf, or with a silhouette one per leaf it keeps
/// ([`silhouette::kept_faces`]); and per face, its leaf.
fn faces_of_tree(tree: &Quadtree, silhouette: Option<&Silhouette>) -> (TreeMesh, Vec<usize>) {
    let shape = tree.mesh();
    match silhouette {
        Some(s) => silhouette::kept_faces(shape, tree, s),
        None => {
            let leaves = (0..shape.faces.len()).collect();
            (shape, leaves)
        }
    }
}

/// The leaves that can be split and hold pixels on the wrong side of the outline, as many as
/// keep the tree within `budget` points.
fn splits_over_silhouette(
    tree: &Quadtree,
    silhouette: &Silhouette,
    min_px: f64,
    budget: usize,
) -> Vec<usize> {
    let mut chosen: Vec<usize> = (0..tree.leaves.len())
        .filter(|&i| {
            let leaf = &tree.leaves[i];
            tree.can_split(leaf, min_px) && silhouette.miscovered_error(tree, leaf) > 0.0
        })
        .collect();
    let mut present = tree.corner_keys();
    let mut kept = 0;
    for &i in &chosen {
        present.extend(Quadtree::new_points(&tree.leaves[i], &present));
        if present.len() > budget {
            break;
        }
        kept += 1;
    }
    chosen.truncate(kept);
    chosen
}

/// `chosen` splits, or the first half of them as often as needed, so that the mesh of the
/// split tree has at most `budget` points. Only a silhouette can make it have more points than
/// the tree has corners: a point where kept cells touch at a corner alone becomes one per fan.
fn within_budget(
    tree: &Quadtree,
    mut chosen: Vec<usize>,
    budget: usize,
    silhouette: Option<&Silhouette>,
) -> Vec<usize> {
    if silhouette.is_none() {
        return chosen;
    }
    while !chosen.is_empty() {
        let mut split = tree.clone();
        split.split(&chosen);
        if faces_of_tree(&split, silhouette).0.positions.len() <= budget {
            break;
        }
        chosen.truncate(chosen.len() / 2);
    }
    chosen
}

/// The mesh of a quadtree's `shape`: its faces, its points coloured as `known` (by key) or
/// else as the picture under them. The mesh of a silhouette (`outlined`) has a smooth outline
/// (every boundary point follows the B-spline rule) except at the picture's corners.
fn tree_mesh(
    shape: &TreeMesh,
    known: &HashMap<Key, [f64; 3]>,
    target: &Target,
    space: ColourSpace,
    outlined: bool,
) -> GradientMesh {
    let mut mesh = GradientMesh::new(space);
    mesh.name = Some("vectorised".into());
    let (w, h) = (target.width as f64, target.height as f64);
    for (k, p) in shape.keys.iter().zip(&shape.positions) {
        let colour = known
            .get(k)
            .copied()
            .unwrap_or_else(|| target_colour_at(target, *p));
        mesh.add_point(*p, colour);
        if outlined && (p.x == 0.0 || p.x == w) && (p.y == 0.0 || p.y == h) {
            mesh.points.last_mut().expect("just added").corner = true;
        }
    }
    if outlined {
        mesh.boundary = BoundaryInterpolation::EdgeOnly;
    }
    for f in &shape.faces {
        mesh.add_face(f.clone());
    }
    mesh
}

/// The point budget `options` give, after checking them and the picture.
fn checked_budget(image: &RgbaImage, options: &VectoriseOptions) -> Result<usize, Error> {
    let budget = match (options.points, options.psnr) {
        (Some(n), _) => n,
        (None, Some(_)) => options.max_points,
        (None, None) => 1024,
    };
    if budget < 4 {
        return Err(invalid(
            "points",
            format!("{budget}: at least 4 are needed"),
        ));
    }
    if let Some(db) = options.psnr {
        if !(db.is_finite() && db > 0.0) {
            return Err(invalid("psnr", format!("{db}: a positive number of dB")));
        }
    }
    if image.width == 0 || image.height == 0 {
        return Err(invalid("image", "the picture is empty"));
    }
    Ok(budget)
}

/// The sum of squared errors of [`pixel_errors`].
fn psnr_sum(errors: &[Option<f64>]) -> f64 {
    errors.iter().map(|e| e.unwrap_or(0.0)).sum()
}

/// PSNR of [`pixel_errors`] over every pixel (uncovered ones count as no error).
fn psnr_of_errors(errors: &[Option<f64>]) -> f64 {
    psnr_of_sum(psnr_sum(errors), 3 * errors.len())
}

/// A mesh, its colour fit and the fit's summed squared 8-bit error.
struct Fit {
    mesh: GradientMesh,
    fitted: Fitted,
    error: f64,
}

impl Fit {
    /// The fitted colours written into the mesh.
    fn set_colours(&mut self) {
        for (p, c) in self.mesh.points.iter_mut().zip(&self.fitted.colours) {
            p.colour = *c;
        }
    }

    /// Up to `quality`'s rounds of [`Fit::move_points`], until one keeps no step; reports
    /// each kept round to `progress`, numbered on from `rounds_before`. Returns the rounds kept.
    fn move_points_rounds(
        &mut self,
        target: &Target,
        image: &RgbaImage,
        settings: &FitSettings,
        quality: Quality,
        rounds_before: usize,
        progress: &mut impl FnMut(&Progress),
    ) -> Result<usize, Error> {
        let mut kept = 0;
        let rounds = position_rounds(quality, self.mesh.points.len());
        while kept < rounds && self.move_points(target, image, settings)? {
            kept += 1;
            progress(&Progress {
                round: rounds_before + kept,
                points: self.mesh.points.len(),
                psnr: psnr_of_sum(self.error, 3 * image.pixels.len()),
            });
        }
        Ok(kept)
    }

    /// One round of Gauss-Newton steps on the positions ([`geometry`]), each at most a quarter
    /// of the point's shortest edge, tried at full, half and quarter length. Where a step
    /// folds the surface, the points of the folded faces stay and the rest is tried again (at
    /// most [`FOLD_RETRIES`] times). The first step that leaves the surface free of folds and,
    /// with the colours solved again, the error lower is kept. Returns whether one was.
    fn move_points(
        &mut self,
        target: &Target,
        image: &RgbaImage,
        settings: &FitSettings,
    ) -> Result<bool, Error> {
        let mut steps = geometry::position_steps(
            &self.fitted.rows,
            &self.fitted.observation,
            &self.fitted.vertex_colours,
            target,
            self.mesh.points.len(),
            0.1,
        );
        limit_steps(
            &self.mesh,
            &mut steps,
            target.width as f64,
            target.height as f64,
        );
        for scale in [1.0, 0.5, 0.25] {
            let mut frozen = vec![false; steps.len()];
            for _ in 0..=FOLD_RETRIES {
                let mut trial = self.mesh.clone();
                for (i, p) in trial.points.iter_mut().enumerate() {
                    if !frozen[i] {
                        p.position += kurbo::Vec2::new(steps[i][0], steps[i][1]) * scale;
                    }
                }
                let folds = find_folds(&trial)?;
                if !folds.is_empty() {
                    for f in folds.iter().flat_map(|f| &f.faces) {
                        for &v in &trial.faces[*f] {
                            frozen[v as usize] = true;
                        }
                    }
                    continue;
                }
                let fitted = fit_mesh(&trial, target, settings, self.fitted.colours.clone())?;
                let error = psnr_sum(&pixel_errors(&fitted, target, image, trial.colour_space));
                if error < self.error {
                    *self = Fit {
                        mesh: trial,
                        fitted,
                        error,
                    };
                    return Ok(true);
                }
                break;
            }
        }
        Ok(false)
    }
}

impl Fit {
    /// Moves the points of the outline (away from the picture's sides) so that its limit curve
    /// runs along the silhouette's edge, then solves the colours again. Each boundary point's
    /// limit lies at `(previous + 4 point + next) / 6` (the outline's points follow the cubic
    /// B-spline rule); [`SNAP_ITERATIONS`] times over, each point moves by half of what would
    /// put that limit on the nearest point of the edge within half its shortest edge. The
    /// points of faces the moves fold stay where they were.
    fn snap_outline(
        &mut self,
        silhouette: &Silhouette,
        target: &Target,
        image: &RgbaImage,
        settings: &FitSettings,
    ) -> Result<(), Error> {
        let (w, h) = (target.width as f64, target.height as f64);
        let edges = outline_edges(&self.mesh, w, h);
        let previous: HashMap<u32, u32> = edges.iter().map(|&(a, b)| (b, a)).collect();
        let reach = shortest_edges(&self.mesh);
        let mut trial = self.mesh.clone();
        for _ in 0..SNAP_ITERATIONS {
            let at: Vec<kurbo::Point> = trial.points.iter().map(|p| p.position).collect();
            for &(v, next) in &edges {
                let (i, p) = (v as usize, at[v as usize]);
                let Some(&before) = previous.get(&v) else {
                    continue;
                };
                if trial.points[i].corner || p.x == 0.0 || p.x == w || p.y == 0.0 || p.y == h {
                    continue;
                }
                let limit = ((at[before as usize].to_vec2()
                    + 4.0 * p.to_vec2()
                    + at[next as usize].to_vec2())
                    / 6.0)
                    .to_point();
                if let Some(edge) = silhouette.nearest_edge(limit, (0.5 * reach[i]).max(2.0)) {
                    trial.points[i].position += (edge - limit) * 0.75;
                }
            }
        }
        let folds = find_folds(&trial)?;
        for f in folds.iter().flat_map(|f| &f.faces) {
            for &v in &trial.faces[*f] {
                trial.points[v as usize].position = self.mesh.points[v as usize].position;
            }
        }
        if !folds.is_empty() && !find_folds(&trial)?.is_empty() {
            return Ok(());
        }
        let fitted = fit_mesh(&trial, target, settings, self.fitted.colours.clone())?;
        let error = psnr_sum(&pixel_errors(&fitted, target, image, trial.colour_space));
        *self = Fit {
            mesh: trial,
            fitted,
            error,
        };
        Ok(())
    }
}

/// How often [`Fit::snap_outline`] moves the outline's points towards the silhouette's edge.
const SNAP_ITERATIONS: usize = 6;

/// The most rounds of position steps for a mesh of `points` points: `quality`'s for 1024
/// points or more, and for fewer up to three times as many, in proportion to `1024 / points`.
/// Small meshes gain most from moved points (each point carries a large part of the picture)
/// and their rounds stop early where no step pays; at the default budget of 1024 points four
/// rounds are what the time target leaves room for.
fn position_rounds(quality: Quality, points: usize) -> usize {
    let scale = (1024.0 / points.max(1) as f64).clamp(1.0, 3.0);
    (quality.position_rounds() as f64 * scale).round() as usize
}

/// How often [`Fit::move_points`] freezes the points of folded faces and tries again.
const FOLD_RETRIES: usize = 3;

/// Shortens each step to at most a quarter of its point's shortest edge, keeps points on
/// the sides of the `width` x `height` picture on them (its corners where they are), and
/// points of the outline elsewhere (a silhouette's) where they are: the colour error cannot
/// tell where the outline should go ([`Fit::snap_outline`] moves them).
fn limit_steps(mesh: &GradientMesh, steps: &mut [[f64; 2]], width: f64, height: f64) {
    let reach = shortest_edges(mesh);
    let on_outline = outline_points(mesh, width, height);
    for (((step, p), reach), outline) in steps
        .iter_mut()
        .zip(&mesh.points)
        .zip(reach)
        .zip(on_outline)
    {
        if outline {
            *step = [0.0; 2];
            continue;
        }
        let length = step[0].hypot(step[1]);
        let limit = 0.25 * reach;
        if length > limit {
            *step = step.map(|d| d * limit / length);
        }
        let q = p.position;
        if q.x <= 1e-9 || q.x >= width - 1e-9 {
            step[0] = 0.0;
        }
        if q.y <= 1e-9 || q.y >= height - 1e-9 {
            step[1] = 0.0;
        }
    }
}

/// Per point, whether it lies on the mesh's outline away from the picture's sides.
fn outline_points(mesh: &GradientMesh, width: f64, height: f64) -> Vec<bool> {
    let mut on = vec![false; mesh.points.len()];
    for (a, b) in outline_edges(mesh, width, height) {
        on[a as usize] = true;
        on[b as usize] = true;
    }
    on
}

/// The edges of the mesh's outline, each from a point to the next along its loop, except
/// those along the sides of the `width` x `height` picture (which stay where they are): the
/// directed edges of faces whose reverse no face has.
fn outline_edges(mesh: &GradientMesh, width: f64, height: f64) -> Vec<(u32, u32)> {
    let mut directed = HashSet::new();
    for f in &mesh.faces {
        for (i, &a) in f.iter().enumerate() {
            directed.insert((a, f[(i + 1) % f.len()]));
        }
    }
    let on_side = |a: u32, b: u32| {
        let (p, q) = (
            mesh.points[a as usize].position,
            mesh.points[b as usize].position,
        );
        (p.x == q.x && (p.x == 0.0 || p.x == width))
            || (p.y == q.y && (p.y == 0.0 || p.y == height))
    };
    let mut edges: Vec<(u32, u32)> = directed
        .iter()
        .filter(|&&(a, b)| !directed.contains(&(b, a)) && !on_side(a, b))
        .copied()
        .collect();
    edges.sort_unstable();
    edges
}

/// Per point, the length of its shortest edge.
fn shortest_edges(mesh: &GradientMesh) -> Vec<f64> {
    let mut reach = vec![f64::INFINITY; mesh.points.len()];
    for [a, b] in mesh_edges(mesh) {
        let (a, b) = (a as usize, b as usize);
        let d = mesh.points[a].position.distance(mesh.points[b].position);
        reach[a] = reach[a].min(d);
        reach[b] = reach[b].min(d);
    }
    reach
}

/// The picture's colour at the pixel under `p`.
fn target_colour_at(target: &Target, p: kurbo::Point) -> [f64; 3] {
    let x = (p.x.floor().max(0.0) as usize).min(target.width - 1);
    let y = (p.y.floor().max(0.0) as usize).min(target.height - 1);
    target.colour[y * target.width + x]
}

/// Per leaf of `tree`, the summed squared error of the pixels of the face it is
/// (`leaf_of_face`), and with a silhouette what its pixels on the wrong side of the outline
/// cost ([`Silhouette::miscovered_error`]).
fn leaf_errors(
    tree: &Quadtree,
    fitted: &Fitted,
    errors: &[Option<f64>],
    leaf_of_face: &[usize],
    silhouette: Option<&Silhouette>,
) -> Vec<f64> {
    let mut leaf_error = vec![0.0; tree.leaves.len()];
    for (i, e) in errors.iter().enumerate() {
        let f = fitted.observation.base_face[i];
        if let (Some(e), true) = (e, f != raster::UNCOVERED) {
            leaf_error[leaf_of_face[f as usize]] += e;
        }
    }
    if let Some(s) = silhouette {
        for (error, leaf) in leaf_error.iter_mut().zip(&tree.leaves) {
            *error += s.miscovered_error(tree, leaf);
        }
    }
    leaf_error
}

/// The leaves to split next: largest error (`leaf_error`) first, adding at most `(growth - 1)`
/// times the points there are and never going past `budget`.
fn choose_splits(
    tree: &Quadtree,
    leaf_error: &[f64],
    budget: usize,
    growth: f64,
    min_px: f64,
) -> Vec<usize> {
    let mut order: Vec<usize> = (0..tree.leaves.len())
        .filter(|&i| tree.can_split(&tree.leaves[i], min_px) && leaf_error[i] > 0.0)
        .collect();
    order.sort_by(|&a, &b| leaf_error[b].total_cmp(&leaf_error[a]));
    let mut present = tree.corner_keys();
    let points = present.len();
    let room = budget.saturating_sub(points);
    let allowance = room.min(((growth - 1.0) * points as f64).ceil().max(5.0) as usize);
    let mut added = 0;
    let mut chosen = Vec::new();
    for i in order {
        let new = Quadtree::new_points(&tree.leaves[i], &present);
        if added + new.len() > allowance {
            continue;
        }
        added += new.len();
        present.extend(new);
        chosen.push(i);
        if added == allowance {
            break;
        }
    }
    chosen
}

/// Rounds `v` to `decimals` decimals, so that it is written in that many digits (the nearest
/// double to a decimal fraction prints as that fraction) and never as `-0`.
fn round_to_decimals(v: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (v * scale).round() / scale + 0.0
}

/// The decimals a colour of `space` keeps when rounded coarsely: a hundredth of its lightness
/// range (whole units in Lab); one more otherwise.
fn colour_decimals(space: ColourSpace, coarse: bool) -> i32 {
    let decimals = match space {
        ColourSpace::Lab => 0,
        ColourSpace::Oklab | ColourSpace::SrgbLinear | ColourSpace::Srgb => 2,
    };
    decimals + i32::from(!coarse)
}

/// Below this PSNR (dB) of the fit the output is rounded coarsely (half pixels, whole Lab
/// units), which costs a photograph's fit a few hundredths of a dB; above it the fit is close
/// enough for that rounding to show (0.55 dB at 41 dB on a smooth picture), and positions and
/// colours keep tenths.
const COARSE_ROUNDING_DB: f64 = 32.0;

/// The step coarse output positions are rounded to, in pixels (a power of two, so exact in
/// binary).
const POSITION_STEP: f64 = 0.5;

/// How finely an output position is written, coarsest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Precision {
    /// To [`POSITION_STEP`].
    Step,
    /// To a tenth of a pixel.
    Tenth,
    /// As fitted.
    Exact,
}

impl Precision {
    fn finer(self) -> Precision {
        match self {
            Precision::Step => Precision::Tenth,
            Precision::Tenth | Precision::Exact => Precision::Exact,
        }
    }

    fn round(self, p: kurbo::Point) -> kurbo::Point {
        let step = |v: f64| (v / POSITION_STEP).round() * POSITION_STEP + 0.0;
        match self {
            Precision::Step => kurbo::Point::new(step(p.x), step(p.y)),
            Precision::Tenth => {
                kurbo::Point::new(round_to_decimals(p.x, 1), round_to_decimals(p.y, 1))
            }
            Precision::Exact => p,
        }
    }
}

/// Rounds the positions and colours of `mesh` for output, what
/// [`VectoriseOptions::round_output`] asks for: if `coarse`, positions to [`POSITION_STEP`]
/// and colours to [`colour_decimals`], else both to tenths. Points whose rounded positions
/// meet, and the points of faces that rounding folds, are written finer (to a tenth of a
/// pixel, then as fitted; then the points of the faces around them) until none meet and no
/// fold remains that the fitted positions lack.
fn round_for_output(mesh: &mut GradientMesh, coarse: bool) -> Result<(), Error> {
    let decimals = colour_decimals(mesh.colour_space, coarse);
    for p in &mut mesh.points {
        p.colour = p.colour.map(|c| round_to_decimals(c, decimals));
    }
    let fitted: Vec<kurbo::Point> = mesh.points.iter().map(|p| p.position).collect();
    let start = if coarse {
        Precision::Step
    } else {
        Precision::Tenth
    };
    let mut precision = vec![start; fitted.len()];
    loop {
        place_rounded(mesh, &fitted, &mut precision);
        let folds = find_folds(mesh)?;
        let folded = points_of_faces(mesh, |f| folds.iter().any(|x| x.faces.contains(&f)));
        if refine_where(&mut precision, &folded) {
            continue;
        }
        // The folded faces' points are as fitted: the rounding of their neighbours folds them.
        let around = points_of_faces(mesh, |f| mesh.faces[f].iter().any(|&v| folded[v as usize]));
        if !refine_where(&mut precision, &around) {
            return Ok(());
        }
    }
}

/// Per point of `mesh`, whether a face for which `chosen` holds has it.
fn points_of_faces(mesh: &GradientMesh, chosen: impl Fn(usize) -> bool) -> Vec<bool> {
    let mut marked = vec![false; mesh.points.len()];
    for (_, face) in mesh.faces.iter().enumerate().filter(|&(f, _)| chosen(f)) {
        for &v in face {
            marked[v as usize] = true;
        }
    }
    marked
}

/// Makes the precision of the points marked in `which` finer; returns whether one could be.
fn refine_where(precision: &mut [Precision], which: &[bool]) -> bool {
    let mut refined = false;
    for (q, _) in precision.iter_mut().zip(which).filter(|(_, &w)| w) {
        refined |= *q != Precision::Exact;
        *q = q.finer();
    }
    refined
}

/// Puts the points of `mesh` at their `fitted` positions rounded to their `precision`, made
/// finer where two would meet.
fn place_rounded(mesh: &mut GradientMesh, fitted: &[kurbo::Point], precision: &mut [Precision]) {
    let key = |p: kurbo::Point| ((p.x + 0.0).to_bits(), (p.y + 0.0).to_bits());
    loop {
        let at: Vec<kurbo::Point> = fitted
            .iter()
            .zip(precision.iter())
            .map(|(&p, q)| q.round(p))
            .collect();
        let mut uses: HashMap<(u64, u64), usize> = HashMap::new();
        for &p in &at {
            *uses.entry(key(p)).or_default() += 1;
        }
        let meet: Vec<bool> = at.iter().map(|&p| uses[&key(p)] > 1).collect();
        if !refine_where(precision, &meet) {
            for (point, p) in mesh.points.iter_mut().zip(at) {
                point.position = p;
            }
            return;
        }
    }
}

/// The document of `mesh`, rendered at the picture's size to measure its PSNR. A mesh of a
/// silhouette (`framed`) does not span the picture: the document keeps the picture's rectangle
/// as its view.
fn finish(
    mesh: GradientMesh,
    image: &RgbaImage,
    rounds: usize,
    framed: bool,
) -> Result<Vectorised, Error> {
    let points = mesh.points.len();
    let (w, h) = (image.width as f64, image.height as f64);
    let document = Document {
        layers: vec![mesh],
        view: framed.then(|| kurbo::Rect::new(0.0, 0.0, w, h)),
    };
    let view = View::new(0.0, 0.0, image.width as f64, image.height as f64);
    let opts = RenderOptions::new(image.width, image.height, view);
    let mut out = vec![0u8; 4 * image.width as usize * image.height as usize];
    render_document_into(&document, &opts, &mut out)?;
    let rendered = RgbaImage::from_rgba8(image.width, image.height, &out)?;
    Ok(Vectorised {
        psnr: psnr(image, &rendered)?,
        document,
        points,
        rounds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quadtree mesh over a 60 x 40 picture with one cell split (so one face is a pentagon
    /// and one point has valence three), coloured by `colour(i)`.
    fn tree_mesh(colour: impl Fn(usize) -> [f64; 3]) -> GradientMesh {
        let mut tree = Quadtree::new(60.0, 40.0, 3, 2);
        tree.split(&[1]);
        let shape = tree.mesh();
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for (i, p) in shape.positions.iter().enumerate() {
            mesh.add_point(*p, colour(i));
        }
        for f in shape.faces {
            mesh.add_face(f);
        }
        mesh
    }

    /// Output rounding: positions to half a pixel and Lab colours to whole units, except two
    /// points whose half-pixel positions would meet, which keep their tenths.
    #[test]
    fn rounding_keeps_points_apart() {
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for (x, y) in [(0.0, 0.0), (10.3, 0.0), (20.2, 0.0)] {
            mesh.add_point(kurbo::Point::new(x, y), [50.44, -3.5, 12.61]);
        }
        for (x, y) in [(0.0, 20.0), (10.64, 0.23), (20.2, 19.7)] {
            mesh.add_point(kurbo::Point::new(x, y), [49.5, 0.2, -7.8]);
        }
        mesh.add_face(vec![0, 1, 4, 3]);
        mesh.add_face(vec![1, 2, 5, 4]);
        round_for_output(&mut mesh, true).unwrap();
        let at: Vec<(f64, f64)> = mesh
            .points
            .iter()
            .map(|p| (p.position.x, p.position.y))
            .collect();
        assert_eq!(
            at,
            [
                (0.0, 0.0),
                (10.3, 0.0),
                (20.0, 0.0),
                (0.0, 20.0),
                (10.6, 0.2),
                (20.0, 19.5)
            ]
        );
        assert_eq!(mesh.points[0].colour, [50.0, -4.0, 13.0]);
        assert_eq!(mesh.points[5].colour, [50.0, 0.0, -8.0]);
    }

    /// The starting grid of each budget has between an eighth and a half of it in points, and
    /// its cells halve down to cells within a quarter of the 3 px floor: with cells of 11.4 px (a
    /// 512 x 600 picture, 45 x 52 cells at budget 9737) they stopped at 5.7 px.
    #[test]
    fn starting_cells_halve_down_to_the_floor() {
        let min_px = 3.0;
        for (w, h, budget) in [
            (512.0, 600.0, 8000),
            (512.0, 600.0, 8800),
            (512.0, 600.0, 9737),
            (512.0, 600.0, 12000),
            (600.0, 400.0, 256),
            (600.0, 400.0, 6800),
            (512.0, 512.0, 1024),
            (640.0, 427.0, 5230),
        ] {
            let (cols, rows) = initial_grid(w, h, budget / 4, min_px);
            let context = format!("{w} x {h} at {budget}: {cols} x {rows} cells");
            let mut tree = Quadtree::new(w, h, cols, rows);
            while tree.can_split(&tree.leaves[0], min_px) {
                tree.split(&[0]);
            }
            let smallest = tree.side_px(&tree.leaves[0]);
            assert!(
                smallest >= min_px && smallest < 1.25 * min_px,
                "{context}: {smallest} px"
            );
            let points = (cols + 1) * (rows + 1);
            assert!(2 * points <= budget as u32, "{context}");
            assert!(8 * points >= budget as u32, "{context}");
        }
    }

    /// A 2 x 2 grid of squares of side `cell` whose middle point is moved to `(x, x)`: towards
    /// the first corner, past the diagonal of the first square, which then folds.
    fn grid_moved(cell: f64, x: f64) -> GradientMesh {
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for j in 0..3 {
            for i in 0..3 {
                let p = kurbo::Point::new(cell * i as f64, cell * j as f64);
                let p = if (i, j) == (1, 1) {
                    kurbo::Point::new(x, x)
                } else {
                    p
                };
                mesh.add_point(p, [50.0, 0.0, 0.0]);
            }
        }
        for a in [0, 1, 3, 4] {
            mesh.add_face(vec![a, a + 1, a + 4, a + 3]);
        }
        mesh
    }

    /// Where between `cell` and a fifth of it the middle point of [`grid_moved`] starts to fold
    /// the surface: the last fold-free position found by bisection.
    fn fold_threshold(cell: f64) -> f64 {
        let folds = |x: f64| !find_folds(&grid_moved(cell, x)).unwrap().is_empty();
        let (mut free, mut folded) = (cell, 0.2 * cell);
        assert!(!folds(free) && folds(folded));
        for _ in 0..50 {
            let mid = 0.5 * (free + folded);
            if folds(mid) {
                folded = mid;
            } else {
                free = mid;
            }
        }
        free
    }

    /// Output rounding folds nothing the fitted positions do not: a point just short of
    /// folding the surface, where its tenths of a pixel fold it, keeps its fitted position.
    #[test]
    fn rounding_folds_nothing() {
        // A cell size whose fold threshold rounds (to tenths) down, into the fold.
        let (cell, x) = (6..40)
            .map(|k| 0.5 * k as f64)
            .map(|cell| (cell, fold_threshold(cell)))
            .find(|&(_, x)| round_to_decimals(x, 1) < x)
            .expect("a threshold that rounds down");
        let tenths = grid_moved(cell, round_to_decimals(x, 1));
        assert!(!find_folds(&tenths).unwrap().is_empty(), "{cell} px: {x}");
        let mut mesh = grid_moved(cell, x);
        round_for_output(&mut mesh, false).unwrap();
        assert!(find_folds(&mesh).unwrap().is_empty(), "{cell} px: {x}");
        assert_eq!(mesh.points[4].position, kurbo::Point::new(x, x));
        assert_eq!(
            mesh.points[8].position,
            kurbo::Point::new(2.0 * cell, 2.0 * cell)
        );
        let mut mesh = grid_moved(cell, x);
        round_for_output(&mut mesh, true).unwrap();
        assert!(find_folds(&mesh).unwrap().is_empty(), "{cell} px: {x}");
    }

    /// Meshes below 1024 points get more rounds of position steps, up to three times as many.
    #[test]
    fn small_meshes_get_more_position_rounds() {
        assert_eq!(position_rounds(Quality::Default, 256), 12);
        assert_eq!(position_rounds(Quality::Default, 64), 12);
        assert_eq!(position_rounds(Quality::Default, 512), 8);
        assert_eq!(position_rounds(Quality::Default, 1024), 4);
        assert_eq!(position_rounds(Quality::Default, 4096), 4);
        assert_eq!(position_rounds(Quality::Fast, 256), 6);
        assert_eq!(position_rounds(Quality::Best, 2048), 8);
    }

    /// With the same topology and geometry, the least-squares step recovers the control colours
    /// of a picture made by the fit's own sampling of the limit surface to 1e-6.
    #[test]
    fn least_squares_recovers_known_colours() {
        let known = |i: usize| {
            let t = i as f64;
            [
                30.0 + 5.0 * (t * 0.7).sin() + t,
                20.0 * (t * 1.3).cos(),
                3.0 * t - 20.0,
            ]
        };
        let mesh = tree_mesh(known);
        assert!(mesh.faces.iter().any(|f| f.len() == 5));
        let blank = Target {
            width: 60,
            height: 40,
            colour: vec![[0.0; 3]; 2400],
            weight: vec![1.0; 2400],
        };
        let settings = FitSettings {
            faces_per_pixel: 0.6,
            smoothness: 0.0,
            tolerance: 1e-13,
            max_iterations: 5000,
            ridge: 0.0,
        };
        let truth: Vec<[f64; 3]> = mesh.points.iter().map(|p| p.colour).collect();
        // The picture: what the fit's sampling shows of the true colours (no solver step).
        let sample_only = FitSettings {
            max_iterations: 0,
            ..settings
        };
        let seen = fit_mesh(&mesh, &blank, &sample_only, truth.clone()).unwrap();
        let mut target = blank.clone();
        for i in 0..2400 {
            let c = seen.observation.predict(&seen.vertex_colours, i);
            target.colour[i] = c.expect("the mesh covers the picture");
        }
        let guess = vec![[50.0, 0.0, 0.0]; truth.len()];
        let settings = FitSettings {
            max_iterations: 5000,
            ..sample_only
        };
        let fitted = fit_mesh(&mesh, &target, &settings, guess).unwrap();
        for (got, want) in fitted.colours.iter().zip(&truth) {
            for k in 0..3 {
                assert!((got[k] - want[k]).abs() < 1e-6, "{got:?} vs {want:?}");
            }
        }
    }
}
