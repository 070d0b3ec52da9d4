//! Working colour spaces, conversion to and from sRGB, and CSS colour strings.

pub(crate) mod fast;
pub(crate) mod gamut;

use palette::convert::FromColorUnclamped;
use palette::{white_point::D65, Lab, LinSrgb, Oklab};

/// The space in which a mesh's colours are given and interpolated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ColourSpace {
    /// CIE L*a*b* with the D65 white point, L in 0..100 (the default, as in the paper).
    #[default]
    Lab,
    /// Oklab, L in 0..1.
    Oklab,
    /// Linear-light sRGB, channels in 0..1.
    SrgbLinear,
    /// Non-linear (gamma-encoded) sRGB, channels in 0..1.
    Srgb,
}

impl ColourSpace {
    /// Every space, in the order of the documentation.
    pub const ALL: [ColourSpace; 4] = [
        ColourSpace::Lab,
        ColourSpace::Oklab,
        ColourSpace::SrgbLinear,
        ColourSpace::Srgb,
    ];

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ColourSpace::Lab => "lab",
            ColourSpace::Oklab => "oklab",
            ColourSpace::SrgbLinear => "srgb-linear",
            ColourSpace::Srgb => "srgb",
        }
    }

    /// The space with the given name.
    pub fn from_name(name: &str) -> Option<ColourSpace> {
        ColourSpace::ALL.into_iter().find(|s| s.name() == name)
    }

    /// Converts coordinates in this space to linear-light sRGB, without any gamut mapping: the
    /// result may lie outside 0..1.
    pub fn to_linear_srgb(self, c: [f64; 3]) -> [f64; 3] {
        let lin: LinSrgb<f64> = match self {
            ColourSpace::Lab => {
                LinSrgb::from_color_unclamped(Lab::<D65, f64>::new(c[0], c[1], c[2]))
            }
            ColourSpace::Oklab => {
                LinSrgb::from_color_unclamped(Oklab::<f64>::new(c[0], c[1], c[2]))
            }
            ColourSpace::SrgbLinear => return c,
            ColourSpace::Srgb => return [srgb_decode(c[0]), srgb_decode(c[1]), srgb_decode(c[2])],
        };
        [lin.red, lin.green, lin.blue]
    }

    /// Converts linear-light sRGB (any range) to coordinates in this space.
    pub fn from_linear_srgb(self, rgb: [f64; 3]) -> [f64; 3] {
        let lin = LinSrgb::<f64>::new(rgb[0], rgb[1], rgb[2]);
        match self {
            ColourSpace::Lab => {
                let lab = Lab::<D65, f64>::from_color_unclamped(lin);
                [lab.l, lab.a, lab.b]
            }
            ColourSpace::Oklab => {
                let ok = Oklab::<f64>::from_color_unclamped(lin);
                [ok.l, ok.a, ok.b]
            }
            ColourSpace::SrgbLinear => rgb,
            ColourSpace::Srgb => [
                srgb_encode(rgb[0]),
                srgb_encode(rgb[1]),
                srgb_encode(rgb[2]),
            ],
        }
    }

    /// Converts coordinates from `self` to `other`.
    pub fn convert(self, other: ColourSpace, c: [f64; 3]) -> [f64; 3] {
        if self == other {
            c
        } else {
            other.from_linear_srgb(self.to_linear_srgb(c))
        }
    }

    /// Whether the colour lies inside the sRGB gamut (with a small tolerance for rounding).
    pub fn in_srgb_gamut(self, c: [f64; 3]) -> bool {
        const TOLERANCE: f64 = 1e-4;
        self.to_linear_srgb(c)
            .iter()
            .all(|&v| (-TOLERANCE..=1.0 + TOLERANCE).contains(&v))
    }
}

/// A 3x3 matrix, rows first.
pub type Matrix3 = [[f64; 3]; 3];

