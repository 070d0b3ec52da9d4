//! Fuzzes the PDF shading-stream decoder: the input's first bytes choose a type 6 or 7
//! shading's bit widths and colour space, the rest is its stream, painted on a page and read
//! as `parse_pdf` reads files.
#![no_main]

#[path = "../../crates/gradmesh/tests/integration/fuzz_entry/mod.rs"]
mod fuzz_entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_entry::pdf::parse_pdf_shading(data);
});
