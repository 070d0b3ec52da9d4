//! Fuzzes the PDF reader on whole files: any bytes read as page 1 give a picture that keeps
//! the reader's guarantees, whose layers validate or fail with an error and refine, or an error
//! with a message.
#![no_main]

#[path = "../../crates/gradmesh/tests/integration/fuzz_entry/mod.rs"]
mod fuzz_entry;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    fuzz_entry::pdf::parse_pdf(data);
});
