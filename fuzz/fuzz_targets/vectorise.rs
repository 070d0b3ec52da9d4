//! Fuzzes `vectorise` on picture bytes: any bytes decode as a PNG or JPEG picture within a
//! small pixel limit or give an error, and a picture that decodes vectorises, within a small
//! point budget, into a valid mesh over its rectangle, or gives an error.
#![no_main]

#[path = "../../crates/gradmesh/tests/integration/fuzz_entry/mod.rs"]
mod fuzz_entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_entry::vectorise_bytes(data);
});
