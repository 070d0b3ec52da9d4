//! Fuzzes the SVG mesh-gradient reader: any text gives a scene that keeps the reader's
//! guarantees or an error, and a converted document survives a write and read back,
//! validation and a small refinement.
#![no_main]

#[path = "../../crates/gradmesh/tests/integration/fuzz_entry/mod.rs"]
mod fuzz_entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_entry::parse_svg(data);
});
