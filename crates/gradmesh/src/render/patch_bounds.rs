//! A regular face's cell count chosen from its control points alone, as Cairo picks a patch's
//! steps: no samples measured.
//!
//! A regular face is a uniform bicubic B-spline patch; over the face it is a bicubic Bézier
//! patch, whose derivatives are Bernstein polynomials of its net's differences with
//! non-negative weights that sum to one. So each derivative is bounded by the largest
//! difference of its kind: `|P_uu| <= 6 max |Δ²_u b|`, `|P_uv| <= 9 max |Δ_u Δ_v b|`,
//! `|P_uuv| <= 18 max |Δ²_u Δ_v b|`, and so on (parameter units of the face, positions in
//! pixels through the view's scaling). Each attribute first loses the affine function of the
//! screen position that matches its gradient at the face's centre: interpolation reproduces
//! it exactly, and where colour follows the geometry the differences shrink severalfold.
//!
//! The triangles of a cell of side `h` show, at a pixel `x`, the interpolation in the plane of
//! `g = C ∘ P⁻¹` (colour as a function of the screen position), so the error is that of
//! interpolating `g`. Pulled back to the face's parameters:
//!
//! - **Linear pieces.** `D²g[Jδ, Jδ] = C''[δ, δ] - ∇g · P''[δ, δ]`, and over a cell's triangle
//!   the weights of the corners spread each parameter by at most `h² / 4`:
//!   `|error| <= h² / 8 · (S₂(C) + G · S₂(P))`, where `S₂ = max|f_uu| + 2 max|f_uv| + max|f_vv|`
//!   and `G` bounds the screen gradient of colour, `|[C_u C_v]| / σ` with `σ` a lower bound of
//!   the Jacobian's smallest singular value over the face.
//! - **Quadratic pieces** (six-node triangles, exact on quadratics): `|error| <= λ / 6 · h³ ·
//!   |D³g|`, `λ` the largest `Σ |φ_a(x)| |δ_a|³∞` of the nodes' basis functions over the triangle,
//!   and `D³g[Jδ]³ = C'''[δ³] + 3 C''[δ, s''] + ∇g · (P'''[δ³] + 3 P''[δ, s''])` with
//!   `s'' = -J⁻¹ P''[δ, δ]`.
//!
//! `σ` is the smallest of the Jacobian's least singular values at the centres of the face's
//! quarters, less the most the Jacobian can move within a quarter (Weyl's inequality). Where
//! it is under a quarter of the value at the face's centre (the surface may fold, or a handle
//! is nearly degenerate) the bounds are loose and the face is measured instead
//! ([`super::face_plans`]); so is a face whose bounds ask for cells under a pixel, where the
//! measure's own rules (which cells count) decide.
//!
//! Colour errors are approximately in Lab units: in other working spaces the differences are
//! scaled by the largest norm of the derivative to Lab over the box of the control points'
//! colours (its corners and centre). Opacity counts 100 per unit, on its own.
//!
//! The bounds hold over the whole face, where the measure samples cells' and sides' centres:
//! on the real artwork they come to about 3 to 4 times the measured error for linear colour
//! and 10 to 20 times for quadratic, so they ask for several times the triangles, which is why
//! [`RenderOptions::plan_from_bounds`](super::RenderOptions::plan_from_bounds) is off by
//! default (figures in `docs/performance.md`).

use crate::colour::ColourSpace;
use crate::limit_surface::patches::ControlGrid;

use super::measure::{Measure, Thresholds};
use super::view::ToPixels;

/// The face is measured instead where the lower bound of the Jacobian's smallest singular value
/// is under this fraction of its value at the centre: the gradient bound is then loose (and
/// where it reaches zero, the face may fold).
const LOOSE_JACOBIAN: f64 = 0.25;

/// The largest `Σ |φ_a(x)| |δ_a|³∞` over a cell's triangle `(0, 0), (1, 0), (1, 1)`, `φ_a` the
/// six quadratic basis functions and `δ_a` the offsets of their nodes from `x` (computed on a
/// fine lattice of the triangle, rounded up).
const QUADRATIC_LEBESGUE: f64 = 0.171;