impl ColourSpace {
    /// The derivative of the map from this space to CIE Lab at `c`: a small difference `d` of
    /// colours near `c` is about `J d` in Lab. Renderers use it to measure colour errors in Lab
    /// units for a price of one conversion per sample instead of two per comparison. The power
    /// functions inside are tabulated: entries agree with the exact derivative to about 1e-4
    /// relative.
    pub fn lab_jacobian(self, c: [f64; 3]) -> Matrix3 {
        match self {
            ColourSpace::Lab => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ColourSpace::Oklab => Self::oklab_to_lab_jacobian(c),
            ColourSpace::SrgbLinear => linear_srgb_to_lab_jacobian(c),
            ColourSpace::Srgb => {
                // Loops, not `array::map`: with closures these stayed chains of calls, and the
                // renderer asks for a Jacobian per sample.
                let decode = &tables().decode;
                let (mut lin, mut slope) = ([0.0; 3], [0.0; 3]);
                for k in 0..3 {
                    lin[k] = decode.at(c[k]).unwrap_or_else(|| srgb_decode(c[k]));
                    slope[k] = srgb_decode_slope(c[k]);
                }
                let mut j = linear_srgb_to_lab_jacobian(lin);
                for row in &mut j {
                    for k in 0..3 {
                        row[k] *= slope[k];
                    }
                }
                j
            }
        }
    }

    /// Oklab has no closed form in Lab worth the trouble: forward differences, with a step
    /// far below the differences being measured and far above rounding.
    fn oklab_to_lab_jacobian(c: [f64; 3]) -> Matrix3 {
        const H: f64 = 1e-6;
        let at = ColourSpace::Oklab.convert(ColourSpace::Lab, c);
        let mut j = [[0.0; 3]; 3];
        for k in 0..3 {
            let mut ck = c;
            ck[k] += H;
            let moved = ColourSpace::Oklab.convert(ColourSpace::Lab, ck);
            for i in 0..3 {
                j[i][k] = (moved[i] - at[i]) / H;
            }
        }
        j
    }
}

/// The derivative of the sRGB decoding function (symmetric, as [`srgb_decode`]).
fn srgb_decode_slope(encoded: f64) -> f64 {
    let a = encoded.abs();
    if a <= 0.040_45 {
        1.0 / 12.92
    } else {
        tables()
            .decode_slope
            .at(a)
            .unwrap_or_else(|| 2.4 / 1.055 * ((a + 0.055) / 1.055).powf(1.4))
    }
}

/// A smooth function sampled on a uniform grid and interpolated linearly: the derivatives
/// below are only used to weigh small colour differences, where a relative error of 1e-4
/// does not matter and `pow` and `cbrt` cost more than the rest of the measure.
struct Table {
    lo: f64,
    /// Samples per unit of `x`: a multiplication per look-up rather than a division.
    per_unit: f64,
    values: Vec<f64>,
}

impl Table {
    const SAMPLES: usize = 4096;

    fn new(lo: f64, hi: f64, f: impl Fn(f64) -> f64) -> Table {
        let step = (hi - lo) / Self::SAMPLES as f64;
        Table {
            lo,
            per_unit: 1.0 / step,
            values: (0..=Self::SAMPLES)
                .map(|k| f(lo + k as f64 * step))
                .collect(),
        }
    }

    /// The interpolated value at `x`, or `None` outside the table.
    #[inline]
    fn at(&self, x: f64) -> Option<f64> {
        let u = (x - self.lo) * self.per_unit;
        if !(0.0..Self::SAMPLES as f64).contains(&u) {
            return None;
        }
        // Through `i32`: a float to `usize` conversion takes a dozen instructions on x86-64.
        let k = u as i32 as usize;
        let t = u - k as f64;
        Some(self.values[k] + t * (self.values[k + 1] - self.values[k]))
    }
}

struct Tables {
    /// sRGB decoding above its linear segment.
    decode: Table,
    /// Its derivative.
    decode_slope: Table,
    /// The derivative of the Lab function above its linear segment.
    lab_slope: Table,
}

