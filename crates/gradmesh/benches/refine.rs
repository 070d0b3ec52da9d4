//! Benchmarks of the refinement stages: validation and base level, the ternary step (topology,
//! data, and the two with validation), a Catmull-Clark step (topology and stencils), data
//! evaluation, and limit stencils.
//!
//! Run: `cargo bench -p gradmesh --bench refine`.

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gradmesh::internals::catmull_clark;
use gradmesh::internals::limit::limit_stencils;
use gradmesh::internals::ternary_step::{ternary_data, ternary_level};
use gradmesh::BaseMesh;
use gradmesh::Refinement;

mod common;
use common::mesh;

fn bench(c: &mut Criterion) {
    let m = mesh(87); // 10,092 faces
    assert!(m.faces.len() >= 10_000);
    let (base, _) = BaseMesh::new(&m).unwrap();
    let level1 = ternary_level(&base);
    let data1 = ternary_data(&base);
    let (level2, stencils) = catmull_clark::refine(&level1);

    let mut g = c.benchmark_group("10k_faces");
    g.sample_size(20);
    g.bench_function("validate_and_base_level", |b| {
        b.iter(|| BaseMesh::new(black_box(&m)).unwrap())
    });
    g.bench_function("ternary_step_topology", |b| {
        b.iter(|| ternary_level(black_box(&base)))
    });
    g.bench_function("ternary_step_data", |b| {
        b.iter(|| ternary_data(black_box(&base)))
    });
    g.bench_function("ternary_step_and_setup", |b| {
        b.iter(|| Refinement::new(black_box(&m), 1).unwrap())
    });
    // The whole first step as a user gets it: validation, level-1 topology and its data.
    g.bench_function("ternary_step_setup_and_data", |b| {
        b.iter(|| {
            let (r, _) = Refinement::new(black_box(&m), 1).unwrap();
            let data = r.evaluate();
            (r, data)
        })
    });
    g.bench_function("catmull_clark_topology_and_stencils", |b| {
        b.iter(|| catmull_clark::refine(black_box(&level1)))
    });
    g.bench_function("catmull_clark_data", |b| {
        b.iter(|| stencils.apply(black_box(&data1)))
    });
    g.bench_function("limit_stencils", |b| {
        b.iter(|| limit_stencils(black_box(&level2)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
