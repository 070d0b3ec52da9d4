//! The colour least-squares problem and its solver.
//!
//! Minimise `sum_p w_p |A_p c - y_p|^2 + lambda sum_(i,j) |c_i - c_j|^2` over the control colours
//! `c`, with `A = P R`: `R` the limit-colour rows of a refined level's vertices
//! ([`super::rows`]), `P` the barycentric weights of each pixel's triangle
//! ([`super::raster`]), `(i, j)` the control mesh's edges. The normal matrix
//! `R^T K R + lambda L` (with `K = P^T W P` summed per triangle and `L` the mesh's graph
//! Laplacian) is symmetric positive definite when the regulariser is on, and is applied as
//! that product, never formed: its rows would hold thousands of products per pixel. The three
//! colour channels share it and are solved together by conjugate gradients with a Jacobi
//! preconditioner, each channel with its own step lengths.

use super::raster::Observation;
use super::rows::SparseRows;

/// The normal equations of one colour fit.
pub(crate) struct NormalEquations<'a> {
    pub rows: &'a SparseRows,
    pub observation: &'a Observation,
    /// The control mesh's edges (point pairs).
    pub edges: &'a [[u32; 2]],
    /// The weight of the smoothness term.
    pub lambda: f64,
    /// The weight of `|x_i|^2` for the unknowns from `ridge_from` on (refined-level offsets,
    /// kept small where the control colours explain the picture).
    pub ridge: f64,
    /// The first unknown the ridge applies to.
    pub ridge_from: usize,
}

type Colours = Vec<[f64; 3]>;

impl NormalEquations<'_> {
    /// The normal matrix applied to `x`.
    fn apply(&self, x: &[[f64; 3]]) -> Colours {
        let z = self.rows.apply(x);
        let kz = self.observation.apply_gram(&z);
        let mut out = self.rows.apply_transpose(&kz);
        if self.lambda > 0.0 {
            for &[a, b] in self.edges {
                let (a, b) = (a as usize, b as usize);
                for k in 0..3 {
                    let d = self.lambda * (x[a][k] - x[b][k]);
                    out[a][k] += d;
                    out[b][k] -= d;
                }
            }
        }
        if self.ridge > 0.0 {
            for (o, xi) in out.iter_mut().zip(x).skip(self.ridge_from) {
                for k in 0..3 {
                    o[k] += self.ridge * xi[k];
                }
            }
        }
        out
    }

    /// The right-hand side `R^T P^T W y`.
    fn rhs(&self) -> Colours {
        self.rows.apply_transpose(&self.observation.rhs)
    }

    /// An approximation of the normal matrix's diagonal (each level vertex's pixels lumped on
    /// it), for the preconditioner.
    pub fn diagonal(&self) -> Vec<f64> {
        let mut d = self.rows.weighted_column_squares(&self.observation.mass);
        for &[a, b] in self.edges {
            d[a as usize] += self.lambda;
            d[b as usize] += self.lambda;
        }
        for v in d.iter_mut().skip(self.ridge_from) {
            *v += self.ridge;
        }
        d
    }

    /// Solves from the guess `x`, until every channel's residual is below `tolerance` times its
    /// right-hand side or after `max_iterations`. Returns the iterations taken.
    pub fn solve(&self, x: &mut [[f64; 3]], tolerance: f64, max_iterations: usize) -> usize {
        let n = x.len();
        let inverse: Vec<f64> = self
            .diagonal()
            .into_iter()
            .map(|d| if d > 0.0 { 1.0 / d } else { 0.0 })
            .collect();
        let b = self.rhs();
        let ax = self.apply(x);
        let mut r: Colours = (0..n)
            .map(|i| [0, 1, 2].map(|k| b[i][k] - ax[i][k]))
            .collect();
        let norm = |v: &[[f64; 3]]| [0, 1, 2].map(|k| v.iter().map(|e| e[k] * e[k]).sum::<f64>());
        let goal = norm(&b).map(|s| s.max(1e-300) * tolerance * tolerance);
        let mut z: Colours = (0..n).map(|i| r[i].map(|e| e * inverse[i])).collect();
        let mut p = z.clone();
        let dot = |u: &[[f64; 3]], v: &[[f64; 3]]| {
            [0, 1, 2].map(|k| u.iter().zip(v).map(|(a, b)| a[k] * b[k]).sum::<f64>())
        };
        let mut rz = dot(&r, &z);
        for iteration in 0..max_iterations {
            let rr = norm(&r);
            if (0..3).all(|k| rr[k] <= goal[k]) {
                return iteration;
            }
            let ap = self.apply(&p);
            let pap = dot(&p, &ap);
            let alpha = [0, 1, 2].map(|k| if pap[k] > 0.0 { rz[k] / pap[k] } else { 0.0 });
            for i in 0..n {
                for k in 0..3 {
                    x[i][k] += alpha[k] * p[i][k];
                    r[i][k] -= alpha[k] * ap[i][k];
                    z[i][k] = r[i][k] * inverse[i];
                }
            }
            let rz_next = dot(&r, &z);
            let beta = [0, 1, 2].map(|k| if rz[k] > 0.0 { rz_next[k] / rz[k] } else { 0.0 });
            for i in 0..n {
                for k in 0..3 {
                    p[i][k] = z[i][k] + beta[k] * p[i][k];
                }
            }
            rz = rz_next;
        }
        max_iterations
    }
}