fn tables() -> &'static Tables {
    static TABLES: std::sync::OnceLock<Tables> = std::sync::OnceLock::new();
    TABLES.get_or_init(|| Tables {
        decode: Table::new(0.040_45, 1.0, srgb_decode),
        decode_slope: Table::new(0.040_45, 1.0, |a| {
            2.4 / 1.055 * ((a + 0.055) / 1.055).powf(1.4)
        }),
        lab_slope: Table::new(LAB_DELTA.powi(3), 1.0, lab_slope_exact),
    })
}

/// `delta` of the Lab function: it is linear below `delta^3`.
const LAB_DELTA: f64 = 6.0 / 29.0;

/// The derivative of the Lab function `t^(1/3)` above `delta^3`.
fn lab_slope_exact(t: f64) -> f64 {
    let r = t.cbrt();
    1.0 / (3.0 * r * r)
}

/// The derivative of linear sRGB to CIE Lab (D65) at `rgb`. Lab is `A f(N rgb) + b` with `N`
/// the linear map to white-relative XYZ and `f` the Lab function applied per channel, so the
/// derivative is `A diag(f'(N rgb)) N`. `N` is read off `palette`'s own conversion (on colours
/// so dark that `f` is affine there), so the two agree.
fn linear_srgb_to_lab_jacobian(rgb: [f64; 3]) -> Matrix3 {
    const DELTA: f64 = LAB_DELTA;
    static N: std::sync::OnceLock<Matrix3> = std::sync::OnceLock::new();
    let n = N.get_or_init(|| {
        // In the affine part, fy = (L + 16) / 116, fx = fy + a / 500, fz = fy - b / 200, and
        // t = 3 delta^2 (f - 4 / 29).
        let eps = 1e-4;
        let t_of = |lab: [f64; 3]| {
            let fy = (lab[0] + 16.0) / 116.0;
            let f = [fy + lab[1] / 500.0, fy, fy - lab[2] / 200.0];
            f.map(|f| 3.0 * DELTA * DELTA * (f - 4.0 / 29.0))
        };
        let mut n = [[0.0; 3]; 3];
        for k in 0..3 {
            let mut probe = [0.0; 3];
            probe[k] = eps;
            let t = t_of(ColourSpace::Lab.from_linear_srgb(probe));
            for i in 0..3 {
                n[i][k] = t[i] / eps;
            }
        }
        n
    });
    // Loops rather than `array::map` (see `lab_jacobian`).
    let lab_slope = &tables().lab_slope;
    let mut slope = [0.0; 3];
    for i in 0..3 {
        let t = n[i][0] * rgb[0] + n[i][1] * rgb[1] + n[i][2] * rgb[2];
        slope[i] = if t > DELTA * DELTA * DELTA {
            lab_slope.at(t).unwrap_or_else(|| lab_slope_exact(t))
        } else {
            1.0 / (3.0 * DELTA * DELTA)
        };
    }
    // Rows of A: L = 116 fy - 16, a = 500 (fx - fy), b = 200 (fy - fz).
    let a = [
        [0.0, 116.0, 0.0],
        [500.0, -500.0, 0.0],
        [0.0, 200.0, -200.0],
    ];
    let mut j = [[0.0; 3]; 3];
    for i in 0..3 {
        for k in 0..3 {
            j[i][k] = a[i][0] * slope[0] * n[0][k]
                + a[i][1] * slope[1] * n[1][k]
                + a[i][2] * slope[2] * n[2][k];
        }
    }
    j
}

/// The sRGB transfer function (encoding), extended to negative values by symmetry.
pub fn srgb_encode(linear: f64) -> f64 {
    let a = linear.abs();
    let e = if a <= 0.003_130_8 {
        12.92 * a
    } else {
        1.055 * a.powf(1.0 / 2.4) - 0.055
    };
    e.copysign(linear)
}

/// The inverse sRGB transfer function (decoding), extended to negative values by symmetry.
pub fn srgb_decode(encoded: f64) -> f64 {
    let a = encoded.abs();
    let l = if a <= 0.040_45 {
        a / 12.92
    } else {
        ((a + 0.055) / 1.055).powf(2.4)
    };
    l.copysign(encoded)
}

