//! Fuzzes the obj reader: any text gives a document or an error, and a document survives a
//! write and read back, validation and a small refinement.
#![no_main]

#[path = "../../crates/gradmesh/tests/integration/fuzz_entry/mod.rs"]
mod fuzz_entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_entry::parse(gradmesh::formats::Format::Obj, data);
});
