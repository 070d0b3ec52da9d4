//! gradmesh against Cairo's mesh pattern (the renderer behind Inkscape's mesh gradients), and
//! against the memory-bandwidth floor (filling the same RGBA buffer with one colour).
//!
//! The scene: a rectangular 4x4-point mesh with curved edges, 9 patches, at 1024x1024. Cairo
//! paints the same 9 patches as Coons patches whose edges are the cubic Béziers through the
//! control points with their handles (as Illustrator's mesh).
//!
//! Run: `apt-get update && apt-get install libcairo2-dev` then
//! `cargo bench -p gradmesh --features cairo-bench --bench vs_cairo`.

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use std::time::Duration;

use cairo::{Context, Format, ImageSurface, Mesh, MeshCorner};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gradmesh::render::{render_document_into, RenderCache, RenderOptions, View};

mod common;
use common::wavy_grid::{colour, document, grid, handle, N};
use common::{check_draws_only, draw_again};

const SIZE: u32 = 1024;

fn cairo_mesh() -> Mesh {
    let p = grid();
    let mesh = Mesh::new();
    let corners = [
        MeshCorner::MeshCorner0,
        MeshCorner::MeshCorner1,
        MeshCorner::MeshCorner2,
        MeshCorner::MeshCorner3,
    ];
    for j in 0..N - 1 {
        for i in 0..N - 1 {
            let idx = [
                j * N + i,
                j * N + i + 1,
                (j + 1) * N + i + 1,
                (j + 1) * N + i,
            ];
            let cells = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            mesh.begin_patch();
            mesh.move_to(p[idx[0]].x, p[idx[0]].y);
            for k in 0..4 {
                let (a, b) = (idx[k], idx[(k + 1) % 4]);
                let (c1, c2) = (p[a] + handle(&p, a, b), p[b] + handle(&p, b, a));
                mesh.curve_to(c1.x, c1.y, c2.x, c2.y, p[b].x, p[b].y);
            }
            for k in 0..4 {
                let c = colour(cells[k].0, cells[k].1);
                mesh.set_corner_color_rgb(corners[k], c[0], c[1], c[2]);
            }
            mesh.end_patch();
        }
    }
    mesh
}

fn bench(c: &mut Criterion) {
    let doc = document();
    let mut opts = RenderOptions::new(SIZE, SIZE, View::new(0.0, 0.0, SIZE as f64, SIZE as f64));
    opts.dither = false;
    let mut buffer = vec![0u8; 4 * (SIZE * SIZE) as usize];
    let mesh = cairo_mesh();
    let surface = ImageSurface::create(Format::ARgb32, SIZE as i32, SIZE as i32).unwrap();

    let mut g = c.benchmark_group("vs_cairo_1024");
    g.sample_size(20).measurement_time(Duration::from_secs(8));
    g.bench_function("gradmesh", |b| {
        b.iter(|| render_document_into(black_box(&doc), &opts, &mut buffer).unwrap())
    });
    // Its drawing stage alone (every pixel, from the prepared layer).
    let (mut draw_opts, mut cache) = (opts.clone(), RenderCache::new());
    check_draws_only(&doc, &mut draw_opts, &mut cache, &mut buffer);
    g.bench_function("gradmesh_draw_only", |b| {
        b.iter(|| draw_again(black_box(&doc), &mut draw_opts, &mut cache, &mut buffer))
    });
    g.bench_function("cairo_mesh_pattern", |b| {
        b.iter(|| {
            let cr = Context::new(&surface).unwrap();
            cr.set_source(black_box(&mesh)).unwrap();
            cr.paint().unwrap();
        })
    });
    g.bench_function("fill_one_colour_floor", |b| {
        b.iter(|| {
            for px in buffer.chunks_exact_mut(4) {
                px.copy_from_slice(black_box(&[200, 100, 50, 255]));
            }
        })
    });
    g.finish();

    // The ratios the issue asks for, from medians of the same three jobs run back to back
    // (criterion's own figures above are the careful ones).
    let median = |f: &mut dyn FnMut()| {
        let mut t: Vec<f64> = (0..15)
            .map(|_| {
                let start = std::time::Instant::now();
                f();
                start.elapsed().as_secs_f64()
            })
            .collect();
        t.sort_by(f64::total_cmp);
        t[t.len() / 2]
    };
    let ours = median(&mut || {
        render_document_into(black_box(&doc), &opts, &mut buffer).unwrap();
    });
    let draw = median(&mut || {
        draw_again(black_box(&doc), &mut draw_opts, &mut cache, &mut buffer);
    });
    let cairo = median(&mut || {
        let cr = Context::new(&surface).unwrap();
        cr.set_source(black_box(&mesh)).unwrap();
        cr.paint().unwrap();
    });
    let floor = median(&mut || {
        for px in buffer.chunks_exact_mut(4) {
            px.copy_from_slice(black_box(&[200, 100, 50, 255]));
        }
    });
    println!(
        "medians of 15: gradmesh {:.1} ms (drawing alone {:.1} ms), cairo {:.1} ms, floor {:.2} ms; \
         gradmesh / cairo = {:.2} (target 0.25; drawing alone {:.2}), gradmesh / floor = {:.0}, \
         cairo / floor = {:.0}",
        ours * 1e3,
        draw * 1e3,
        cairo * 1e3,
        floor * 1e3,
        ours / cairo,
        draw / cairo,
        ours / floor,
        cairo / floor
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