/// Bounds of one attribute's derivatives over the face (colour in approximately Lab units, or
/// opacity times 100).
#[derive(Clone, Copy, Debug, Default)]
struct AttributeBounds {
    /// `sqrt(max|f_u|² + max|f_v|²)`: bounds the norm of the derivative `[f_u f_v]`.
    first: f64,
    /// `max|f_uu| + 2 max|f_uv| + max|f_vv|`.
    second: f64,
    /// `max|f_uuu| + 3 max|f_uuv| + 3 max|f_uvv| + max|f_vvv|`.
    third: f64,
}

/// Bounds of a regular patch's derivatives over its face.
#[derive(Clone, Copy, Debug)]
pub(super) struct PatchBounds {
    /// `max|P_u|` and `max|P_v|`, pixels.
    first: [f64; 2],
    /// The largest second derivative along each side of the face, pixels.
    sides: [f64; 4],
    /// [`AttributeBounds::second`] of position, pixels.
    second: f64,
    /// [`AttributeBounds::third`] of position, pixels.
    third: f64,
    /// A lower bound of the Jacobian's smallest singular value over the face, pixels.
    sigma: f64,
    /// Its value at the face's centre.
    sigma_centre: f64,
    /// Colour, then opacity.
    attributes: [AttributeBounds; 2],
    /// The box of the Bézier net on the screen, pixels: lower and upper corners.
    screen_box: [[f64; 2]; 2],
}

/// A point of a Bézier net in the units of the bounds: position in pixels, colour scaled to
/// approximately Lab units, opacity times 100.
type Scaled = [f64; 6];

fn sub(a: &Scaled, b: &Scaled) -> Scaled {
    std::array::from_fn(|k| a[k] - b[k])
}

/// The largest squared norms of differences: position, colour, opacity.
#[derive(Default)]
struct Largest([f64; 3]);

impl Largest {
    fn add(&mut self, d: &Scaled) {
        let n = [
            d[0] * d[0] + d[1] * d[1],
            d[2] * d[2] + d[3] * d[3] + d[4] * d[4],
            d[5] * d[5],
        ];
        for k in 0..3 {
            self.0[k] = self.0[k].max(n[k]);
        }
    }

    /// The largest norms, times `factor`.
    fn norms(&self, factor: f64) -> [f64; 3] {
        self.0.map(|x| factor * x.sqrt())
    }
}

/// The largest norms of a difference net of `R x C` points, times `factor`.
fn largest<const R: usize, const C: usize>(net: &[[Scaled; C]; R], factor: f64) -> [f64; 3] {
    let mut m = Largest::default();
    net.iter().flatten().for_each(|d| m.add(d));
    m.norms(factor)
}

/// Differences along rows (`u`) of an `R x C` net.
fn along_u<const R: usize, const C: usize, const D: usize>(
    net: &[[Scaled; C]; R],
) -> [[Scaled; D]; R] {
    std::array::from_fn(|j| std::array::from_fn(|i| sub(&net[j][i + 1], &net[j][i])))
}

/// Differences along columns (`v`) of an `R x C` net.
fn along_v<const R: usize, const C: usize, const D: usize>(
    net: &[[Scaled; C]; R],
) -> [[Scaled; C]; D] {
    std::array::from_fn(|j| std::array::from_fn(|i| sub(&net[j + 1][i], &net[j][i])))
}

/// The largest Frobenius norm of the derivative from `space` to Lab at the corners and centre of
/// the box of the control points' colours (1 in Lab).
fn lab_scale(cp: &ControlGrid, space: ColourSpace) -> f64 {
    if space == ColourSpace::Lab {
        return 1.0;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for d in cp.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(d[2 + k]);
            hi[k] = hi[k].max(d[2 + k]);
        }
    }
    let norm = |c: [f64; 3]| {
        let j = space.lab_jacobian(c);
        j.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
    };
    let centre = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    (0..8)
        .map(|corner| {
            norm(std::array::from_fn(|k| {
                if corner >> k & 1 == 0 {
                    lo[k]
                } else {
                    hi[k]
                }
            }))
        })
        .fold(norm(centre), f64::max)
}

