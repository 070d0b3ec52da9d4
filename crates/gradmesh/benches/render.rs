//! Whole renders of the gallery examples (`examples/*.json`) at 1024 pixels on the longer
//! side, and the floor: filling the same RGBA `f32` buffer with one colour. Then the authors'
//! six-layer Tucan at 1024 pixels wide into an 8-bit buffer, from scratch and as an editor
//! re-renders it after one layer changed (`RenderCache`); Glasses at 1024 and both at 4096
//! pixels wide, and the three Paprika layers at 1024 (`artwork`). Time against mesh size:
//! jittered grids of 10 to 10,000 faces at 1024x1024 (`mesh_size_1024`). Last, PNG encoding
//! of a rendered megapixel (`png_megapixel`).
//!
//! Run: `cargo bench -p gradmesh --bench render` (add a name to run one example, e.g.
//! `-- rectangle`, `-- tucan_1024` for the editing figures, `-- artwork` for the others,
//! `-- mesh_size` for the grids, `-- png` for encoding).

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use std::path::PathBuf;
use std::time::Duration;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gradmesh::formats;
use gradmesh::render::{
    render_document, render_document_into, render_document_into_cached, write_png_rgba8_with,
    GamutMapping, PngCompression, RenderCache, RenderOptions, View,
};
use gradmesh::Document;

mod common;

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

/// The authors' real files: `names` from the shared real data beside the repository, as the
/// layers of one document, bottom to top.
fn real_document(names: &[String]) -> Option<Document> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/realdata/gradientmeshimproved-off");
    let mut layers = Vec::new();
    for name in names {
        layers.extend(formats::read_path(&dir.join(name)).ok()?.layers);
    }
    Some(Document::new(layers))
}

/// The six Tucan layers, bottom to top (the README's order).
fn tucan() -> Option<Document> {
    let names: Vec<String> = (0..6)
        .rev()
        .map(|i| format!("Tucan_Tucan_Layer{i}.off"))
        .collect();
    real_document(&names)
}

/// The absolute targets on the real artwork: Glasses at 1024 pixels wide, and both
/// at 4096 (print size), into 8-bit buffers as the command line writes them (Tucan at 1024 is
/// `tucan_1024/from_scratch`).
fn bench_artwork(c: &mut Criterion) {
    let (Some(tucan), Some(glasses), Some(paprika)) = (
        tucan(),
        real_document(&["Glasses.off".into()]),
        real_document(
            &(0..3)
                .rev()
                .map(|i| format!("Paprika_Paprika_layer{i}.off"))
                .collect::<Vec<_>>(),
        ),
    ) else {
        eprintln!("shared/realdata not found: skipping the artwork benchmarks");
        return;
    };
    let mut g = c.benchmark_group("artwork");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    for (name, doc, width) in [
        ("glasses_1024", &glasses, 1024),
        ("glasses_4096", &glasses, 4096),
        ("tucan_4096", &tucan, 4096),
        // About 31k of its pixels lie outside sRGB: the gamut mapping's share of real work.
        ("paprika_1024", &paprika, 1024),
    ] {
        let opts = RenderOptions::fit(doc, width);
        let mut buffer = vec![0u8; 4 * (opts.width * opts.height) as usize];
        g.bench_function(name, |b| {
            b.iter(|| render_document_into(black_box(doc), &opts, &mut buffer).unwrap())
        });
    }
    g.finish();
}