/// Parses a CSS Color 4 string (`#ff8800`, `rgb(...)`, `lab(...)`, `oklch(...)`, a named colour)
/// into coordinates of `space` and an opacity.
///
/// CSS `lab()` is defined with the D50 white point; it is converted to this crate's D65 Lab like
/// any other CSS colour.
pub fn parse_css_colour(text: &str, space: ColourSpace) -> Result<([f64; 3], f64), String> {
    let c = csscolorparser::parse(text).map_err(|e| e.to_string())?;
    let [r, g, b, a] = c.to_linear_rgba();
    let coords = space.from_linear_srgb([r as f64, g as f64, b as f64]);
    Ok((coords, a as f64))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_jacobian_matches_differences() {
        let samples = [
            [0.2, 0.5, 0.8],
            [0.9, 0.1, 0.4],
            [0.01, 0.02, 0.015],
            [-0.05, 0.5, 1.1],
        ];
        for space in ColourSpace::ALL {
            for rgb in samples {
                let c = space.from_linear_srgb(rgb);
                let j = space.lab_jacobian(c);
                for k in 0..3 {
                    // Central differences, a step of about 1e-5 of the space's range.
                    let h = if space == ColourSpace::Lab {
                        1e-3
                    } else {
                        1e-5
                    };
                    let (mut up, mut down) = (c, c);
                    up[k] += h;
                    down[k] -= h;
                    let up = space.convert(ColourSpace::Lab, up);
                    let down = space.convert(ColourSpace::Lab, down);
                    for i in 0..3 {
                        let diff = (up[i] - down[i]) / (2.0 * h);
                        let tol = 1e-3 * (1.0 + diff.abs());
                        assert!(
                            (diff - j[i][k]).abs() < tol,
                            "{space:?} at {c:?}: J[{i}][{k}] = {} but differences give {diff}",
                            j[i][k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn lab_white_is_srgb_white() {
        let rgb = ColourSpace::Lab.to_linear_srgb([100.0, 0.0, 0.0]);
        for v in rgb {
            assert!((v - 1.0).abs() < 1e-3, "{rgb:?}");
        }
    }

    #[test]
    fn round_trips_through_linear_srgb() {
        for space in ColourSpace::ALL {
            let c = space.from_linear_srgb([0.2, 0.5, 0.7]);
            let back = space.to_linear_srgb(c);
            for (x, y) in back.iter().zip([0.2, 0.5, 0.7]) {
                assert!((x - y).abs() < 1e-6, "{space:?}: {back:?}");
            }
        }
    }

    #[test]
    fn conversions_do_not_clamp() {
        // A Lab colour far outside sRGB converts to linear values outside 0..1 and back
        // (palette's matrices are not exact inverses: about 1e-6 relative).
        let lab = [50.0, 150.0, 0.0];
        assert!(!ColourSpace::Lab.in_srgb_gamut(lab));
        let back =
            ColourSpace::SrgbLinear.convert(ColourSpace::Lab, ColourSpace::Lab.to_linear_srgb(lab));
        for (x, y) in back.iter().zip(lab) {
            assert!((x - y).abs() < 1e-3, "{back:?}");
        }
    }

    #[test]
    fn parses_css_strings() {
        let (c, a) = parse_css_colour("#ff0000", ColourSpace::Srgb).unwrap();
        assert!((c[0] - 1.0).abs() < 1e-6 && c[1].abs() < 1e-6 && c[2].abs() < 1e-6);
        assert_eq!(a, 1.0);
        let (lab, _) = parse_css_colour("white", ColourSpace::Lab).unwrap();
        assert!((lab[0] - 100.0).abs() < 1e-2, "{lab:?}");
        assert!(parse_css_colour("oklch(70% 0.1 200)", ColourSpace::Oklab).is_ok());
        assert!(parse_css_colour("not a colour", ColourSpace::Lab).is_err());
    }

    #[test]
    fn transfer_function_is_odd_and_invertible() {
        for x in [-0.5, -0.001, 0.0, 0.002, 0.3, 1.0, 1.2] {
            assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-12);
        }
    }
}
