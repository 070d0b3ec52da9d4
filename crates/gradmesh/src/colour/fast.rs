//! Fast forms of the colour conversions the renderer runs per pixel: Lab to linear sRGB with
//! a precomputed matrix (double and single precision), the sRGB transfer function by tables,
//! and Oklab conversions over lanes of colours. Each is checked against the exact conversion of
//! the parent module ([`ColourSpace::to_linear_srgb`], [`srgb_encode`]) in the tests below.

use super::{srgb_encode, ColourSpace};

/// The matrix of [`lab_to_linear_srgb`], rounded to single precision.
pub(crate) fn lab_matrix_f32() -> &'static [[f32; 3]; 3] {
    static MATRIX: std::sync::OnceLock<[[f32; 3]; 3]> = std::sync::OnceLock::new();
    MATRIX.get_or_init(|| lab_matrix().map(|row| row.map(|v| v as f32)))
}

/// [`lab_to_linear_srgb`] in single precision, with the matrix `m` of [`lab_matrix_f32`].
/// Without branches (both pieces of the inverse Lab function are computed, and one chosen),
/// so that a loop over many colours vectorises.
#[inline(always)]
pub(crate) fn lab_to_linear_srgb_f32(m: &[[f32; 3]; 3], c: [f32; 3]) -> [f32; 3] {
    // Products by reciprocals: a rounding apart from the quotients, a division's time less.
    let fy = (c[0] + 16.0) * (1.0 / 116.0);
    let fx = fy + c[1] * (1.0 / 500.0);
    let fz = fy - c[2] * (1.0 / 200.0);
    let finv = |t: f32| {
        let cube = t * t * t;
        let linear = 3.0 * (6.0f32 / 29.0) * (6.0f32 / 29.0) * (t - 4.0 / 29.0);
        if t > 6.0 / 29.0 {
            cube
        } else {
            linear
        }
    };
    let (x, y, z) = (finv(fx), finv(fy), finv(fz));
    let row = |r: &[f32; 3]| r[0] * x + r[1] * y + r[2] * z;
    [row(&m[0]), row(&m[1]), row(&m[2])]
}

/// CIE Lab (D65) to linear-light sRGB, specialised: the inverse of the Lab function, then the
/// linear map from the reference white's XYZ to linear sRGB. The map's matrix and the white are
/// taken from `palette` (the converter of [`ColourSpace::to_linear_srgb`]), so the two agree to
/// rounding.
pub(crate) fn lab_to_linear_srgb(c: [f64; 3]) -> [f64; 3] {
    let m = lab_matrix();
    let fy = (c[0] + 16.0) / 116.0;
    let fx = fy + c[1] / 500.0;
    let fz = fy - c[2] / 200.0;
    let finv = |t: f64| {
        if t > 6.0 / 29.0 {
            t * t * t
        } else {
            3.0 * (6.0f64 / 29.0).powi(2) * (t - 4.0 / 29.0)
        }
    };
    let (x, y, z) = (finv(fx), finv(fy), finv(fz));
    let row = |r: &[f64; 3]| r[0] * x + r[1] * y + r[2] * z;
    [row(&m[0]), row(&m[1]), row(&m[2])]
}

/// The linear map from the factors (X / Xn, Y, Z / Zn) of CIE Lab to linear sRGB.
fn lab_matrix() -> &'static [[f64; 3]; 3] {
    static MATRIX: std::sync::OnceLock<[[f64; 3]; 3]> = std::sync::OnceLock::new();
    MATRIX.get_or_init(|| {
        // The map from the three factors (X / Xn, Y, Z / Zn) to linear sRGB is linear: probe
        // it with Lab colours whose factors lie in the linear part of the inverse Lab function.
        let probe = |f: [f64; 3]| -> [f64; 3] {
            let t = |f: f64| f / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0;
            let (tx, ty, tz) = (t(f[0]), t(f[1]), t(f[2]));
            let (l, a, b) = (116.0 * ty - 16.0, 500.0 * (tx - ty), 200.0 * (ty - tz));
            ColourSpace::Lab.to_linear_srgb([l, a, b])
        };
        let eps = 1e-3;
        let cols = [
            probe([eps, 0.0, 0.0]),
            probe([0.0, eps, 0.0]),
            probe([0.0, 0.0, eps]),
        ];
        let mut m = [[0.0; 3]; 3];
        for (j, col) in cols.iter().enumerate() {
            for i in 0..3 {
                m[i][j] = col[i] / eps;
            }
        }
        m
    })
}

