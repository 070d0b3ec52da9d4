//! Splitting Bézier patches until a viewer's bilinear colour between corners stays within a
//! tolerance of the surface's bicubic colour.
//!
//! A viewer colours a patch by interpolating its four corner colours bilinearly in the
//! patch's colour space, while the limit surface's colour is bicubic. Splitting a patch into
//! `n x m` equal cells, each given its exact corner colours, cuts the difference by about
//! `1 / n²` along `u` (and `1 / m²` along `v`): for a Bézier net with largest second
//! differences `D_u`, `D_v` the error is at most `3/4 (D_u / n² + D_v / m²)` (in the net's
//! units). That bound starts the counts (it is about twice the real error); the counts then
//! grow until the CIEDE2000 difference between the bilinear colour, in the viewer's space, and
//! the surface's colour is within the tolerance at nine points of every cell (centre, side
//! midpoints, quarter points) and opacity within a hundredth of it. Colours are compared after
//! the renderer's gamut mapping, which is what is written.

use palette::color_difference::Ciede2000;
use palette::{white_point::D65, Lab};

use super::bezier::{evaluate, sub_net, BezierNet};
use crate::colour::gamut::{to_blend_space, BlendSpace, GamutMapping};
use crate::colour::ColourSpace;
use crate::validate::VertexData;

/// The bound's usual overestimate: counts start from the bound at this many times the tolerance.
const BOUND_SLACK: f64 = 2.5;
/// Counts never exceed this along either direction of one patch.
pub(crate) const MAX_SPLIT: usize = 256;
/// Opacity errors count this many times in colour units (a hundredth of opacity is one ΔE00).
const OPACITY_WEIGHT: f64 = 100.0;
/// Where each cell is checked, in its own parameters.
const SAMPLES: [(f64, f64); 9] = [
    (0.5, 0.0),
    (0.0, 0.5),
    (1.0, 0.5),
    (0.5, 1.0),
    (0.5, 0.5),
    (0.25, 0.25),
    (0.75, 0.25),
    (0.25, 0.75),
    (0.75, 0.75),
];

/// The space a viewer interpolates corner colours in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Target {
    /// CIE L*a*b* (D65).
    Lab,
    /// Non-linear sRGB, channels unclamped.
    Srgb,
}

impl Target {
    fn space(self) -> ColourSpace {
        match self {
            Target::Lab => ColourSpace::Lab,
            Target::Srgb => ColourSpace::Srgb,
        }
    }
}

/// One patch as written: its Bézier net in pixels (`points[j][i]`, `i` along `u`), and the
/// colours (in the target space) and opacities of its corners at `(0, 0)`, `(1, 0)`, `(1, 1)`
/// and `(0, 1)`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct OutPatch {
    pub points: [[[f64; 2]; 4]; 4],
    pub colours: [[f64; 3]; 4],
    pub opacity: [f64; 4],
}

/// How to split: the layer's working space, the target space, the tolerance in ΔE00, and
/// whether opacity counts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Splitter {
    pub space: ColourSpace,
    pub target: Target,
    pub tolerance: f64,
    pub opacity: bool,
}

/// CIEDE2000 between two Lab colours.
pub(crate) fn delta_e00(a: [f64; 3], b: [f64; 3]) -> f64 {
    let lab = |c: [f64; 3]| Lab::<D65, f64>::new(c[0], c[1], c[2]);
    lab(a).difference(lab(b))
}

impl Splitter {
    /// Splits `net` (positions in pixels, colours in the working space) and appends its cells
    /// to `out`; returns the counts `(n, m)` along `u` and `v`.
    pub fn split(&self, net: &BezierNet, out: &mut Vec<OutPatch>) -> (usize, usize) {
        let (mut n, mut m) = self.initial_counts(net);
        loop {
            let corners = corner_values(net, n, m);
            let (error, along_u, along_v) = self.worst_error(net, n, m, &corners);
            if error <= self.tolerance || (n >= MAX_SPLIT && m >= MAX_SPLIT) {
                self.emit(net, n, m, &corners, out);
                return (n, m);
            }
            // The error falls as the square of the counts: grow the direction(s) it comes from.
            let grow = (error / self.tolerance).sqrt();
            let total = along_u + along_v;
            if along_u >= 0.3 * total || m >= MAX_SPLIT {
                n = ((n as f64 * grow).ceil() as usize)
                    .max(n + 1)
                    .min(MAX_SPLIT);
            }
            if along_v >= 0.3 * total || n >= MAX_SPLIT {
                m = ((m as f64 * grow).ceil() as usize)
                    .max(m + 1)
                    .min(MAX_SPLIT);
            }
        }
    }

