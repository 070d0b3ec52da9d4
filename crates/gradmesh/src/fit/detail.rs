//! Refined-level colour edits (the paper's section 5) as unknowns of the colour fit.
//!
//! A relative colour edit of a vertex of level `k` adds its offset to the colour subdivision
//! gives the vertex, and the next step gives the vertex's whole ring (its vertex point and the
//! edge and face points around it) that colour, shared ring points the mean of their edited
//! vertices ([`crate::edits`]). Both are linear in the control colours and the offsets
//! together, so the offsets join the control colours as columns of the limit-colour rows.

use std::collections::{BTreeMap, HashMap, HashSet};

use crate::catmull_clark::Stencils;
use crate::edits::Resolver;
use crate::error::Error;
use crate::mesh::GradientMesh;
use crate::multires::{ColourEdit, Edit, VertexAddress};
use crate::refine::Refinement;
use crate::size_limits::Limits;

use super::image::Target;
use super::rows::{level_1_rows, SparseRows};
use super::{
    check_fittable, fit_refined, invalid, pixel_errors, psnr_of_covered, sampling_level,
    FitSettings, Fitted, Quality, RgbaImage,
};

/// Colour edits of one level, each an unknown offset: edit `i` is column `points + i`.
#[derive(Clone, Debug, Default)]
pub(crate) struct DetailEdits {
    /// The level of every edit (at least 2).
    pub level: usize,
    /// The edited vertices, as the level numbers them.
    pub vertices: Vec<u32>,
    /// Their names, for the mesh's edits.
    pub addresses: Vec<VertexAddress>,
}

impl DetailEdits {
    /// Edits of every vertex of level `level` in `faces` (base faces), each vertex once.
    pub fn on_faces(refinement: &Refinement, level: usize, faces: &[usize]) -> DetailEdits {
        let base = refinement.topology(0);
        let levels: Vec<_> = (1..=level).map(|k| refinement.topology(k)).collect();
        let m = VertexAddress::sector_size(level as u32);
        let mut seen = HashSet::new();
        let mut out = DetailEdits {
            level,
            ..DetailEdits::default()
        };
        for &face in faces {
            let corners = base.face_vertices(face);
            for corner in 0..corners.len() {
                let point = refinement.base().source_point[corners[corner] as usize];
                let mut resolver = Resolver::new(base, levels.clone(), face, corner);
                for i in 0..=m {
                    for j in 0..=m {
                        let Some(v) = resolver.vertex(level, i, j) else {
                            continue;
                        };
                        if seen.insert(v) {
                            out.vertices.push(v);
                            let address =
                                VertexAddress::new(level as u32, face as u32, point, [i, j]);
                            out.addresses.push(address);
                        }
                    }
                }
            }
        }
        out
    }

    /// The number of edits.
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// [`super::rows::limit_colour_rows`] with these edits: a column for each edit's offset
    /// after the control points' (the edit level must lie below `depth`).
    pub fn limit_colour_rows(
        &self,
        refinement: &Refinement,
        depth: usize,
        limit: &Stencils,
        points: usize,
    ) -> SparseRows {
        let mut rows = level_1_rows(refinement, points, points + self.len());
        for k in 1..depth {
            if k == self.level {
                let edited = self.add_offsets(&rows, points);
                let next = edited.compose(refinement.stencils(k));
                rows = self.flatten_rings(refinement, &edited, &next);
            } else {
                rows = rows.compose(refinement.stencils(k));
            }
        }
        rows.compose(limit)
    }

    /// The rows of the edit level with each edited vertex's offset column added (columns of
    /// the offsets follow the `points` control points).
    pub fn add_offsets(&self, rows: &SparseRows, points: usize) -> SparseRows {
        let column: HashMap<u32, u32> = self
            .vertices
            .iter()
            .enumerate()
            .map(|(i, &v)| (v, (points + i) as u32))
            .collect();
        rows.map_rows(|i, cols, vals| {
            let &c = column.get(&(i as u32))?;
            let mut row: Vec<(u32, f64)> = cols.iter().copied().zip(vals.iter().copied()).collect();
            row.push((c, 1.0));
            Some(row)
        })
    }

