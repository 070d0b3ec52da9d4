//! Whole renders of the gallery examples (`examples/*.json`) at 1024 pixels on the longer
//! side, and the floor: filling the same RGBA `f32` buffer with one colour.
//!
//! Run: `cargo bench -p gradmesh --bench render` (add a name to run one example, e.g.
//! `-- rectangle`).

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use std::path::PathBuf;
use std::time::Duration;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gradmesh::formats;
use gradmesh::render::{render_document, RenderOptions};

const SIZE: u32 = 1024;

fn examples() -> Vec<(String, PathBuf)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("the examples directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .map(|p| (p.file_stem().unwrap().to_string_lossy().into_owned(), p))
        .collect();
    files.sort();
    files
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("render_1024");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    let mut largest = (0, 0);
    for (name, path) in examples() {
        let doc = formats::read_path(&path).expect("a gallery example");
        let opts = RenderOptions::fit(&doc, SIZE);
        largest = largest.max((opts.width, opts.height));
        g.bench_function(&name, |b| {
            b.iter(|| render_document(black_box(&doc), &opts).unwrap())
        });
    }
    // The floor: one pass writing every channel of the largest image.
    let mut buffer = vec![0f32; 4 * largest.0 as usize * largest.1 as usize];
    g.bench_function("fill_one_colour_floor", |b| {
        b.iter(|| {
            for px in buffer.chunks_exact_mut(4) {
                px.copy_from_slice(black_box(&[0.8, 0.4, 0.2, 1.0]));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
