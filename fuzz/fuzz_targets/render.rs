//! Fuzzes the renderer: structured random meshes drawn with arbitrary options (size, view,
//! output type, dithering, gamut mapping, colour space, outline, reference mode, quadratic
//! faces), then drawn again through a `RenderCache` after an arbitrary edit. Every pixel is
//! written and in range, the cached render equals a fresh one, one thread equals two.
#![no_main]

#[path = "../../crates/gradmesh/tests/integration/fuzz_entry/mod.rs"]
mod fuzz_entry;

libfuzzer_sys::fuzz_target!(|desc: fuzz_entry::render::RenderDescription| {
    fuzz_entry::render::render_entry(&desc);
});