    /// Counts from the bound on the bilinear error (see the module documentation).
    fn initial_counts(&self, net: &BezierNet) -> (usize, usize) {
        let centre = evaluate(net, 0.5, 0.5);
        let j = self.space.lab_jacobian(centre.colour);
        let scale = j.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
        let second = |a: VertexData, b: VertexData, c: VertexData| {
            let colour = (0..3)
                .map(|k| (a.colour[k] - 2.0 * b.colour[k] + c.colour[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            let opacity = if self.opacity {
                OPACITY_WEIGHT * (a.opacity - 2.0 * b.opacity + c.opacity).abs()
            } else {
                0.0
            };
            scale * colour + opacity
        };
        let (mut du, mut dv) = (0.0f64, 0.0f64);
        for a in 0..4 {
            for b in 0..2 {
                du = du.max(second(net[a][b], net[a][b + 1], net[a][b + 2]));
                dv = dv.max(second(net[b][a], net[b + 1][a], net[b + 2][a]));
            }
        }
        let count = |d: f64| {
            let n = (1.5 * d / (BOUND_SLACK * self.tolerance)).sqrt().ceil();
            (n as usize).clamp(1, MAX_SPLIT)
        };
        (count(du), count(dv))
    }

    /// The surface's colour in the target space and in Lab, and its opacity. Colours outside
    /// the sRGB gamut are mapped into it as the renderer maps them (chroma reduced in Oklch),
    /// rather than left for each viewer to clip.
    fn colours(&self, p: &VertexData) -> ([f64; 3], [f64; 3], f64) {
        let c = p.colour;
        let srgb = to_blend_space(self.space, c, GamutMapping::default(), BlendSpace::Srgb);
        let lab = ColourSpace::Srgb.convert(ColourSpace::Lab, srgb);
        let target = match self.target {
            Target::Lab => lab,
            Target::Srgb => srgb,
        };
        (target, lab, p.opacity)
    }

    /// The largest error over the samples of every cell, and the parts of the error along `u`
    /// and along `v` where it is largest (from the side midpoints across each direction).
    fn worst_error(
        &self,
        net: &BezierNet,
        n: usize,
        m: usize,
        corners: &[VertexData],
    ) -> (f64, f64, f64) {
        let (mut worst, mut along_u, mut along_v) = (0.0f64, 0.0f64, 0.0f64);
        let target_space = self.target.space();
        for j in 0..m {
            for i in 0..n {
                let at = |di: usize, dj: usize| self.colours(&corners[(j + dj) * (n + 1) + i + di]);
                let c = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
                for &(s, t) in &SAMPLES {
                    let u = (i as f64 + s) / n as f64;
                    let v = (j as f64 + t) / m as f64;
                    let (_, lab, alpha) = self.colours(&evaluate(net, u, v));
                    let w = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
                    let mut mix = [0.0; 3];
                    let mut mix_alpha = 0.0;
                    for k in 0..4 {
                        for ch in 0..3 {
                            mix[ch] += w[k] * c[k].0[ch];
                        }
                        mix_alpha += w[k] * c[k].2;
                    }
                    let shown = target_space.convert(ColourSpace::Lab, mix);
                    let mut e = delta_e00(shown, lab);
                    if self.opacity {
                        e = e.max(OPACITY_WEIGHT * (mix_alpha - alpha).abs());
                    }
                    worst = worst.max(e);
                    // Side midpoints vary along one direction only.
                    if t == 0.0 || t == 1.0 {
                        along_u = along_u.max(e);
                    } else if s == 0.0 || s == 1.0 {
                        along_v = along_v.max(e);
                    }
                }
            }
        }
        if along_u == 0.0 && along_v == 0.0 {
            (along_u, along_v) = (worst, worst);
        }
        (worst, along_u, along_v)
    }

    /// Appends the `n x m` cells of `net`.
    fn emit(
        &self,
        net: &BezierNet,
        n: usize,
        m: usize,
        corners: &[VertexData],
        out: &mut Vec<OutPatch>,
    ) {
        for j in 0..m {
            for i in 0..n {
                let us = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                let vs = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
                let cell = if n == 1 && m == 1 {
                    *net
                } else {
                    sub_net(net, us, vs)
                };
                let at = |di: usize, dj: usize| corners[(j + dj) * (n + 1) + i + di];
                let c = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
                out.push(OutPatch {
                    points: cell.map(|row| row.map(|p| p.position)),
                    colours: c.map(|p| self.colours(&p).0),
                    opacity: c.map(|p| p.opacity),
                });
            }
        }
    }
}

/// The surface at the corners of `n x m` equal cells, row by row (`(n + 1)` a row).
fn corner_values(net: &BezierNet, n: usize, m: usize) -> Vec<VertexData> {
    let mut out = Vec::with_capacity((n + 1) * (m + 1));
    for j in 0..=m {
        for i in 0..=n {
            out.push(evaluate(net, i as f64 / n as f64, j as f64 / m as f64));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic sequence in `0..1`.
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A net over a 40-pixel square with colours varying strongly and unevenly, inside the sRGB
    /// gamut (where the colour is as smooth as the surface; gamut mapping adds kinks).
    fn random_net(rng: &mut Lcg, space: ColourSpace) -> BezierNet {
        std::array::from_fn(|j| {
            std::array::from_fn(|i| {
                let colour = match space {
                    ColourSpace::Lab => [
                        35.0 + 30.0 * rng.next(),
                        -20.0 + 40.0 * rng.next(),
                        -20.0 + 40.0 * rng.next(),
                    ],
                    _ => [
                        0.1 + 0.8 * rng.next(),
                        0.1 + 0.8 * rng.next(),
                        0.1 + 0.8 * rng.next(),
                    ],
                };
                VertexData {
                    position: [40.0 * i as f64 / 3.0, 40.0 * j as f64 / 3.0],
                    colour,
                    opacity: 0.3 + 0.7 * rng.next(),
                }
            })
        })
    }

    /// The largest ΔE00 (or weighted opacity error) between the viewer's bilinear colour of the
    /// cells of `net` (split `n x m` into `cells`) and the surface, at random points.
    fn largest_error(
        s: &Splitter,
        net: &BezierNet,
        (n, m): (usize, usize),
        cells: &[OutPatch],
        rng: &mut Lcg,
    ) -> f64 {
        let mut worst = 0.0f64;
        for _ in 0..400 {
            let (u, v) = (rng.next(), rng.next());
            let (i, j) = (
                ((u * n as f64) as usize).min(n - 1),
                ((v * m as f64) as usize).min(m - 1),
            );
            let (s_, t) = (u * n as f64 - i as f64, v * m as f64 - j as f64);
            let cell = &cells[j * n + i];
            let w = [
                (1.0 - s_) * (1.0 - t),
                s_ * (1.0 - t),
                s_ * t,
                (1.0 - s_) * t,
            ];
            let mix: [f64; 3] =
                std::array::from_fn(|ch| (0..4).map(|k| w[k] * cell.colours[k][ch]).sum());
            let alpha: f64 = (0..4).map(|k| w[k] * cell.opacity[k]).sum();
            let truth = evaluate(net, u, v);
            let lab = s.space.convert(ColourSpace::Lab, truth.colour);
            let shown = s.target.space().convert(ColourSpace::Lab, mix);
            worst = worst
                .max(delta_e00(shown, lab))
                .max(OPACITY_WEIGHT * (alpha - truth.opacity).abs());
        }
        worst
    }

    #[test]
    fn split_patches_stay_within_the_tolerance() {
        let mut rng = Lcg(7);
        for (space, target) in [
            (ColourSpace::Lab, Target::Lab),
            (ColourSpace::Lab, Target::Srgb),
            (ColourSpace::Srgb, Target::Lab),
            (ColourSpace::Srgb, Target::Srgb),
        ] {
            let s = Splitter {
                space,
                target,
                tolerance: 0.5,
                opacity: true,
            };
            let (mut worst, mut unsplit_worst) = (0.0f64, 0.0f64);
            for _ in 0..40 {
                let net = random_net(&mut rng, space);
                let mut cells = Vec::new();
                let counts = s.split(&net, &mut cells);
                assert_eq!(cells.len(), counts.0 * counts.1);
                worst = worst.max(largest_error(&s, &net, counts, &cells, &mut rng));
                let mut one = Vec::new();
                s.emit(&net, 1, 1, &corner_values(&net, 1, 1), &mut one);
                unsplit_worst = unsplit_worst.max(largest_error(&s, &net, (1, 1), &one, &mut rng));
            }
            // Nine checked points a cell leave a little between them.
            assert!(worst <= 0.5 * 1.1, "{space:?} -> {target:?}: {worst}");
            assert!(
                unsplit_worst > 5.0,
                "{space:?}: the nets need splitting ({unsplit_worst})"
            );
        }
    }

    #[test]
    fn cells_share_their_corners_and_cover_the_patch() {
        let mut rng = Lcg(3);
        let net = random_net(&mut rng, ColourSpace::Lab);
        let s = Splitter {
            space: ColourSpace::Lab,
            target: Target::Lab,
            tolerance: 0.5,
            opacity: false,
        };
        let mut cells = Vec::new();
        let (n, m) = s.split(&net, &mut cells);
        assert!(n > 1 && m > 1);
        for j in 0..m {
            for i in 0..n {
                let c = &cells[j * n + i];
                let at = evaluate(&net, i as f64 / n as f64, j as f64 / m as f64);
                assert!(
                    (c.points[0][0][0] - at.position[0]).abs() < 1e-9
                        && (c.points[0][0][1] - at.position[1]).abs() < 1e-9
                );
                if i + 1 < n {
                    let right = &cells[j * n + i + 1];
                    for k in 0..4 {
                        let (a, b) = (c.points[k][3], right.points[k][0]);
                        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
                    }
                    assert_eq!(c.colours[1], right.colours[0]);
                }
            }
        }
    }
}