/// Octaves of the encoding table: linear values from `2^-ENCODE_OCTAVES` to 1.
const ENCODE_OCTAVES: u32 = 9;
/// Table entries per octave (a power of two).
const ENCODE_STEPS: u32 = 1 << 10;

/// [`srgb_encode`] at the start of every one of `steps` steps per octave of the table's
/// octaves, and 1 at the end.
fn encode_samples(steps: u32) -> impl Iterator<Item = f64> {
    (0..=ENCODE_OCTAVES * steps).map(move |i| {
        let octave = (i / steps) as i32 - ENCODE_OCTAVES as i32;
        let m = 1.0 + (i % steps) as f64 / steps as f64;
        srgb_encode(m * 2f64.powi(octave))
    })
}

/// The table of [`srgb_encode_fast`].
fn encode_table() -> &'static [f64] {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| encode_samples(ENCODE_STEPS).collect())
}

/// [`srgb_encode`] by a table with linear interpolation within each of 1024 steps per octave
/// (relative error under 1e-7, far below a 16-bit step) for values in `[2^-9, 1)`; exact
/// elsewhere (the linear segment, which ends at 0.0031308 > 2^-9, and out-of-range values).
pub(crate) fn srgb_encode_fast(linear: f64) -> f64 {
    let lo = 1.0 / (1u32 << ENCODE_OCTAVES) as f64;
    if !(lo..1.0).contains(&linear) || linear <= 0.003_130_8 {
        return srgb_encode(linear);
    }
    // Within octave [2^e, 2^(e+1)) the value is linear in the mantissa.
    let bits = linear.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mantissa = bits & ((1u64 << 52) - 1);
    let shift = 52 - ENCODE_STEPS.trailing_zeros();
    let step = (mantissa >> shift) as usize;
    let frac = (mantissa & ((1u64 << shift) - 1)) as f64 / (1u64 << shift) as f64;
    let i = (exponent + ENCODE_OCTAVES as i64) as usize * ENCODE_STEPS as usize + step;
    let t = encode_table();
    t[i] + frac * (t[i + 1] - t[i])
}

/// Table entries per octave of [`srgb_encode_f32`]'s table: 9 octaves of 256 fit a 9 KB
/// table in the first-level cache.
const ENCODE_STEPS_F32: u32 = 1 << 8;

/// Entries of the table of [`srgb_encode_f32`].
pub(crate) const ENCODE_TABLE_F32_LEN: usize = (ENCODE_OCTAVES * ENCODE_STEPS_F32) as usize + 1;

/// The table of [`srgb_encode_f32`]. Of fixed size, so that indices clamped to it need no
/// bounds check, which would keep a loop over many values from vectorising.
pub(crate) fn encode_table_f32() -> &'static [f32; ENCODE_TABLE_F32_LEN] {
    static TABLE: std::sync::OnceLock<[f32; ENCODE_TABLE_F32_LEN]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut table = [0.0; ENCODE_TABLE_F32_LEN];
        for (t, v) in table.iter_mut().zip(encode_samples(ENCODE_STEPS_F32)) {
            *t = v as f32;
        }
        table
    })
}

/// [`srgb_encode`] in single precision: a table with linear interpolation within each of 256
/// steps per octave for values in `[2^-9, 1)` (error under 1e-6, a fifteenth of a 16-bit
/// step), the linear segment below, and [`srgb_encode`] outside `0..=1`.
#[inline]
pub(crate) fn srgb_encode_f32(linear: f32) -> f32 {
    srgb_encode_f32_with(encode_table_f32(), linear)
}

