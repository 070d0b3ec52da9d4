//! Reading SVG files of many elements that are not mesh fills (each left out with a warning
//! naming its line), from 8,000 to 64,000 paths beside one mesh-filled rectangle: the reader's
//! time should grow in proportion to the file.
//!
//! Run: `cargo bench -p gradmesh --bench svg_read`.

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use std::fmt::Write;
use std::time::Duration;

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gradmesh::formats::svg::read_svg;

/// An SVG file of `paths` small flat-filled triangles, one per line, and one rectangle filled
/// with a one-patch mesh gradient.
fn many_paths(paths: usize) -> String {
    let mut text = String::from(
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="1000" height="1000"><defs>
<meshgradient id="m" x="0" y="0"><meshrow><meshpatch>
<stop path="c 25,0 75,0 100,0" stop-color="#f00"/><stop path="c 0,25 0,75 0,100" stop-color="#0f0"/>
<stop path="c -25,0 -75,0 -100,0" stop-color="#00f"/><stop path="c 0,-25 0,-75 0,-100" stop-color="#ff0"/>
</meshpatch></meshrow></meshgradient></defs>
"##,
    );
    for i in 0..paths {
        let (x, y) = ((i * 7) % 1000, (i * 13) % 1000);
        writeln!(
            text,
            r##"<path d="M{x} {y} l5 0 l0 5 z" fill="#{:02x}8040"/>"##,
            i % 255
        )
        .unwrap();
    }
    text.push_str(r#"<rect width="100" height="100" fill="url(#m)"/></svg>"#);
    text
}

fn svg_read(c: &mut Criterion) {
    let mut group = c.benchmark_group("svg_read");
    group.measurement_time(Duration::from_secs(5));
    group.sample_size(10);
    for paths in [8_000, 16_000, 32_000, 64_000] {
        let text = many_paths(paths);
        group.throughput(Throughput::Elements(paths as u64));
        group.bench_with_input(BenchmarkId::from_parameter(paths), &text, |b, text| {
            b.iter(|| {
                let scene = read_svg(black_box(text)).unwrap();
                assert_eq!(scene.warnings.len(), paths);
                scene
            })
        });
    }
    group.finish();
}

criterion_group!(benches, svg_read);
criterion_main!(benches);