/// The bicubic Bézier net of the patch `cp` over its face, scaled ([`Scaled`]).
fn bezier_net(cp: &ControlGrid, xf: &ToPixels, lab: f64) -> [[Scaled; 4]; 4] {
    // Each span of a uniform cubic B-spline as a cubic Bézier.
    const TO_BEZIER: [[f64; 4]; 4] = [
        [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
        [0.0, 4.0 / 6.0, 2.0 / 6.0, 0.0],
        [0.0, 2.0 / 6.0, 4.0 / 6.0, 0.0],
        [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
    ];
    let scale = [xf.sx, xf.sy, lab, lab, lab, 100.0];
    let scaled: [[Scaled; 4]; 4] = std::array::from_fn(|j| {
        std::array::from_fn(|i| std::array::from_fn(|k| scale[k] * cp[j][i][k]))
    });
    let combine = |w: &[f64; 4], p: [&Scaled; 4]| -> Scaled {
        std::array::from_fn(|k| w[0] * p[0][k] + w[1] * p[1][k] + w[2] * p[2][k] + w[3] * p[3][k])
    };
    let rows: [[Scaled; 4]; 4] = std::array::from_fn(|j| {
        let r = &scaled[j];
        std::array::from_fn(|i| combine(&TO_BEZIER[i], [&r[0], &r[1], &r[2], &r[3]]))
    });
    std::array::from_fn(|j| {
        std::array::from_fn(|i| {
            combine(
                &TO_BEZIER[j],
                [&rows[0][i], &rows[1][i], &rows[2][i], &rows[3][i]],
            )
        })
    })
}

/// The derivatives `[P_u, P_v]` at the face's centre of the Bézier patch whose first
/// differences are `du` and `dv`: three times the differences weighted by the quadratic
/// Bernstein basis at 1/2 along the derivative and the cubic one across it.
fn centre_derivatives(du: &[[Scaled; 3]; 4], dv: &[[Scaled; 4]; 3]) -> [Scaled; 2] {
    const QUADRATIC_HALF: [f64; 3] = [0.75, 1.5, 0.75];
    const CUBIC_HALF: [f64; 4] = [0.125, 0.375, 0.375, 0.125];
    let (mut pu, mut pv) = ([0.0; 6], [0.0; 6]);
    for j in 0..4 {
        for i in 0..3 {
            let w = QUADRATIC_HALF[i] * CUBIC_HALF[j];
            for k in 0..6 {
                pu[k] += w * du[j][i][k];
                pv[k] += w * dv[i][j][k];
            }
        }
    }
    [pu, pv]
}

/// Subtracts from each attribute of `net` the affine function of the screen position that
/// matches its gradient at the face's centre (from the centre's derivatives `[pu, pv]`).
/// Interpolation reproduces affine functions of the screen position exactly, so the error is
/// the same; the bounds are far tighter where colour follows the geometry (the differences of
/// position and colour then largely cancel). A singular Jacobian leaves `net` as it is.
fn remove_affine_part(net: &mut [[Scaled; 4]; 4], [pu, pv]: [Scaled; 2]) {
    let (a, b, c, d) = (pu[0], pu[1], pv[0], pv[1]);
    let det = a * d - b * c;
    if det.is_nan() || det.abs() <= 1e-12 * (a * a + b * b + c * c + d * d) {
        return;
    }
    // Solve [gx gy] [a c; b d] = [f_u f_v] for each attribute.
    let gradient: [[f64; 2]; 4] = std::array::from_fn(|k| {
        [
            (pu[2 + k] * d - pv[2 + k] * b) / det,
            (pv[2 + k] * a - pu[2 + k] * c) / det,
        ]
    });
    for p in net.iter_mut().flatten() {
        for k in 0..4 {
            p[2 + k] -= gradient[k][0] * p[0] + gradient[k][1] * p[1];
        }
    }
}

/// The Jacobian (pixels) at parameter `(u, v)` of the Bézier patch whose first differences are
/// `du` and `dv`: columns `P_u` and `P_v`.
fn jacobian_at(du: &[[Scaled; 3]; 4], dv: &[[Scaled; 4]; 3], u: f64, v: f64) -> [[f64; 2]; 2] {
    let quadratic = |t: f64| {
        [
            3.0 * (1.0 - t) * (1.0 - t),
            6.0 * t * (1.0 - t),
            3.0 * t * t,
        ]
    };
    let cubic = |t: f64| {
        let s = 1.0 - t;
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
    };
    let (qu, qv, cu, cv) = (quadratic(u), quadratic(v), cubic(u), cubic(v));
    let (mut pu, mut pv) = ([0.0; 2], [0.0; 2]);
    for j in 0..4 {
        for i in 0..3 {
            let (wu, wv) = (qu[i] * cv[j], qv[i] * cu[j]);
            for k in 0..2 {
                pu[k] += wu * du[j][i][k];
                pv[k] += wv * dv[i][j][k];
            }
        }
    }
    [pu, pv]
}

/// The smallest singular value of the 2x2 matrix with columns `a` and `b`.
fn smallest_singular_value(a: [f64; 2], b: [f64; 2]) -> f64 {
    let plus = ((a[0] + b[1]).powi(2) + (a[1] - b[0]).powi(2)).sqrt();
    let minus = ((a[0] - b[1]).powi(2) + (a[1] + b[0]).powi(2)).sqrt();
    0.5 * (plus - minus).abs()
}

impl PatchBounds {
    /// The bounds of the patch `cp` drawn through `xf`, its colours in `space`.
    pub fn new(cp: &ControlGrid, xf: &ToPixels, space: ColourSpace) -> PatchBounds {
        let mut net = bezier_net(cp, xf, lab_scale(cp, space));
        let mut screen_box = [[f64::INFINITY; 2], [f64::NEG_INFINITY; 2]];
        for p in net.iter().flatten() {
            // The net's positions are scaled but not shifted.
            let at = [p[0] - xf.x0 * xf.sx, p[1] - xf.y0 * xf.sy];
            for k in 0..2 {
                screen_box[0][k] = screen_box[0][k].min(at[k]);
                screen_box[1][k] = screen_box[1][k].max(at[k]);
            }
        }
        let centre = centre_derivatives(&along_u(&net), &along_v(&net));
        remove_affine_part(&mut net, centre);
        let du: [[Scaled; 3]; 4] = along_u(&net);
        let dv: [[Scaled; 4]; 3] = along_v(&net);
        let duu: [[Scaled; 2]; 4] = along_u(&du);
        let dvv: [[Scaled; 4]; 2] = along_v(&dv);
        let duv: [[Scaled; 3]; 3] = along_v(&du);
        let duuu: [[Scaled; 1]; 4] = along_u(&duu);
        let dvvv: [[Scaled; 4]; 1] = along_v(&dvv);
        let duuv: [[Scaled; 2]; 3] = along_v(&duu);
        let duvv: [[Scaled; 3]; 2] = along_u(&dvv);
        // A cubic's derivatives in Bernstein form: 3 times the first differences, 6 times the
        // second, 6 times the third (and products of these across).
        let first = [largest(&du, 3.0), largest(&dv, 3.0)];
        let [uu, vv, uv] = [largest(&duu, 6.0), largest(&dvv, 6.0), largest(&duv, 9.0)];
        let [uuu, vvv, uuv, uvv] = [
            largest(&duuu, 6.0),
            largest(&dvvv, 6.0),
            largest(&duuv, 18.0),
            largest(&duvv, 18.0),
        ];
        // The face's sides are the net's outer rows and columns.
        let sides = [
            largest(&[duu[0]], 6.0)[0],
            largest(&dvv.map(|r| [r[3]]), 6.0)[0],
            largest(&[duu[3]], 6.0)[0],
            largest(&dvv.map(|r| [r[0]]), 6.0)[0],
        ];
        let second = |k: usize| uu[k] + 2.0 * uv[k] + vv[k];
        let third = |k: usize| uuu[k] + 3.0 * uuv[k] + 3.0 * uvv[k] + vvv[k];
        let [pu, pv] = centre;
        let sigma_centre = smallest_singular_value([pu[0], pu[1]], [pv[0], pv[1]]);
        // Over each quarter of the face, from its centre, each parameter moves at most 1/4.
        let moved_u = 0.25 * (uu[0] + uv[0]);
        let moved_v = 0.25 * (uv[0] + vv[0]);
        let moved = (moved_u * moved_u + moved_v * moved_v).sqrt();
        let sigma = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
            .map(|(u, v)| {
                let [a, b] = jacobian_at(&du, &dv, u, v);
                smallest_singular_value(a, b) - moved
            })
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        let attribute = |k: usize| AttributeBounds {
            first: (first[0][k] * first[0][k] + first[1][k] * first[1][k]).sqrt(),
            second: second(k),
            third: third(k),
        };
        PatchBounds {
            first: [first[0][0], first[1][0]],
            sides,
            second: second(0),
            third: third(0),
            sigma,
            sigma_centre,
            attributes: [attribute(1), attribute(2)],
            screen_box,
        }
    }

    /// Whether the patch misses an image of `size` pixels: its Bézier net's convex hull,
    /// which holds it, does.
    pub fn off_image(&self, size: (f64, f64)) -> bool {
        let (lo, hi) = (self.screen_box[0], self.screen_box[1]);
        hi[0] < -1.0 || hi[1] < -1.0 || lo[0] > size.0 + 1.0 || lo[1] > size.1 + 1.0
    }

    /// Whether the bounds are tight enough to plan by: the Jacobian stays well away from
    /// singular over the face.
    fn tight(&self) -> bool {
        self.sigma > LOOSE_JACOBIAN * self.sigma_centre
    }

    /// The largest colour error of linear pieces on cells of side `h`.
    fn linear_colour(&self, h: f64) -> f64 {
        self.attributes
            .iter()
            .map(|a| h * h / 8.0 * (a.second + a.first / self.sigma * self.second))
            .fold(0.0, f64::max)
    }

    /// A bound of `|D³g[Jδ, Jδ, Jδ]| / |δ|³∞` for attribute `a` (see the module's comment).
    fn third_of_g(&self, a: &AttributeBounds) -> f64 {
        let k = 1.0 / self.sigma;
        let gradient = a.first * k;
        a.third
            + 3.0 * a.second * k * self.second
            + gradient * (self.third + 3.0 * k * self.second * self.second)
    }

    /// The largest colour error of quadratic pieces on cells of side `h`.
    fn quadratic_colour(&self, h: f64) -> f64 {
        // The chords' offsets from `J δ` (the second-order term of the map) widen the nodes'
        // offsets by at most this factor.
        let widen = (1.0 + 0.5 * self.second / self.sigma * h).powi(3);
        self.attributes
            .iter()
            .map(|a| QUADRATIC_LEBESGUE / 6.0 * h * h * h * widen * self.third_of_g(a))
            .fold(0.0, f64::max)
    }

    /// The bounds of the figures [`super::measure::measure_quad`] measures, for cells of side
    /// `h` with colour error `colour`; `boundary[k]`: whether side `k` of the face (along `u`
    /// for even `k`) lies on the outline.
    fn figures(&self, h: f64, colour: f64, boundary: [bool; 4]) -> Measure {
        let bend = (0..4)
            .filter(|&k| boundary[k])
            .map(|k| self.sides[k])
            .fold(0.0, f64::max);
        Measure {
            extent: h * (self.first[0] + self.first[1]),
            colour,
            outline: h * h / 8.0 * bend,
        }
    }
}

/// A face's cells a side and colour order chosen from its bounds, with the bounds of what the
/// measure would see there.
#[derive(Clone, Copy, Debug)]
pub(super) struct BoundedPlan {
    pub n: usize,
    /// Whether the cells take quadratic colour (six-node triangles) rather than linear.
    pub quadratic: bool,
    pub figures: Measure,
    /// The colour error of linear pieces at `n`.
    pub linear_colour: f64,
}

/// The fewest cells a side (a power of two, at most `n_max`) whose bounds pass `th`, linear or
/// (when `th` allows it, and fewer cells) quadratic; `None` where the bounds are loose: the
/// Jacobian nearly singular, cells under [`Thresholds::min_quad`] across, or more than `n_max`
/// cells a side.
pub(super) fn plan_from_bounds(
    b: &PatchBounds,
    th: &Thresholds,
    boundary: [bool; 4],
    n_max: usize,
) -> Option<BoundedPlan> {
    if !b.tight() {
        return None;
    }
    let passes =
        |m: &Measure| m.extent <= th.quad && m.colour <= th.colour && m.outline <= th.outline;
    let fewest = |colour: &dyn Fn(f64) -> f64| -> Option<(usize, Measure)> {
        let mut n = 1;
        loop {
            let h = 1.0 / n as f64;
            let m = b.figures(h, colour(h), boundary);
            if passes(&m) {
                return Some((n, m));
            }
            if n >= n_max {
                return None;
            }
            n *= 2;
        }
    };
    let (n_linear, linear) = fewest(&|h| b.linear_colour(h))?;
    let quadratic = if th.quadratic && n_linear > 1 {
        fewest(&|h| b.quadratic_colour(h)).filter(|&(n, _)| n < n_linear)
    } else {
        None
    };
    let plan = match quadratic {
        Some((n, figures)) => BoundedPlan {
            n,
            quadratic: true,
            figures,
            linear_colour: b.linear_colour(1.0 / n as f64),
        },
        None => BoundedPlan {
            n: n_linear,
            quadratic: false,
            figures: linear,
            linear_colour: linear.colour,
        },
    };
    // Where the bound asks for cells too small to count, the measure's rules decide.
    (plan.figures.extent >= th.min_quad || plan.n == 1).then_some(plan)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limit_surface::patches::evaluate_patch;
    use crate::render::measure::{measure_quad, QuadSamples, MIN_QUAD_PX};
    use crate::render::{each4, View};

    /// A curved patch: a grid bent along a parabola, with colour `colour(x, y)` at each point
    /// and opacity falling by `fade` times the product of the grid's coordinates.
    fn patch(colour: impl Fn(f64, f64) -> [f64; 3], fade: f64) -> ControlGrid {
        std::array::from_fn(|j| {
            std::array::from_fn(|i| {
                let (u, v) = (i as f64, j as f64);
                let (x, y) = (10.0 * u + 0.8 * v * v, 9.0 * v + 0.6 * u * u - 0.3 * u * v);
                let c = colour(x, y);
                [x, y, c[0], c[1], c[2], 1.0 - fade * u * v]
            })
        })
    }

    fn view() -> ToPixels {
        ToPixels::new(&View::new(-10.0, -10.0, 50.0, 50.0), 150, 150)
    }

    fn thresholds() -> Thresholds {
        Thresholds {
            quad: 64.0,
            colour: 0.15,
            outline: 0.25,
            min_quad: MIN_QUAD_PX,
            size: (150.0, 150.0),
            space: ColourSpace::Lab,
            quadratic: true,
            plan_from_bounds: true,
        }
    }

    /// The colour error, size and outline distance the measure finds on the face's grid of `n`
    /// cells a side, every side on the outline.
    fn measured(cp: &ControlGrid, n: usize) -> Measure {
        let (g, g2) = (evaluate_patch(cp, n), evaluate_patch(cp, 2 * n));
        let (s, s2) = (n + 1, 2 * n + 1);
        let mut worst = Measure::default();
        for j in 0..n {
            for i in 0..n {
                let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let mid = |a: (usize, usize), b: (usize, usize)| &g2[(a.1 + b.1) * s2 + a.0 + b.0];
                let q = QuadSamples {
                    corners: each4(|k| &g[c[k].1 * s + c[k].0]),
                    centre: mid(c[0], c[2]),
                    mids: each4(|k| mid(c[k], c[(k + 1) % 4])),
                    boundary: [j == 0, i + 1 == n, j + 1 == n, i == 0],
                    jacobians: None,
                };
                let m = measure_quad(&q, &view(), (150.0, 150.0), ColourSpace::Lab, 0.0, true);
                worst = worst.max(m);
            }
        }
        worst
    }

    /// Every figure the measure finds is within its bound, at every count.
    #[test]
    fn bounds_hold_what_the_measure_finds() {
        let cp = patch(
            |x, y| [50.0 + 0.02 * x * x, 10.0 * (0.1 * y).sin(), 0.01 * x * y],
            0.01,
        );
        let b = PatchBounds::new(&cp, &view(), ColourSpace::Lab);
        assert!(b.tight());
        for n in [1, 2, 4, 8] {
            let h = 1.0 / n as f64;
            let m = measured(&cp, n);
            let bound = b.figures(h, b.linear_colour(h), [true; 4]);
            assert!(
                m.colour > 0.0 && m.colour <= bound.colour,
                "{n}: {m:?} {bound:?}"
            );
            assert!(m.extent <= bound.extent, "{n}: {m:?} {bound:?}");
            assert!(m.outline <= bound.outline, "{n}: {m:?} {bound:?}");
        }
    }

    /// Colour that is an affine function of the position is drawn exactly by any cells, however
    /// the patch bends: one cell, whatever the colour's slope.
    #[test]
    fn colour_affine_in_the_plane_takes_one_cell() {
        let cp = patch(|x, y| [20.0 + 1.5 * x, -30.0 + 2.0 * y, 0.5 * x - y], 0.0);
        let b = PatchBounds::new(&cp, &view(), ColourSpace::Lab);
        assert!(b.linear_colour(1.0) < 1e-9, "{b:?}");
        let th = Thresholds {
            outline: 100.0,
            ..thresholds()
        };
        let plan = plan_from_bounds(&b, &th, [false; 4], 64).unwrap();
        assert_eq!((plan.n, plan.quadratic), (1, false));
    }

    /// Steeper colour takes more cells, and smooth colour quadratic ones.
    #[test]
    fn counts_follow_the_colour() {
        let th = thresholds();
        let count = |k: f64| {
            let cp = patch(
                |x, y| [50.0 + k * 0.02 * x * x, k * (0.1 * y).sin(), 0.0],
                0.0,
            );
            plan_from_bounds(
                &PatchBounds::new(&cp, &view(), ColourSpace::Lab),
                &th,
                [false; 4],
                64,
            )
            .unwrap()
        };
        let (gentle, steep) = (count(0.2), count(40.0));
        assert!(gentle.n < steep.n, "{gentle:?} {steep:?}");
        assert!(steep.quadratic, "{steep:?}");
    }

    /// A patch whose handles cross folds over itself: its bounds are loose and it is measured.
    #[test]
    fn folded_patches_are_left_to_the_measure() {
        let mut cp = patch(|_, _| [50.0, 0.0, 0.0], 0.0);
        cp[1][2][0] = cp[1][0][0] - 25.0;
        cp[2][2][0] = cp[2][0][0] - 25.0;
        let b = PatchBounds::new(&cp, &view(), ColourSpace::Lab);
        assert!(!b.tight(), "{b:?}");
        assert!(plan_from_bounds(&b, &thresholds(), [false; 4], 64).is_none());
    }
}
