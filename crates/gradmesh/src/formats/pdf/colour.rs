//! Colour spaces and functions of shadings: from a shading's components to sRGB.

use super::postscript::Program;
use crate::colour::{srgb_encode, ColourSpace};

/// The colour spaces a patch-mesh shading may be read in.
#[derive(Clone, Debug, PartialEq)]
pub enum PdfColourSpace {
    /// `DeviceGray` (or `ICCBased` with one component): grey in 0..1, taken as sRGB-encoded.
    Gray,
    /// `DeviceRGB` (or `CalRGB`, or `ICCBased` with three components): taken as sRGB.
    Rgb,
    /// `DeviceCMYK` (or `ICCBased` with four components), converted naively:
    /// `R = (1 - C)(1 - K)` and likewise for G with M and B with Y.
    Cmyk,
    /// `Lab` with its white point (XYZ, Y = 1): adapted to D65 by the Bradford transform
    /// when it is not D65, then converted to sRGB.
    Lab {
        /// The `WhitePoint`.
        white: [f64; 3],
    },
    /// `Indexed`: one component, an index rounded to the nearest entry of the table and
    /// clipped to it, as poppler and Ghostscript look it up.
    Indexed {
        /// The base space.
        base: Box<PdfColourSpace>,
        /// The table: one colour of the base space's components per entry, entry after entry,
        /// the bytes already mapped to the components' ranges.
        lookup: Vec<f64>,
    },
    /// `Separation` (one colourant) or `DeviceN` (several): the tints, from 0 to 1, taken
    /// through the tint transform into the alternate space.
    Tinted {
        /// The number of colourants.
        colourants: usize,
        /// The alternate space.
        alternate: Box<PdfColourSpace>,
        /// The tint transform: `colourants` inputs, the alternate space's components out.
        tint: Box<Function>,
    },
}

impl PdfColourSpace {
    /// The number of components of a colour.
    pub fn components(&self) -> usize {
        match self {
            PdfColourSpace::Gray | PdfColourSpace::Indexed { .. } => 1,
            PdfColourSpace::Rgb | PdfColourSpace::Lab { .. } => 3,
            PdfColourSpace::Cmyk => 4,
            PdfColourSpace::Tinted { colourants, .. } => *colourants,
        }
    }

    /// The sRGB colour (gamma-encoded, clipped to 0..1) of `c`.
    pub fn to_srgb(&self, c: &[f64]) -> [f64; 3] {
        let at = |k: usize| c.get(k).copied().unwrap_or(0.0);
        let unit = |x: f64| x.clamp(0.0, 1.0);
        match self {
            PdfColourSpace::Gray => [unit(at(0)); 3],
            PdfColourSpace::Rgb => [unit(at(0)), unit(at(1)), unit(at(2))],
            PdfColourSpace::Cmyk => {
                let k = unit(at(3));
                [0, 1, 2].map(|i| (1.0 - unit(at(i))) * (1.0 - k))
            }
            PdfColourSpace::Lab { white } => {
                let linear = lab_to_linear_srgb([at(0), at(1), at(2)], *white);
                linear.map(|x| srgb_encode(x.clamp(0.0, 1.0)))
            }
            PdfColourSpace::Indexed { base, lookup } => {
                let m = base.components();
                let entries = lookup.len() / m;
                let index = at(0).round().clamp(0.0, entries.saturating_sub(1) as f64) as usize;
                base.to_srgb(lookup.get(index * m..index * m + m).unwrap_or(&[]))
            }
            PdfColourSpace::Tinted {
                colourants,
                alternate,
                tint,
            } => {
                let tints: Vec<f64> = (0..*colourants).map(|k| unit(at(k))).collect();
                alternate.to_srgb(&tint.eval_inputs(&tints))
            }
        }
    }

    /// Whether the conversion to sRGB is affine, so that colour bilinear in the components is
    /// bilinear in sRGB.
    pub fn is_affine(&self) -> bool {
        matches!(self, PdfColourSpace::Gray | PdfColourSpace::Rgb)
    }
}

/// The D65 white point as the Lab space of this crate takes it.
const D65: [f64; 3] = [0.95047, 1.0, 1.08883];

