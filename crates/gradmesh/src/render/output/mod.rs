//! Output: 8-bit, 16-bit and float pixels, dither, PNG, and the outline overlay.

pub(super) mod overlay;
pub(super) mod pixels;
pub(super) mod png_deflate;