/// [`srgb_encode_f32`] with its `table` ([`encode_table_f32`]) at hand.
#[inline(always)]
pub(crate) fn srgb_encode_f32_with(table: &[f32], linear: f32) -> f32 {
    // Written so that NaN takes this branch too (and comes back NaN): the table has no row
    // for it.
    if !(linear > 0.003_130_8 && linear < 1.0) {
        return if (0.0..=1.0).contains(&linear) {
            if linear == 1.0 {
                1.0
            } else {
                12.92 * linear
            }
        } else {
            srgb_encode(linear as f64) as f32
        };
    }
    let (i, frac) = table_position(linear);
    let i = i as usize;
    table[i] + frac * (table[i + 1] - table[i])
}

/// Where `linear` falls in the table of [`srgb_encode_f32`]: the index of the entry at or
/// below it (meaningful for values in `[2^-9, 1)`) and the fraction of the way to the next.
/// Within octave `[2^e, 2^(e+1))` the value is linear in the mantissa; 0.0031308 > 2^-9.
#[inline(always)]
fn table_position(linear: f32) -> (i32, f32) {
    let bits = linear.to_bits();
    let exponent = ((bits >> 23) & 0xff) as i32 - 127;
    let mantissa = bits & ((1 << 23) - 1);
    let shift = 23 - ENCODE_STEPS_F32.trailing_zeros();
    let step = (mantissa >> shift) as i32;
    let frac = (mantissa & ((1 << shift) - 1)) as f32 / (1u32 << shift) as f32;
    (
        (exponent + ENCODE_OCTAVES as i32) * ENCODE_STEPS_F32 as i32 + step,
        frac,
    )
}

/// [`srgb_encode_f32_with`] of a value in `0..=1`, bit for bit, without branches: both
/// pieces are computed and one chosen, and the table index is clamped (for values outside
/// `0..=1` the result is meaningless, but nothing panics), so that a loop over many values
/// vectorises (the table reads stay scalar loads).
#[inline(always)]
pub(crate) fn srgb_encode_unit_f32(table: &[f32; ENCODE_TABLE_F32_LEN], linear: f32) -> f32 {
    let (i, frac) = table_position(linear);
    let i = i.clamp(0, ENCODE_TABLE_F32_LEN as i32 - 2) as usize;
    let tabled = table[i] + frac * (table[i + 1] - table[i]);
    let low = 12.92 * linear;
    if linear <= 0.003_130_8 {
        low
    } else if linear >= 1.0 {
        1.0
    } else {
        tabled
    }
}

/// Linear-light sRGB to Oklab (Ottosson 2020), lane by lane; channels outermost.
#[inline(always)]
pub(crate) fn linear_srgb_to_oklab_lanes<const N: usize>(c: &[[f64; N]; 3]) -> [[f64; N]; 3] {
    const TO_LMS: [[f64; 3]; 3] = [
        [0.412_221_470_8, 0.536_332_536_3, 0.051_445_992_9],
        [0.211_903_498_2, 0.680_699_545_1, 0.107_396_956_6],
        [0.088_302_461_9, 0.281_718_837_6, 0.629_978_700_5],
    ];
    let mut lms = [[0.0; N]; 3];
    for (row, w) in lms.iter_mut().zip(TO_LMS) {
        for i in 0..N {
            row[i] = w[0] * c[0][i] + w[1] * c[1][i] + w[2] * c[2][i];
        }
    }
    let [l, m, s] = cube_root_lanes(lms);
    let mut out = [[0.0; N]; 3];
    for i in 0..N {
        out[0][i] = 0.210_454_255_3 * l[i] + 0.793_617_785_0 * m[i] - 0.004_072_046_8 * s[i];
        out[1][i] = 1.977_998_495_1 * l[i] - 2.428_592_205_0 * m[i] + 0.450_593_709_9 * s[i];
        out[2][i] = 0.025_904_037_1 * l[i] + 0.782_771_766_2 * m[i] - 0.808_675_766_0 * s[i];
    }
    out
}

