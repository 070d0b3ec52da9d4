//! Vector output of the authors' artwork at 512 points wide with the default tolerances: the
//! six-layer Tucan, the three Paprika layers and Glasses, each as a PDF in Lab and in sRGB and
//! as an SVG without its PNG fallback.
//!
//! Run: `cargo bench -p gradmesh --bench export` (add `-- tucan` to run one artwork).

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use std::path::PathBuf;
use std::time::Duration;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gradmesh::export::{write_pdf, write_svg, ExportOptions, PdfColour};
use gradmesh::formats;
use gradmesh::render::RenderOptions;
use gradmesh::Document;

fn artwork(files: &[&str]) -> Document {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/realdata/gradientmeshimproved-off");
    let mut doc = Document::default();
    for f in files {
        let path = dir.join(f);
        let read = formats::read_path(&path)
            .unwrap_or_else(|e| panic!("{} (see README, Test data): {e}", path.display()));
        doc.layers.extend(read.layers);
    }
    doc
}

fn bench(c: &mut Criterion) {
    let sets: [(&str, Vec<&str>); 3] = [
        (
            "tucan",
            vec![
                "Tucan_Tucan_Layer5.off",
                "Tucan_Tucan_Layer4.off",
                "Tucan_Tucan_Layer3.off",
                "Tucan_Tucan_Layer2.off",
                "Tucan_Tucan_Layer1.off",
                "Tucan_Tucan_Layer0.off",
            ],
        ),
        (
            "paprika",
            vec![
                "Paprika_Paprika_layer2.off",
                "Paprika_Paprika_layer1.off",
                "Paprika_Paprika_layer0.off",
            ],
        ),
        ("glasses", vec!["Glasses.off"]),
    ];
    let mut group = c.benchmark_group("export_512");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5));
    for (name, files) in &sets {
        let doc = artwork(files);
        let render = RenderOptions::fit(&doc, 512);
        let mut opts = ExportOptions::new(render.width, render.height, render.view);
        for colour in [PdfColour::Lab, PdfColour::Srgb] {
            opts.colour = colour;
            group.bench_function(format!("{name}_pdf_{}", colour.name()), |b| {
                b.iter(|| black_box(write_pdf(&doc, &opts).unwrap()))
            });
        }
        group.bench_function(format!("{name}_svg"), |b| {
            b.iter(|| black_box(write_svg(&doc, &opts, false).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