fn bench_editing(c: &mut Criterion) {
    let Some(doc) = tucan() else {
        eprintln!("shared/realdata not found: skipping the Tucan benchmarks");
        return;
    };
    let opts = RenderOptions::fit(&doc, SIZE);
    let mut buffer = vec![0u8; 4 * (opts.width * opts.height) as usize];
    let mut g = c.benchmark_group("tucan_1024");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    g.bench_function("from_scratch", |b| {
        b.iter(|| render_document_into(black_box(&doc), &opts, &mut buffer).unwrap())
    });
    // The render `gradmesh render Tucan_Tucan_Layer{5,4,3,2,1,0}.off --width 1024` makes: the
    // command line's view has no margin (its faces along the fold need more cells), and
    // 1024x559 pixels. The whole process is measured against this.
    {
        let opts = command_line_options(&doc, 1024);
        let mut buffer = vec![0u8; 4 * (opts.width * opts.height) as usize];
        g.bench_function("command_line_view", |b| {
            b.iter(|| render_document_into(black_box(&doc), &opts, &mut buffer).unwrap())
        });
    }
    // The drawing stage alone (every pixel, from prepared layers); preparing is the rest of
    // `from_scratch`.
    {
        let (mut opts, mut cache) = (opts.clone(), RenderCache::new());
        common::check_draws_only(&doc, &mut opts, &mut cache, &mut buffer);
        g.bench_function("draw_only", |b| {
            b.iter(|| common::draw_again(black_box(&doc), &mut opts, &mut cache, &mut buffer))
        });
    }
    // An edit moves a point of one layer back and forth, so every iteration prepares that
    // layer again and takes the others from the cache.
    for (name, layer) in [("edit_top_layer", 5), ("edit_densest_layer", 3)] {
        let mut doc = doc.clone();
        let mut cache = RenderCache::new();
        render_document_into_cached(&doc, &opts, &mut cache, &mut buffer).unwrap();
        let mut moved = false;
        g.bench_function(name, |b| {
            b.iter(|| {
                moved = !moved;
                doc.layers[layer].points[0].position.x += if moved { 0.5 } else { -0.5 };
                render_document_into_cached(black_box(&doc), &opts, &mut cache, &mut buffer)
                    .unwrap()
            })
        });
    }
    g.finish();
}

/// Time against mesh size at a fixed pixel count: the scaling example's grids of 10 to 10,000
/// faces at 1024x1024, as it renders them, and again with gamut clipping (their colours leave
/// sRGB over about half the image, and the chroma search is the larger part of drawing them).
fn bench_mesh_size(c: &mut Criterion) {
    let mut g = c.benchmark_group("mesh_size_1024");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    for (w, h) in common::jittered_grid::SIZES {
        let doc = common::jittered_grid::grid(w, h);
        let mut opts = RenderOptions::fit(&doc, SIZE);
        let faces = w * h;
        g.bench_function(format!("{faces}_faces"), |b| {
            b.iter(|| render_document(black_box(&doc), &opts).unwrap())
        });
        opts.gamut = GamutMapping::Clip;
        g.bench_function(format!("{faces}_faces_clip"), |b| {
            b.iter(|| render_document(black_box(&doc), &opts).unwrap())
        });
    }
    g.finish();
}

/// The options `gradmesh render --width WIDTH` takes for `doc`: the document's bounds with
/// no margin, the height from their aspect ratio.
fn command_line_options(doc: &Document, width: u32) -> RenderOptions {
    let view = View::fit(doc, 0.0);
    let height = (width as f64 * view.height() / view.width())
        .round()
        .max(1.0) as u32;
    RenderOptions::new(width, height, view)
}

/// PNG encoding of about a megapixel: Tucan rendered 1372 pixels wide (1372x749, dithered),
/// as the command line encodes it (`fast`, the default) and with `--png-compression best`.
fn bench_png(c: &mut Criterion) {
    let Some(doc) = tucan() else {
        eprintln!("shared/realdata not found: skipping the PNG benchmarks");
        return;
    };
    let opts = command_line_options(&doc, 1372);
    let (w, h) = (opts.width, opts.height);
    let mut pixels = vec![0u8; 4 * (w * h) as usize];
    render_document_into(&doc, &opts, &mut pixels).unwrap();
    let mut g = c.benchmark_group("png_megapixel");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    let mut out = Vec::new();
    for (name, compression) in [
        ("fast", PngCompression::Fast),
        ("best", PngCompression::Best),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                out.clear();
                write_png_rgba8_with(&mut out, w, h, black_box(&pixels), compression).unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    bench,
    bench_editing,
    bench_artwork,
    bench_mesh_size,
    bench_png
);
criterion_main!(benches);
