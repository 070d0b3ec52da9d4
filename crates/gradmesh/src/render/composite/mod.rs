//! Compositing: each band draws every layer front to back, converts to the blend space and
//! encodes the pixels; a picture's bands composited onto a caller's canvas.

pub(super) mod band;
pub(super) mod over;
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
pub(super) mod wide_vectors;
