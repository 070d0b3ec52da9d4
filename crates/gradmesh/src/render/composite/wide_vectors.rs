//! The one place with `unsafe` code: calling [`draw_band`] (and the gamut mapping of many
//! colours) compiled for x86-64-v3, which is sound only on a CPU that has those instructions,
//! after checking that it does.
use super::band::{draw_band as draw_band_inlined, Band, Scratch};
use crate::colour::gamut::GamutMapping;
use crate::render::output::pixels::OutputPixel;

/// Whether the CPU has every feature [`draw_band_v3`] is compiled for (detected once, then
/// read from a cache). Tests can turn the wide path off to compare the two.
pub fn available() -> bool {
    #[cfg(test)]
    if BASELINE_ONLY.load(std::sync::atomic::Ordering::Relaxed) {
        return false;
    }
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
        && std::arch::is_x86_feature_detected!("popcnt")
}

#[cfg(test)]
pub static BASELINE_ONLY: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

pub fn draw_band<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
    assert!(available(), "the CPU lacks x86-64-v3");
    // SAFETY: `draw_band_v3` only needs the CPU to have the features it is compiled for,
    // and the assertion above checked that it has them.
    unsafe { draw_band_v3(job, s) }
}

/// # Safety
/// The CPU must have the features named below ([`available`]).
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
#[inline(never)]
unsafe fn draw_band_v3<P: OutputPixel>(job: Band<'_, P>, s: &mut Scratch) {
    draw_band_inlined(job, s)
}

pub fn map_gamut(gamut: GamutMapping, colours: &mut [[f64; 3]]) {
    assert!(available(), "the CPU lacks x86-64-v3");
    // SAFETY: as in `draw_band`.
    unsafe { map_gamut_v3(gamut, colours) }
}

/// # Safety
/// The CPU must have the features named below ([`available`]).
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
#[inline(never)]
unsafe fn map_gamut_v3(gamut: GamutMapping, colours: &mut [[f64; 3]]) {
    gamut.apply_to_all_inlined(colours)
}
