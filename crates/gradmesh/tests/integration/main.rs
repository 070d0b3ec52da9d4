//! The integration tests of gradmesh, one module per area, linked as a single test binary
//! (`cargo test -p gradmesh --test integration [filter]`) so that the workspace links one
//! executable instead of one per file.
//!
//! The data the tests read stays beside this folder: `tests/corpus/`, `tests/data/`,
//! `tests/references/` and `tests/regressions/`; the real artwork comes from `../shared/`
//! beside the repository (`realdata`). proptest keeps the seeds of past failures in
//! `tests/proptest-regressions/<module>.txt`: its place for them when the test crate has a
//! `main.rs`.

mod common;
mod fuzz_entry;
mod realdata;

mod accuracy_1024;
mod binary_step;
mod cache;
mod classic_fit;
mod closed_form;
mod corpus;
mod declared_counts;
mod degenerate;
mod edits;
mod errors_doc;
mod export;
mod formats;
mod fuzz_replay;
mod limit_matrix;
mod opensubdiv_oracle;
mod options;
mod pdf_other_programs;
mod pdf_read;
mod properties;
mod reference_images;
mod reference_outputs;
mod render;
mod svg;
mod svg_inkscape;
mod threads;
mod validation;
mod vectorise;
