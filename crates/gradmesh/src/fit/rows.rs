//! The limit colour of every vertex of a refined level as a sparse combination of the control
//! colours.
//!
//! With topology and tags fixed the whole refinement is linear in the colours: the ternary
//! step copies each control colour to the level-1 points around it, every Catmull-Clark step
//! and the limit stencils are fixed weights. Composing those stencils gives, for each vertex of
//! level `L`, weights over the control points that do not depend on positions or handles.

use rayon::prelude::*;

use crate::catmull_clark::Stencils;
use crate::refine::Refinement;
use crate::ternary_step;
use crate::topology::Topology;

/// Sparse rows over `columns` unknowns: row `i` is `vals[k]` at `cols[k]` for `k` in
/// `offsets[i]..offsets[i + 1]`, columns increasing.
#[derive(Clone, Debug, Default)]
pub(crate) struct SparseRows {
    offsets: Vec<u32>,
    cols: Vec<u32>,
    vals: Vec<f64>,
    columns: usize,
}

/// Rows built per chunk in parallel, then concatenated in order.
const CHUNK: usize = 1 << 12;

impl SparseRows {
    /// One entry of weight 1 per row: row `i` is column `columns_of[i]`.
    pub fn selection(columns_of: Vec<u32>, columns: usize) -> SparseRows {
        SparseRows {
            offsets: (0..=columns_of.len() as u32).collect(),
            vals: vec![1.0; columns_of.len()],
            cols: columns_of,
            columns,
        }
    }

    /// These rows with `columns` unknowns in all (at least as many as now).
    pub fn widened(mut self, columns: usize) -> SparseRows {
        self.columns = self.columns.max(columns);
        self
    }

    /// The rows with row `i` replaced by `replace(i, cols, vals)` where that gives one (its
    /// entries' columns increasing).
    pub fn map_rows(
        &self,
        replace: impl Fn(usize, &[u32], &[f64]) -> Option<Vec<(u32, f64)>>,
    ) -> SparseRows {
        let mut out = SparseRows {
            offsets: vec![0],
            columns: self.columns,
            ..SparseRows::default()
        };
        for i in 0..self.len() {
            let (cols, vals) = self.row(i);
            match replace(i, cols, vals) {
                Some(row) => {
                    for (c, v) in row {
                        out.cols.push(c);
                        out.vals.push(v);
                    }
                }
                None => {
                    out.cols.extend_from_slice(cols);
                    out.vals.extend_from_slice(vals);
                }
            }
            out.offsets.push(out.cols.len() as u32);
        }
        out
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The columns and weights of row `i`.
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let (s, e) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
        (&self.cols[s..e], &self.vals[s..e])
    }

    /// The rows `stencils` make of these: row `i` is the sum of `w * self.row(s)` over the
    /// terms `(s, w)` of stencil `i`.
    pub fn compose(&self, stencils: &Stencils) -> SparseRows {
        let n = stencils.len();
        let parts: Vec<SparseRows> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|k| self.compose_range(stencils, k * CHUNK..((k + 1) * CHUNK).min(n)))
            .collect();
        let mut out = SparseRows {
            offsets: vec![0],
            columns: self.columns,
            ..SparseRows::default()
        };
        for part in parts {
            let base = *out.offsets.last().expect("offsets start with 0");
            out.offsets
                .extend(part.offsets[1..].iter().map(|&o| o + base));
            out.cols.extend(part.cols);
            out.vals.extend(part.vals);
        }
        out
    }

    fn compose_range(&self, stencils: &Stencils, range: std::ops::Range<usize>) -> SparseRows {
        let mut acc = vec![0.0; self.columns];
        let mut seen = vec![false; self.columns];
        let mut touched: Vec<u32> = Vec::with_capacity(64);
        let mut out = SparseRows {
            offsets: vec![0],
            columns: self.columns,
            ..SparseRows::default()
        };
        for i in range {
            let (src, w) = stencils.stencil(i);
            for (&s, &w) in src.iter().zip(w) {
                let (cols, vals) = self.row(s as usize);
                for (&c, &v) in cols.iter().zip(vals) {
                    if !seen[c as usize] {
                        seen[c as usize] = true;
                        touched.push(c);
                    }
                    acc[c as usize] += w * v;
                }
            }
            touched.sort_unstable();
            for &c in &touched {
                let v = std::mem::take(&mut acc[c as usize]);
                seen[c as usize] = false;
                if v != 0.0 {
                    out.cols.push(c);
                    out.vals.push(v);
                }
            }
            touched.clear();
            out.offsets.push(out.cols.len() as u32);
        }
        out
    }

    /// `self * x`: one value per row.
    pub fn apply(&self, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                let (cols, vals) = self.row(i);
                let mut acc = [0.0; 3];
                for (&c, &v) in cols.iter().zip(vals) {
                    let xc = &x[c as usize];
                    for k in 0..3 {
                        acc[k] += v * xc[k];
                    }
                }
                acc
            })
            .collect()
    }

    /// `self^T * y`: one value per column.
    pub fn apply_transpose(&self, y: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let n = self.len();
        let chunk = n.div_ceil(rayon::current_num_threads().max(1)).max(CHUNK);
        (0..n.div_ceil(chunk))
            .into_par_iter()
            .map(|k| {
                let mut out = vec![[0.0; 3]; self.columns];
                for i in k * chunk..((k + 1) * chunk).min(n) {
                    let (cols, vals) = self.row(i);
                    for (&c, &v) in cols.iter().zip(vals) {
                        for j in 0..3 {
                            out[c as usize][j] += v * y[i][j];
                        }
                    }
                }
                out
            })
            .reduce_with(|mut a, b| {
                for (p, q) in a.iter_mut().zip(&b) {
                    for j in 0..3 {
                        p[j] += q[j];
                    }
                }
                a
            })
            .unwrap_or_else(|| vec![[0.0; 3]; self.columns])
    }

    /// `sum_i weight[i] * self(i, c)^2` for every column `c`.
    pub fn weighted_column_squares(&self, weight: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.columns];
        for (i, &w) in weight.iter().enumerate() {
            let (cols, vals) = self.row(i);
            for (&c, &v) in cols.iter().zip(vals) {
                out[c as usize] += w * v * v;
            }
        }
        out
    }
}

