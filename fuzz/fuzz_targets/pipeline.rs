//! Fuzzes the whole pipeline on structured random meshes: build, validate, refine to depth
//! <= 3, limit; the output is finite and the limit colours interpolate the control colours.
#![no_main]

#[path = "../../crates/gradmesh/tests/integration/fuzz_entry/mod.rs"]
mod fuzz_entry;

libfuzzer_sys::fuzz_target!(|desc: fuzz_entry::MeshDescription| {
    fuzz_entry::pipeline(&desc);
});