    /// The rows of the level after the edit level, its edited vertices' rings given the mean
    /// of the edited rows (`edited`, of the edit level) that reach them.
    pub fn flatten_rings(
        &self,
        refinement: &Refinement,
        edited: &SparseRows,
        next: &SparseRows,
    ) -> SparseRows {
        let t = refinement.topology(self.level);
        let (faces, edges) = (t.face_count() as u32, t.edge_count() as u32);
        let mut sums: HashMap<u32, (BTreeMap<u32, f64>, u32)> = HashMap::new();
        for &v in &self.vertices {
            let ring = std::iter::once(faces + edges + v)
                .chain(t.vertex_edges(v as usize).iter().map(|&e| faces + e))
                .chain(t.vertex_faces(v as usize).iter().copied());
            let (cols, vals) = edited.row(v as usize);
            for p in ring {
                let entry = sums.entry(p).or_default();
                for (&c, &w) in cols.iter().zip(vals) {
                    *entry.0.entry(c).or_insert(0.0) += w;
                }
                entry.1 += 1;
            }
        }
        next.map_rows(|i, _, _| {
            let (sum, count) = sums.get(&(i as u32))?;
            Some(sum.iter().map(|(&c, &w)| (c, w / *count as f64)).collect())
        })
    }
}

/// Where [`fit_colours_with_detail`] adds refined-level colour edits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetailOptions {
    /// The level of the edits, 2 to 4: a face of `n` corners gets about `n (3 * 2^(level -
    /// 2))^2` of them.
    pub level: u32,
    /// Faces whose root-mean-square colour error after the control colours' fit exceeds this
    /// (in the mesh's colour space, per channel) get edits on every vertex of that level.
    pub threshold: f64,
    /// The weight of the offsets' squares, relative to the average weight a control point
    /// gets from its pixels: small, so that the control colours carry what they can.
    pub ridge: f64,
}

impl Default for DetailOptions {
    fn default() -> Self {
        DetailOptions {
            level: 3,
            threshold: 0.3,
            ridge: 1e-4,
        }
    }
}

/// What [`fit_colours_with_detail`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetailFit {
    /// PSNR (dB) of the fitted surface as the fit samples it (over the pixels it covers).
    pub psnr: f64,
    /// Faces that took edits.
    pub faces: usize,
    /// Edits added.
    pub edits: usize,
}

/// [`fit_colours`](super::fit_colours), then, on the faces the control colours cannot follow,
/// relative colour edits of refined vertices fitted together with the control colours by the
/// same least squares (see [`DetailOptions`]). The edits are added to the mesh's.
pub fn fit_colours_with_detail(
    mesh: &mut GradientMesh,
    image: &RgbaImage,
    quality: Quality,
    options: &DetailOptions,
) -> Result<DetailFit, Error> {
    check_fittable(mesh)?;
    if !(2..=4).contains(&options.level) {
        return Err(invalid(
            "detail level",
            format!("{}: 2 to 4", options.level),
        ));
    }
    let level = options.level as usize;
    let target = Target::new(image, mesh.colour_space);
    let settings = FitSettings {
        faces_per_pixel: quality.faces_per_pixel(),
        smoothness: 0.0,
        tolerance: 1e-10,
        max_iterations: 20 * quality.max_iterations(),
        ridge: options.ridge,
    };
    let pixels = target.width * target.height;
    let depth = sampling_level(mesh, pixels, settings.faces_per_pixel).max(level + 1);
    let (refinement, _) = Refinement::new_with_limits(mesh, depth, &Limits::DEFAULT)?;
    let guess = mesh.points.iter().map(|p| p.colour).collect();
    let mut fitted = fit_refined(mesh, &refinement, &target, &settings, guess, None)?;
    let faces = faces_beyond(&fitted, &target, mesh.faces.len(), options.threshold);
    let detail = DetailEdits::on_faces(&refinement, level, &faces);
    if detail.len() > 0 {
        let mut guess = fitted.colours.clone();
        guess.resize(mesh.points.len() + detail.len(), [0.0; 3]);
        fitted = fit_refined(mesh, &refinement, &target, &settings, guess, Some(&detail))?;
    }
    let (colours, offsets) = fitted.colours.split_at(mesh.points.len());
    for (p, c) in mesh.points.iter_mut().zip(colours) {
        p.colour = *c;
        p.colour_text = None;
    }
    for (address, offset) in detail.addresses.iter().zip(offsets) {
        let mut edit = Edit::new(*address);
        edit.colour = Some(ColourEdit::Offset(*offset));
        mesh.edits.push(edit);
    }
    let errors = pixel_errors(&fitted, &target, image, mesh.colour_space);
    Ok(DetailFit {
        psnr: psnr_of_covered(&errors),
        faces: faces.len(),
        edits: detail.len(),
    })
}