/// The real cube root of each lane, to within a few units in the last place. `f64::cbrt` is
/// correctly rounded but, on baseline x86-64 (no fused multiply-add instruction), emulates
/// `fma` in software: it was two thirds of drawing an image with many colours outside the
/// gamut, whose chroma search takes about 36 cube roots per pixel.
#[inline(always)]
pub(crate) fn cube_root_lanes<const N: usize, const M: usize>(x: [[f64; N]; M]) -> [[f64; N]; M] {
    // A first guess within a few percent from the exponent (a third of it, by integer
    // division of the bits), then Halley's iteration, which triples the correct digits.
    let mut a = [[1.0; N]; M];
    let mut y = [[0.0; N]; M];
    let mut irregular = false;
    for j in 0..M {
        for i in 0..N {
            let v = x[j][i].abs();
            irregular |= !v.is_normal();
            if v.is_normal() {
                a[j][i] = v;
            }
            y[j][i] = f64::from_bits(a[j][i].to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
        }
    }
    for _ in 0..3 {
        for j in 0..M {
            for i in 0..N {
                let y3 = y[j][i] * y[j][i] * y[j][i];
                y[j][i] *= (y3 + 2.0 * a[j][i]) / (2.0 * y3 + a[j][i]);
            }
        }
    }
    for j in 0..M {
        for i in 0..N {
            y[j][i] = y[j][i].copysign(x[j][i]);
        }
    }
    if irregular {
        // Zero, subnormal, infinite or NaN: rare, and the library has the edge cases right.
        for j in 0..M {
            for i in 0..N {
                if !x[j][i].abs().is_normal() {
                    y[j][i] = x[j][i].cbrt();
                }
            }
        }
    }
    y
}

/// Oklab to linear-light sRGB, lane by lane; channels outermost.
#[inline(always)]
pub(crate) fn oklab_to_linear_srgb_lanes<const N: usize>(c: &[[f64; N]; 3]) -> [[f64; N]; 3] {
    let mut out = [[0.0; N]; 3];
    for i in 0..N {
        let (ll, a, b) = (c[0][i], c[1][i], c[2][i]);
        let l = ll + 0.396_337_777_4 * a + 0.215_803_757_3 * b;
        let m = ll - 0.105_561_345_8 * a - 0.063_854_172_8 * b;
        let s = ll - 0.089_484_177_5 * a - 1.291_485_548_0 * b;
        let (l, m, s) = (l * l * l, m * m * m, s * s * s);
        out[0][i] = 4.076_741_662_1 * l - 3.307_711_591_3 * m + 0.230_969_929_2 * s;
        out[1][i] = -1.268_438_004_6 * l + 2.609_757_401_1 * m - 0.341_319_396_5 * s;
        out[2][i] = -0.004_196_086_3 * l - 0.703_418_614_7 * m + 1.707_614_701_0 * s;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Linear-light sRGB to Oklab (Ottosson 2020).
    fn linear_srgb_to_oklab(c: [f64; 3]) -> [f64; 3] {
        linear_srgb_to_oklab_lanes(&c.map(|v| [v])).map(|[v]| v)
    }

    /// Oklab to linear-light sRGB.
    fn oklab_to_linear_srgb(c: [f64; 3]) -> [f64; 3] {
        oklab_to_linear_srgb_lanes(&c.map(|v| [v])).map(|[v]| v)
    }

    /// The real cube root, to within a few units in the last place.
    fn cube_root(x: f64) -> f64 {
        cube_root_lanes([[x]])[0][0]
    }

    #[test]
    fn lab_conversion_matches_palette() {
        let mut worst = 0.0f64;
        for l in (0..=20).map(|k| k as f64 * 5.0) {
            for a in (-8..=8).map(|k| k as f64 * 15.0) {
                for b in (-8..=8).map(|k| k as f64 * 15.0) {
                    let (x, y) = (
                        lab_to_linear_srgb([l, a, b]),
                        ColourSpace::Lab.to_linear_srgb([l, a, b]),
                    );
                    for k in 0..3 {
                        worst = worst.max((x[k] - y[k]).abs() / y[k].abs().max(1.0));
                    }
                }
            }
        }
        assert!(worst < 1e-9, "worst {worst}");
    }

    #[test]
    fn fast_encoding_matches_the_transfer_function() {
        let mut worst = 0.0f64;
        let n = 200_000;
        for k in 0..=n {
            // Dense in [0, 1], with a few values beyond.
            let x = (k as f64 / n as f64).powi(3) * 1.01 - 0.001;
            worst = worst.max((srgb_encode_fast(x) - srgb_encode(x)).abs());
        }
        assert!(worst < 1e-7, "worst {worst}");
        for x in [0.0, 1.0, 0.003_130_8, 1.0 / 512.0, 0.5, 0.25] {
            assert!((srgb_encode_fast(x) - srgb_encode(x)).abs() < 1e-12, "{x}");
        }
    }

    #[test]
    fn single_precision_encoding_matches_the_transfer_function() {
        let mut worst = 0.0f64;
        let n = 200_000;
        for k in 0..=n {
            let x = (k as f64 / n as f64).powi(3) * 1.01 - 0.001;
            let fast = srgb_encode_f32(x as f32) as f64;
            worst = worst.max((fast - srgb_encode(x as f32 as f64)).abs());
        }
        // A 16-bit step is 1.5e-5.
        assert!(worst < 1e-6, "worst {worst}");
        for x in [0.0, 1.0, 0.003_130_8, 1.0 / 512.0, 0.5, 0.25] {
            let fast = srgb_encode_f32(x as f32) as f64;
            assert!((fast - srgb_encode(x)).abs() < 2e-7, "{x}");
        }
    }

    /// The branch-free encoder gives the bits of the other on `0..=1`: at the ends, at the
    /// joins of its pieces and of the table's octaves, and between them.
    #[test]
    fn branch_free_encoding_matches_bit_for_bit() {
        let table = encode_table_f32();
        let mut values = vec![0.0f32, 1.0, 0.003_130_8, 1.0 / 512.0, 0.5, 0.25, 1e-30];
        for v in values.clone() {
            values.push(f32::from_bits(v.to_bits() + 1));
            if v > 0.0 {
                values.push(f32::from_bits(v.to_bits() - 1));
            }
        }
        values.extend((0..=100_000).map(|k| (k as f32 / 100_000.0).powi(3)));
        for v in values.into_iter().filter(|v| (0.0..=1.0).contains(v)) {
            assert_eq!(
                srgb_encode_unit_f32(table, v).to_bits(),
                srgb_encode_f32_with(table, v).to_bits(),
                "{v}"
            );
        }
        // Outside, meaningless but no panic; the other gives NaN for NaN.
        for v in [f32::NAN, -1.0, 2.0, f32::INFINITY, f32::MAX, -0.0] {
            srgb_encode_unit_f32(table, v);
        }
        assert!(srgb_encode_f32(f32::NAN).is_nan());
    }

    #[test]
    fn cube_root_matches_the_library() {
        let mut worst = 0.0f64;
        let mut x = 1e-300;
        while x < 1e300 {
            for v in [x, -x, x * 1.37, x * 2.9] {
                let (ours, lib) = (cube_root(v), v.cbrt());
                worst = worst.max(((ours - lib) / lib).abs());
            }
            x *= 1.9;
        }
        assert!(worst < 4.0 * f64::EPSILON, "worst relative error {worst:e}");
        for v in [
            0.0,
            -0.0,
            1.0,
            -8.0,
            27.0,
            f64::INFINITY,
            f64::MIN_POSITIVE / 4.0,
        ] {
            assert_eq!(cube_root(v), v.cbrt(), "{v}");
        }
        assert!(cube_root(f64::NAN).is_nan());
    }

    #[test]
    fn oklab_round_trip_and_white() {
        let w = linear_srgb_to_oklab([1.0, 1.0, 1.0]);
        assert!((w[0] - 1.0).abs() < 1e-6 && w[1].abs() < 1e-6 && w[2].abs() < 1e-6);
        let c = [0.2, 0.7, 0.05];
        let back = oklab_to_linear_srgb(linear_srgb_to_oklab(c));
        for (x, y) in back.iter().zip(c) {
            assert!((x - y).abs() < 1e-6);
        }
    }
}