/// Linear sRGB of CIE Lab relative to `white`.
fn lab_to_linear_srgb(lab: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let near_d65 = white.iter().zip(D65).all(|(a, b)| (a - b).abs() < 2e-3);
    if near_d65 {
        return ColourSpace::Lab.to_linear_srgb(lab);
    }
    let finv = |t: f64| {
        if t > 6.0 / 29.0 {
            t * t * t
        } else {
            3.0 * (6.0f64 / 29.0).powi(2) * (t - 4.0 / 29.0)
        }
    };
    let l = (lab[0] + 16.0) / 116.0;
    let xyz = [
        white[0] * finv(l + lab[1] / 500.0),
        white[1] * finv(l),
        white[2] * finv(l - lab[2] / 200.0),
    ];
    let adapted = bradford(xyz, white, D65);
    // XYZ (D65) to linear sRGB.
    const M: [[f64; 3]; 3] = [
        [3.2404542, -1.5371385, -0.4985314],
        [-0.9692660, 1.8760108, 0.0415560],
        [0.0556434, -0.2040259, 1.0572252],
    ];
    M.map(|row| row[0] * adapted[0] + row[1] * adapted[1] + row[2] * adapted[2])
}

/// `xyz` under white `from` adapted to white `to` by the Bradford transform.
fn bradford(xyz: [f64; 3], from: [f64; 3], to: [f64; 3]) -> [f64; 3] {
    const B: [[f64; 3]; 3] = [
        [0.8951, 0.2664, -0.1614],
        [-0.7502, 1.7135, 0.0367],
        [0.0389, -0.0685, 1.0296],
    ];
    const B_INV: [[f64; 3]; 3] = [
        [0.9869929, -0.1470543, 0.1599627],
        [0.4323053, 0.5183603, 0.0492912],
        [-0.0085287, 0.0400428, 0.9684867],
    ];
    let mul = |m: &[[f64; 3]; 3], v: [f64; 3]| m.map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2]);
    let (cone, cf, ct) = (mul(&B, xyz), mul(&B, from), mul(&B, to));
    let scaled = [0, 1, 2].map(|k| {
        if cf[k].abs() > 1e-12 {
            cone[k] * ct[k] / cf[k]
        } else {
            cone[k]
        }
    });
    mul(&B_INV, scaled)
}

/// A PDF function: of one input (types 2 and 3), of any number of inputs (types 0 and 4), or
/// an array of functions of one output each.
#[derive(Clone, Debug, PartialEq)]
pub enum Function {
    /// Type 0: samples over a grid of the domain, interpolated multilinearly.
    Sampled {
        /// `Domain`: a range per input.
        domain: Vec<[f64; 2]>,
        /// `Encode`: each input's range mapped to `0..size - 1`.
        encode: Vec<[f64; 2]>,
        /// `Size`: the number of samples along each input.
        size: Vec<usize>,
        /// The outputs at each point of the grid, the first input varying fastest, already
        /// decoded.
        samples: Vec<f64>,
        /// The number of outputs.
        outputs: usize,
    },
    /// Type 2: `C0 + x^N (C1 - C0)`.
    Exponential {
        /// `Domain`.
        domain: [f64; 2],
        /// `C0`.
        c0: Vec<f64>,
        /// `C1`.
        c1: Vec<f64>,
        /// `N`.
        n: f64,
    },
    /// Type 3: functions over the parts of the domain `Bounds` cut it into.
    Stitching {
        /// `Domain`.
        domain: [f64; 2],
        /// The functions, one per part.
        functions: Vec<Function>,
        /// `Bounds`.
        bounds: Vec<f64>,
        /// `Encode`, a pair per function.
        encode: Vec<[f64; 2]>,
    },
    /// An array of functions of one output each: the outputs side by side.
    Array(Vec<Function>),
    /// Type 4: a PostScript calculator program (PDF 32000-1, 7.10.5) of any number of inputs.
    PostScript {
        /// `Domain`: a range per input.
        domain: Vec<[f64; 2]>,
        /// `Range`: a range per output.
        range: Vec<[f64; 2]>,
        /// The program.
        program: Program,
    },
}

/// `x` clipped to the range `d` (whichever way round it is given).
fn clip(x: f64, d: [f64; 2]) -> f64 {
    x.clamp(d[0].min(d[1]), d[0].max(d[1]))
}