/// The base faces whose pixels' root-mean-square colour error (per channel, alpha-weighted)
/// exceeds `threshold`.
fn faces_beyond(fitted: &Fitted, target: &Target, faces: usize, threshold: f64) -> Vec<usize> {
    let mut sums = vec![(0.0, 0.0); faces];
    for (i, &face) in fitted.observation.base_face.iter().enumerate() {
        let w = target.weight[i];
        let Some(c) = fitted.observation.predict(&fitted.vertex_colours, i) else {
            continue;
        };
        if w > 0.0 && (face as usize) < faces {
            let e: f64 = (0..3).map(|k| (c[k] - target.colour[i][k]).powi(2)).sum();
            sums[face as usize].0 += w * e;
            sums[face as usize].1 += 3.0 * w;
        }
    }
    (0..faces)
        .filter(|&f| sums[f].1 > 0.0 && (sums[f].0 / sums[f].1).sqrt() > threshold)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::ColourSpace;
    use crate::limit_surface::limit_stencils;
    use kurbo::{Point, Vec2};

    /// A quad, a triangle and a pentagon with a turned handle.
    fn mesh() -> GradientMesh {
        let mut m = GradientMesh::new(ColourSpace::Lab);
        let pts = [
            (0.0, 0.0),
            (10.0, 0.0),
            (20.0, 0.0),
            (0.0, 10.0),
            (10.0, 10.0),
        ];
        for (i, &(x, y)) in pts.iter().enumerate() {
            let i = i as f64;
            m.add_point(Point::new(x, y), [40.0 + 3.0 * i, 10.0 - 2.0 * i, i * i]);
        }
        m.add_point(Point::new(22.0, 12.0), [60.0, 5.0, -5.0]);
        m.add_point(Point::new(15.0, 18.0), [55.0, -8.0, 12.0]);
        m.add_face(vec![0, 1, 4, 3]);
        m.add_face(vec![1, 2, 5, 6, 4]);
        m.set_handle(4, 6, Vec2::new(2.0, 3.0));
        m
    }

    /// With the edits' offsets as columns, the rows give the limit colours the refinement
    /// computes with those edits applied, for edits at levels 2 and 3 on one of two faces.
    #[test]
    fn rows_with_edits_reproduce_the_edited_limit_colours() {
        let plain = mesh();
        for level in [2, 3] {
            let depth = level + 2;
            let (refinement, _) = Refinement::new(&plain, depth).unwrap();
            let detail = DetailEdits::on_faces(&refinement, level, &[1]);
            assert!(detail.len() > 20);
            let offsets: Vec<[f64; 3]> = (0..detail.len())
                .map(|i| {
                    let t = i as f64;
                    [(t * 0.7).sin() * 5.0, (t * 1.1).cos() * 4.0, t * 0.01]
                })
                .collect();
            let mut edited = plain.clone();
            for (a, o) in detail.addresses.iter().zip(&offsets) {
                let mut e = Edit::new(*a);
                e.colour = Some(ColourEdit::Offset(*o));
                edited.edits.push(e);
            }
            let (truth, _) = Refinement::new(&edited, depth).unwrap();
            let data = truth.evaluate();
            let limit = limit_stencils(truth.level(depth)).unwrap();
            let expected = limit.apply(&data.levels[depth]);
            let rows = detail.limit_colour_rows(&refinement, depth, &limit, plain.points.len());
            let mut unknowns: Vec<[f64; 3]> = plain.points.iter().map(|p| p.colour).collect();
            unknowns.extend(&offsets);
            let got = rows.apply(&unknowns);
            assert_eq!(got.len(), expected.len());
            for (g, e) in got.iter().zip(&expected) {
                for k in 0..3 {
                    assert!(
                        (g[k] - e.to_array()[2 + k]).abs() < 1e-9,
                        "level {level}: {g:?} vs {e:?}"
                    );
                }
            }
        }
    }
}
