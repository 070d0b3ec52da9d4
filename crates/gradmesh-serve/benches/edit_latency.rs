//! The editor's edit path on the Tucan artwork (six layers) in a 1024-pixel-wide view: from
//! the command text reaching the session to the frame bytes and the state ready to send
//! (validation, the cached render, the changed rows, the state JSON).
//!
//! The point edited is the one whose change of colour redraws the most pixels.
//!
//! `cargo bench -p gradmesh-serve --bench edit_latency`. Besides criterion's figures it prints
//! the median and worst of one drag of 100 moves and of 100 colour changes.

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion};
use gradmesh::render::{self, RenderCache, RenderOptions};
use gradmesh::Document;
use gradmesh_serve::security::Folder;
use gradmesh_serve::{App, Editor, History, Outgoing, Picture, Session};

const TUCAN: &str = "../../../shared/realdata/gradientmeshimproved-off";
const WIDTH: u32 = 1024;

fn tucan() -> Document {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(TUCAN);
    let layers = (0..6)
        .rev()
        .map(|i| {
            let path = dir.join(format!("Tucan_Tucan_Layer{i}.off"));
            let doc = gradmesh::formats::read_path(&path)
                .unwrap_or_else(|e| panic!("the Tucan artwork ({}): {e}", path.display()));
            doc.layers.into_iter().next().expect("one layer")
        })
        .collect();
    Document { layers }
}

/// The layer and point whose change of colour redraws the most pixels of the picture (through
/// a `RenderCache`, as the editor renders): the costliest point to edit.
fn costliest_point(doc: &Document, opts: &RenderOptions) -> (usize, usize) {
    let mut cache = RenderCache::new();
    let mut pixels = vec![0u8; 4 * opts.width as usize * opts.height as usize];
    render::render_document_into_cached(doc, opts, &mut cache, &mut pixels).expect("renders");
    let mut best = (0, 0, 0);
    let mut edited = doc.clone();
    for layer in 0..doc.layers.len() {
        for point in 0..doc.layers[layer].points.len() {
            edited.layers[layer].points[point].colour[0] += 30.0;
            let info = render::render_document_into_cached(&edited, opts, &mut cache, &mut pixels)
                .expect("renders");
            edited.layers[layer].points[point].colour[0] -= 30.0;
            if info.drawn_pixels > best.0 {
                best = (info.drawn_pixels, layer, point);
            }
        }
    }
    (best.1, best.2)
}

/// A session showing the Tucan at 1024 pixels wide, its first frame drawn; the layer and point
/// to edit ([`costliest_point`]).
fn tucan_session() -> (Session, usize, usize) {
    let doc = tucan();
    let bounds = render::View::fit(&doc, 0.02);
    let height = (WIDTH as f64 * bounds.height() / bounds.width()).round() as u32;
    let (layer, point) = costliest_point(&doc, &RenderOptions::new(WIDTH, height, bounds));
    let folder = Folder::new(&std::env::temp_dir()).expect("temp folder");
    let editor = Editor {
        history: History::new(Picture::new(doc)),
        path: None,
    };
    let app = Arc::new(App::new(editor, folder));
    let mut session = Session::new(app);
    let view = format!(
        r#"{{"type":"view","width":{WIDTH},"height":{height},"view":[{},{},{},{}]}}"#,
        bounds.x0, bounds.y0, bounds.x1, bounds.y1
    );
    let first = session.handle_texts(&[view]);
    assert!(first.iter().any(|m| matches!(m, Outgoing::Binary(_))));
    (session, layer, point)
}

fn drag_command(layer: usize, point: usize, step: usize) -> String {
    // Back and forth by up to 3 units (a few pixels), as a mouse drag does.
    let dx = 3.0 * ((step % 8) as f64 / 4.0 - 1.0);
    format!(
        r#"{{"type":"edit","gesture":1,"op":{{"op":"move_points","layer":{layer},"points":[{point}],"dx":{dx},"dy":{}}}}}"#,
        dx / 2.0
    )
}

fn colour_command(layer: usize, point: usize, step: usize) -> String {
    let css = ["#d04020", "#2060c0", "#40a040"][step % 3];
    format!(
        r#"{{"type":"edit","gesture":2,"op":{{"op":"set_colour","layer":{layer},"points":[{point}],"css":"{css}"}}}}"#
    )
}

/// Runs `command(step)` for 100 steps and prints the median and worst time of one step.
fn report_100(name: &str, command: fn(usize, usize, usize) -> String) {
    let (mut session, layer, point) = tucan_session();
    let mut times: Vec<Duration> = (0..100)
        .map(|step| {
            let text = command(layer, point, step + 1);
            let start = Instant::now();
            let out = session.handle_texts(&[text]);
            let elapsed = start.elapsed();
            assert!(!out.iter().any(|m| matches!(m, Outgoing::Error(_))));
            elapsed
        })
        .collect();
    times.sort();
    println!(
        "{name}: 100 edits of point {point} of layer {layer} of the Tucan at {WIDTH} px wide: \
         median {:.2} ms, worst {:.2} ms",
        times[50].as_secs_f64() * 1e3,
        times[99].as_secs_f64() * 1e3
    );
}

fn edit_latency(c: &mut Criterion) {
    let mut group = c.benchmark_group("edit_latency_tucan_1024");
    let (mut session, layer, point) = tucan_session();
    let mut step = 0;
    group.bench_function("drag_point", |b| {
        b.iter(|| {
            step += 1;
            session.handle_texts(&[drag_command(layer, point, step)])
        })
    });
    let (mut session, layer, point) = tucan_session();
    group.bench_function("set_colour", |b| {
        b.iter(|| {
            step += 1;
            session.handle_texts(&[colour_command(layer, point, step)])
        })
    });
    group.finish();
}

criterion_group!(benches, edit_latency);

fn main() {
    report_100("drag", drag_command);
    report_100("colour", colour_command);
    benches();
    Criterion::default().configure_from_args().final_summary();
}