impl Function {
    /// The outputs at the inputs `inputs` (each clipped to the domain). A function of one
    /// input takes the first. A type 4 program that fails (a division by zero, say) gives each
    /// output 0 clipped to its range; programs are tried at the corners and centre of their
    /// domain when read, so that one failing there is an error instead.
    pub fn eval_inputs(&self, inputs: &[f64]) -> Vec<f64> {
        match self {
            Function::PostScript { range, .. } => self
                .try_eval(inputs)
                .unwrap_or_else(|_| range.iter().map(|&r| clip(0.0, r)).collect()),
            Function::Sampled {
                domain,
                encode,
                size,
                samples,
                outputs,
            } => {
                let grid = SampleGrid {
                    size,
                    samples,
                    outputs: *outputs,
                };
                let at: Vec<f64> = (domain.iter().zip(encode).enumerate())
                    .map(|(k, (&d, &e))| {
                        let x = clip(inputs.get(k).copied().unwrap_or(0.0), d);
                        interpolate(x, d, e).clamp(0.0, (size[k] - 1) as f64)
                    })
                    .collect();
                grid.at(&at)
            }
            Function::Array(functions) => functions
                .iter()
                .flat_map(|f| f.eval_inputs(inputs).into_iter().take(1))
                .collect(),
            _ => self.eval(inputs.first().copied().unwrap_or(0.0)),
        }
    }

    /// The outputs of a type 4 function at `inputs`, or why its program failed; other
    /// functions as [`Function::eval_inputs`] gives them.
    pub fn try_eval(&self, inputs: &[f64]) -> Result<Vec<f64>, String> {
        let Function::PostScript {
            domain,
            range,
            program,
        } = self
        else {
            return Ok(self.eval_inputs(inputs));
        };
        let clipped: Vec<f64> = (domain.iter().enumerate())
            .map(|(k, &d)| clip(inputs.get(k).copied().unwrap_or(0.0), d))
            .collect();
        let outputs = program.run(&clipped, range.len())?;
        Ok(outputs
            .iter()
            .zip(range)
            .map(|(&y, &r)| clip(y, r))
            .collect())
    }

    /// The outputs at `x` (clipped to the domain), for a function of one input.
    pub fn eval(&self, x: f64) -> Vec<f64> {
        match self {
            Function::Sampled { .. } | Function::PostScript { .. } => self.eval_inputs(&[x]),
            Function::Exponential { domain, c0, c1, n } => {
                let x = clip(x, *domain);
                let p = if *n == 1.0 { x } else { x.max(0.0).powf(*n) };
                c0.iter().zip(c1).map(|(a, b)| a + p * (b - a)).collect()
            }
            Function::Stitching {
                domain,
                functions,
                bounds,
                encode,
            } => {
                let x = clip(x, *domain);
                let k = bounds.iter().take_while(|&&b| x >= b).count();
                let k = k.min(functions.len() - 1);
                let lo = if k == 0 { domain[0] } else { bounds[k - 1] };
                let hi = if k == bounds.len() {
                    domain[1]
                } else {
                    bounds[k]
                };
                functions[k].eval(interpolate(x, [lo, hi], encode[k]))
            }
            Function::Array(functions) => functions
                .iter()
                .flat_map(|f| f.eval(x).into_iter().take(1))
                .collect(),
        }
    }
}

/// `x` mapped from the range `from` to the range `to` (to `to[0]` when `from` is empty).
fn interpolate(x: f64, from: [f64; 2], to: [f64; 2]) -> f64 {
    if from[1] == from[0] {
        to[0]
    } else {
        to[0] + (x - from[0]) * (to[1] - to[0]) / (from[1] - from[0])
    }
}

/// The samples of a type 0 function on their grid.
struct SampleGrid<'a> {
    size: &'a [usize],
    samples: &'a [f64],
    outputs: usize,
}