/// For each level-1 vertex of the ternary step, the base vertex whose colour it copies:
/// vertex points their own, edge points the end they lie at, face points their corner.
pub(crate) fn ternary_colour_sources(base: &Topology) -> Vec<u32> {
    let mut sources =
        Vec::with_capacity(base.vertex_count() + 2 * base.edge_count() + base.corner_count());
    sources.extend((0..base.vertex_count() as u32).map(ternary_step::vertex_point));
    for e in 0..base.edge_count() {
        sources.extend(base.edge_vertices(e));
    }
    for f in 0..base.face_count() {
        sources.extend_from_slice(base.face_vertices(f));
    }
    sources
}

/// The colours of level 1 as rows over the control points (`source_point` of the base level
/// names each base vertex's point), with `columns` unknowns in all (at least `points`).
pub(crate) fn level_1_rows(refinement: &Refinement, points: usize, columns: usize) -> SparseRows {
    let base = refinement.base();
    let sources = ternary_colour_sources(&base.topology)
        .into_iter()
        .map(|v| base.source_point[v as usize])
        .collect();
    SparseRows::selection(sources, points).widened(columns)
}

/// The limit colours of the vertices of level `depth >= 2` of `refinement` as rows over the
/// control points, with `limit` the level's limit stencils.
pub(crate) fn limit_colour_rows(
    refinement: &Refinement,
    depth: usize,
    limit: &Stencils,
    points: usize,
) -> SparseRows {
    let mut rows = level_1_rows(refinement, points, points);
    for k in 1..depth {
        rows = rows.compose(refinement.stencils(k));
    }
    rows.compose(limit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::ColourSpace;
    use crate::limit_surface::limit_stencils;
    use crate::mesh::GradientMesh;
    use kurbo::{Point, Vec2};

    /// The rows give the limit colours the refinement computes, for a mesh of a quad, a
    /// triangle and a pentagon with a turned handle.
    #[test]
    fn rows_reproduce_the_limit_colours() {
        let mut m = GradientMesh::new(ColourSpace::Lab);
        let pts = [
            (0.0, 0.0),
            (10.0, 0.0),
            (20.0, 0.0),
            (0.0, 10.0),
            (10.0, 10.0),
            (20.0, 10.0),
            (5.0, 18.0),
            (15.0, 20.0),
        ];
        for (i, &(x, y)) in pts.iter().enumerate() {
            let i = i as f64;
            m.add_point(Point::new(x, y), [40.0 + 3.0 * i, 10.0 - 2.0 * i, i * i]);
        }
        m.add_face(vec![0, 1, 4, 3]);
        m.add_face(vec![1, 2, 5, 4]);
        m.add_face(vec![3, 4, 6]);
        m.add_face(vec![4, 5, 7, 6]);
        m.set_handle(4, 5, Vec2::new(2.0, 2.0));
        for depth in [2, 3] {
            let (refinement, _) = Refinement::new(&m, depth).unwrap();
            let data = refinement.evaluate();
            let limit = limit_stencils(refinement.level(depth)).unwrap();
            let expected = limit.apply(&data.levels[depth]);
            let rows = limit_colour_rows(&refinement, depth, &limit, m.points.len());
            let colours: Vec<[f64; 3]> = m.points.iter().map(|p| p.colour).collect();
            let got = rows.apply(&colours);
            assert_eq!(got.len(), expected.len());
            for (g, e) in got.iter().zip(&expected) {
                for k in 0..3 {
                    assert!((g[k] - e.to_array()[2 + k]).abs() < 1e-9, "{g:?} vs {e:?}");
                }
            }
        }
    }
}
