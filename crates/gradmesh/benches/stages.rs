//! One benchmark per stage of the pipeline, on the 10,092-face mesh of the `refine` bench:
//! the ternary step, a Catmull-Clark step (topology and stencils, then applying them alone),
//! limit evaluation (stencils and their application), colour conversion of a large buffer, and
//! CSS Color 4 gamut mapping of it (colour by colour and with `GamutMapping::apply_to_all`).
//!
//! Run: `cargo bench -p gradmesh --bench stages`.

#![allow(missing_docs)] // criterion_group! generates undocumented items.

mod common;

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion};
use gradmesh::internals::catmull_clark;
use gradmesh::internals::limit::limit_stencils;
use gradmesh::internals::ternary_step::{ternary_data, ternary_level};
use gradmesh::render::GamutMapping;
use gradmesh::BaseMesh;
use gradmesh::ColourSpace;

fn bench(c: &mut Criterion) {
    let m = common::mesh(87); // 10,092 faces
    let (base, _) = BaseMesh::new(&m).unwrap();
    let level1 = ternary_level(&base);
    let data1 = ternary_data(&base);
    let (level2, stencils12) = catmull_clark::refine(&level1);
    let data2 = stencils12.apply(&data1);
    let limit2 = limit_stencils(&level2).expect("level 2 is all quads");

    let mut g = c.benchmark_group("stages_10k_faces");
    g.sample_size(20);
    g.bench_function("ternary_step", |b| {
        b.iter(|| (ternary_level(black_box(&base)), ternary_data(&base)))
    });
    g.bench_function("catmull_clark_topology_and_stencils", |b| {
        b.iter(|| catmull_clark::refine(black_box(&level1)))
    });
    g.bench_function("catmull_clark_apply_stencils", |b| {
        b.iter(|| stencils12.apply(black_box(&data1)))
    });
    g.bench_function("catmull_clark_data_without_stencil_table", |b| {
        b.iter(|| catmull_clark::refine_data(black_box(&level1), &data1))
    });
    g.bench_function("limit_stencils_and_apply", |b| {
        b.iter(|| limit_stencils(black_box(&level2)).unwrap().apply(&data2))
    });
    g.bench_function("limit_apply", |b| {
        b.iter(|| limit2.apply(black_box(&data2)))
    });
    g.finish();

    // A 1024 x 1024 buffer of Lab colours, converted to sRGB and to Oklab.
    let colours: Vec<[f64; 3]> = (0..1 << 20)
        .map(|i| {
            let t = i as f64 / (1 << 20) as f64;
            [100.0 * t, 80.0 * (7.0 * t).sin(), 80.0 * (5.0 * t).cos()]
        })
        .collect();
    let mut g = c.benchmark_group("colour_convert_1m");
    g.sample_size(10);
    for to in [ColourSpace::Srgb, ColourSpace::Oklab] {
        g.bench_function(format!("lab_to_{}", to.name()), |b| {
            b.iter_batched_ref(
                || colours.clone(),
                |buffer| {
                    for c in buffer.iter_mut() {
                        *c = ColourSpace::Lab.convert(to, *c);
                    }
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();

    // The same colours in linear sRGB, about two thirds of them outside the gamut: CSS Color
    // 4's chroma search, colour by colour and sixteen at a time.
    let linear: Vec<[f64; 3]> = colours
        .iter()
        .map(|&c| ColourSpace::Lab.to_linear_srgb(c))
        .collect();
    let outside = linear
        .iter()
        .filter(|c| c.iter().any(|v| !(0.0..=1.0).contains(v)))
        .count();
    assert!(outside > linear.len() / 2, "{outside} outside");
    let mut g = c.benchmark_group("gamut_map_1m");
    g.sample_size(10);
    g.bench_function("chroma_one_by_one", |b| {
        b.iter_batched_ref(
            || linear.clone(),
            |buffer| {
                for c in buffer.iter_mut() {
                    *c = GamutMapping::Chroma.apply(*c);
                }
            },
            BatchSize::LargeInput,
        )
    });
    g.bench_function("chroma_all_at_once", |b| {
        b.iter_batched_ref(
            || linear.clone(),
            |buffer| GamutMapping::Chroma.apply_to_all(buffer),
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