impl SampleGrid<'_> {
    /// The outputs at the grid position `at` (an index from 0 to `size - 1` along each
    /// input), multilinear between the samples around it: the sum over the corners of the
    /// cell of each corner's outputs times the product of its weights along each input.
    fn at(&self, at: &[f64]) -> Vec<f64> {
        // Along each input: the lower sample, the step to the upper one, and the weight of the upper.
        let mut stride = 1;
        let mut base = 0;
        let mut varying: Vec<(usize, f64)> = Vec::new();
        for (k, &e) in at.iter().enumerate() {
            let lower = (e.floor() as usize).min(self.size[k] - 1);
            let t = e - lower as f64;
            base += lower * stride;
            if t > 0.0 && lower + 1 < self.size[k] {
                varying.push((stride, t));
            }
            stride *= self.size[k];
        }
        let mut out = vec![0.0; self.outputs];
        for corner in 0u32..(1 << varying.len()) {
            let (mut index, mut weight) = (base, 1.0);
            for (bit, &(step, t)) in varying.iter().enumerate() {
                if (corner >> bit) & 1 == 1 {
                    index += step;
                    weight *= t;
                } else {
                    weight *= 1.0 - t;
                }
            }
            let row = &self.samples[index * self.outputs..(index + 1) * self.outputs];
            for (o, s) in out.iter_mut().zip(row) {
                *o += weight * s;
            }
        }
        out
    }
}

/// How a shading's corner components become colours: its colour space, and the function of
/// the parametric value when it has one.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadingColour {
    /// The `ColorSpace`.
    pub space: PdfColourSpace,
    /// The `Function`: each corner then has one parametric value `t`.
    pub function: Option<Function>,
}

impl ShadingColour {
    /// The number of components each corner carries.
    pub fn corner_components(&self) -> usize {
        match self.function {
            Some(_) => 1,
            None => self.space.components(),
        }
    }

    /// The sRGB colour (gamma-encoded, 0..1) of the corner components `c`.
    pub fn to_srgb(&self, c: &[f64]) -> [f64; 3] {
        match &self.function {
            Some(f) => self
                .space
                .to_srgb(&f.eval(c.first().copied().unwrap_or(0.0))),
            None => self.space.to_srgb(c),
        }
    }

    /// Whether colour bilinear in the components is bilinear in sRGB.
    pub fn is_affine(&self) -> bool {
        self.function.is_none() && self.space.is_affine()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn naive_cmyk_and_grey() {
        let cmyk = PdfColourSpace::Cmyk;
        assert_eq!(cmyk.to_srgb(&[1.0, 0.0, 0.0, 0.0]), [0.0, 1.0, 1.0]);
        assert_eq!(cmyk.to_srgb(&[0.0, 0.0, 0.0, 0.5]), [0.5, 0.5, 0.5]);
        assert_eq!(PdfColourSpace::Gray.to_srgb(&[0.25]), [0.25; 3]);
    }

    /// Lab under D50 white is adapted: its white is sRGB white, as D65 white is.
    #[test]
    fn lab_white_points() {
        let d50 = PdfColourSpace::Lab {
            white: [0.9642, 1.0, 0.8249],
        };
        let d65 = PdfColourSpace::Lab { white: D65 };
        for space in [d50, d65] {
            let white = space.to_srgb(&[100.0, 0.0, 0.0]);
            assert!(white.iter().all(|&c| (c - 1.0).abs() < 2e-3), "{white:?}");
            let grey = space.to_srgb(&[50.0, 0.0, 0.0]);
            assert!((grey[0] - grey[2]).abs() < 2e-3, "{grey:?}");
        }
    }

    #[test]
    fn stitched_exponential_functions() {
        let red_green = Function::Exponential {
            domain: [0.0, 1.0],
            c0: vec![1.0, 0.0, 0.0],
            c1: vec![0.0, 1.0, 0.0],
            n: 1.0,
        };
        let green_blue = Function::Exponential {
            domain: [0.0, 1.0],
            c0: vec![0.0, 1.0, 0.0],
            c1: vec![0.0, 0.0, 1.0],
            n: 1.0,
        };
        let f = Function::Stitching {
            domain: [0.0, 1.0],
            functions: vec![red_green, green_blue],
            bounds: vec![0.5],
            encode: vec![[0.0, 1.0], [0.0, 1.0]],
        };
        assert_eq!(f.eval(0.25), vec![0.5, 0.5, 0.0]);
        assert_eq!(f.eval(0.75), vec![0.0, 0.5, 0.5]);
        assert_eq!(f.eval(2.0), vec![0.0, 0.0, 1.0]);
    }
}
