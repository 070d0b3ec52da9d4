//! The limit colours of a refined level as a sparse linear map of the control colours.
//!
//! Colours and opacity go through refinement by fixed weights: the first step copies or
//! averages control colours (its handles move positions only), every Catmull-Clark step and
//! the limit stencils are linear. So the limit colour (and opacity) of each vertex of level `k`
//! is one row of a sparse matrix applied to the control colours, the same matrix for every
//! channel: what fitting colours to a picture by least squares needs. Positions are not linear
//! in the control data (the first step's handles), and multi-resolution colour edits add
//! targets of their own, so a mesh with colour or opacity edits is refused.

use crate::binary_step;
use crate::catmull_clark::Stencils;
use crate::error::{Error, ErrorKind, Warning};
use crate::limit_surface;
use crate::mesh::{FirstStep, GradientMesh};
use crate::refine::Refinement;
use crate::size_limits::Limits;
use crate::ternary_step;
use crate::validate::BaseMesh;

/// A sparse matrix in compressed sparse row form (as `scipy.sparse.csr_matrix` takes it):
/// row `r` holds `values[offsets[r]..offsets[r + 1]]` in the columns `columns[...]`, in
/// increasing column order, with no zero stored.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitMatrix {
    /// Number of rows: the vertices of the level.
    pub rows: usize,
    /// Number of columns: the control values mapped.
    pub columns: usize,
    /// `rows + 1` offsets into `indices` and `values`.
    pub offsets: Vec<usize>,
    /// The column of each stored value.
    pub indices: Vec<u32>,
    /// The stored values.
    pub values: Vec<f64>,
}

impl LimitMatrix {
    /// The matrix applied to `control`, `columns` rows of `width` values each (row-major):
    /// `rows` rows of `width` values.
    ///
    /// # Panics
    /// If `control` does not hold `columns * width` values.
    pub fn apply(&self, control: &[f64], width: usize) -> Vec<f64> {
        assert_eq!(control.len(), self.columns * width, "one row per column");
        let mut out = vec![0.0; self.rows * width];
        if width == 0 {
            return out;
        }
        for (r, row) in out.chunks_exact_mut(width).enumerate() {
            for k in self.offsets[r]..self.offsets[r + 1] {
                let (c, w) = (self.indices[k] as usize, self.values[k]);
                for (o, x) in row.iter_mut().zip(&control[c * width..(c + 1) * width]) {
                    *o += w * x;
                }
            }
        }
        out
    }

    fn from_stencils(stencils: &Stencils, columns: usize) -> LimitMatrix {
        let mut m = LimitMatrix {
            rows: stencils.len(),
            columns,
            offsets: Vec::with_capacity(stencils.len() + 1),
            indices: Vec::new(),
            values: Vec::new(),
        };
        m.offsets.push(0);
        for r in 0..stencils.len() {
            let (sources, weights) = stencils.stencil(r);
            m.indices.extend_from_slice(sources);
            m.values.extend_from_slice(weights);
            m.offsets.push(m.indices.len());
        }
        m
    }
}

impl Refinement {
    /// The limit colour and opacity of every vertex of level `k` as a sparse matrix of the base
    /// level's colours: row `i` is vertex `i` of level `k` (as in [`Refinement::limit`]), column
    /// `j` is base vertex `j` (the control points first, then the extra wedges of points on
    /// discontinuous edges, [`BaseMesh::source_point`]). Refines further where
    /// [`Refinement::limit`] does.
    ///
    /// Refuses a mesh with colour or opacity edits: their targets are not a linear map of the
    /// control colours.
    pub fn limit_matrix(&mut self, k: usize) -> Result<LimitMatrix, Error> {
        refuse_colour_edits(self.base())?;
        let columns = self.base().topology.vertex_count();
        // `to_base` maps level `j`'s colours to the base level's.
        let mut j = k;
        let mut to_base = if k == 0 {
            None
        } else {
            Some(self.colours_from_base(k))
        };
        let mut index: Vec<u32> = (0..self.topology(k).vertex_count() as u32).collect();
        loop {
            if let Some(m) = &to_base {
                if let Some(st) = limit_surface::limit_stencils(self.level(j)) {
                    let rows = Stencils::build(index.len(), |r, terms| {
                        let (s, w) = st.stencil(index[r] as usize);
                        compose_row(s, w, m, terms);
                    });
                    return Ok(LimitMatrix::from_stencils(&rows, columns));
                }
                // Vertex v of level j is vertex point nf + ne + v at level j + 1.
                let t = self.topology(j);
                let shift = (t.face_count() + t.edge_count()) as u32;
                index.iter_mut().for_each(|i| *i += shift);
            }
            j += 1;
            self.extend_to(j);
            to_base = Some(match to_base {
                None => first_step_colours(self.base()),
                Some(m) => compose(self.stencils(j - 1), &m),
            });
        }
    }

    /// The colours of level `k >= 1` as stencils over the base level's colours.
    fn colours_from_base(&mut self, k: usize) -> Stencils {
        self.extend_to(k);
        let mut m = first_step_colours(self.base());
        for j in 1..k {
            m = compose(self.stencils(j), &m);
        }
        m
    }
}

/// The limit colour and opacity of every vertex of level `level` of `mesh` as a sparse matrix
/// of its points' colours: row `i` is vertex `i` of the level (the order of
/// [`refine_level`](crate::refine_level) with [`LevelPoints::Limit`](crate::LevelPoints)),
/// column `j` is `mesh.points[j]`. Applied to the points' colours (or opacities) it gives the
/// level's limit colours (or opacities).
///
/// Refuses, with an error naming it, a colour or opacity edit and a wedge (one side of a
/// discontinuous edge) with a colour or opacity of its own: the limit is then not a linear map
/// of the points' colours ([`Refinement::limit_matrix`] maps the split vertices' colours,
/// wedges included). Checks `limits` as [`refine_level`](crate::refine_level) does.
pub fn limit_matrix(
    mesh: &GradientMesh,
    level: usize,
    limits: &Limits,
) -> Result<(LimitMatrix, Vec<Warning>), Error> {
    refuse_own_wedge_colours(mesh)?;
    let (mut refinement, warnings) = Refinement::new_with_limits(mesh, level, limits)?;
    limits.check_refinement(refinement.base(), level.max(2))?;
    let by_vertex = refinement.limit_matrix(level)?;
    // Each split vertex carries its point's colour: fold the wedges' columns into the points'.
    let source = &refinement.base().source_point;
    let rows = Stencils::build(by_vertex.rows, |r, terms| {
        let span = by_vertex.offsets[r]..by_vertex.offsets[r + 1];
        terms.extend(
            by_vertex.indices[span.clone()]
                .iter()
                .zip(&by_vertex.values[span])
                .map(|(&c, &w)| (source[c as usize], w)),
        );
    });
    Ok((
        LimitMatrix::from_stencils(&rows, mesh.points.len()),
        warnings,
    ))
}

/// Level 1's colours as stencils over the base level's: the first step's copies and means.
fn first_step_colours(base: &BaseMesh) -> Stencils {
    let t = &base.topology;
    match base.first_step {
        FirstStep::Ternary => {
            let sources = ternary_step::colour_sources(t);
            Stencils::build(sources.len(), |i, terms| terms.push((sources[i], 1.0)))
        }
        FirstStep::Binary => {
            let sources = binary_step::colour_sources(t);
            Stencils::build(sources.len(), |i, terms| {
                let w = 1.0 / sources[i].len() as f64;
                terms.extend(sources[i].iter().map(|&s| (s, w)));
            })
        }
    }
}

/// `outer` applied after `inner`: each row of `outer` over `inner`'s sources.
fn compose(outer: &Stencils, inner: &Stencils) -> Stencils {
    Stencils::build(outer.len(), |i, terms| {
        let (s, w) = outer.stencil(i);
        compose_row(s, w, inner, terms);
    })
}

/// The terms of one row of weights `weights` on the rows `sources` of `inner`.
fn compose_row(sources: &[u32], weights: &[f64], inner: &Stencils, terms: &mut Vec<(u32, f64)>) {
    for (&s, &w) in sources.iter().zip(weights) {
        let (cs, cw) = inner.stencil(s as usize);
        terms.extend(cs.iter().zip(cw).map(|(&c, &v)| (c, w * v)));
    }
}

fn refuse_colour_edits(base: &BaseMesh) -> Result<(), Error> {
    match base.edits.edits.iter().find(|e| e.edit.changes_colour()) {
        Some(e) => Err(ErrorKind::Invalid {
            what: format!("edit {}", e.index),
            message: "it changes colour or opacity, so the limit colours are not a linear map \
                      of the control colours: no limit matrix"
                .into(),
        }
        .into()),
        None => Ok(()),
    }
}

fn refuse_own_wedge_colours(mesh: &GradientMesh) -> Result<(), Error> {
    for w in &mesh.wedges {
        let Some(point) = mesh.points.get(w.point as usize) else {
            continue; // validation names it
        };
        if w.colour != point.colour || w.opacity.is_some_and(|o| o != point.opacity) {
            return Err(ErrorKind::Invalid {
                what: format!("wedge of point {} at face {}", w.point, w.face),
                message: "it has a colour or opacity of its own, so the limit colours are not a \
                          linear map of the points' colours: no limit matrix by point"
                    .into(),
            }
            .into());
        }
    }
    Ok(())
}
