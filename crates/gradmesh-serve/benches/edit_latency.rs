//! The editor's edit path on the paper authors' Tucan (six layers), Paprika (three) and Glasses
//! (one mesh, faces up to 14 sides) in the view the page first shows on a 1024 x 900 canvas: from
//! the command text reaching the session to the frame bytes and the state ready to send
//! (applying, validation, the cached render, the changed rows, the state JSON).
//!
//! For each artwork it edits the costliest points: the drag of the point whose move takes the
//! longest to render, and the colour change of the point whose change redraws the most pixels;
//! then the drags of the browser test (`drag_latency_in_a_real_browser`). A drag moves as the
//! browser test's mouse does: out by 12 pixels and back, 2 pixels a step.
//!
//! A drag is drawn as the session draws it while a gesture is open, as a draft
//! (`RenderOptions::draft`); the stages also show the exact render of the same step and the
//! exact frame at the drag's end.
//!
//! `cargo bench -p gradmesh-serve --bench edit_latency`. Besides criterion's figures it prints,
//! per artwork and edit, the median, 95th percentile and worst of 100 steps, and for the drag
//! the time of each stage of one step. `GRADMESH_LATENCY_STEPS=N` sets the steps,
//! `GRADMESH_LATENCY_ARTWORKS=glasses,tucan` the artworks; a criterion filter (`-- drag`) runs
//! criterion alone; `GRADMESH_LATENCY_DRAG=3,28` times that drag alone.

#![allow(missing_docs)] // criterion_group! generates undocumented items.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion};
use gradmesh::render::{self, RenderCache, RenderOptions, View};
use gradmesh::Document;
use gradmesh_serve::security::Folder;
use gradmesh_serve::{App, Editor, History, Outgoing, Picture, Session};

const REAL: &str = "../../../shared/realdata/gradientmeshimproved-off";
const WIDTH: u32 = 1024;
/// The picture's height: the editor's canvas in the browser test's window (1324 x 900).
const HEIGHT: u32 = 900;

/// The artworks: name and files, the bottom layer first.
const ARTWORKS: [(&str, &[&str]); 3] = [
    (
        "tucan",
        &[
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
        &[
            "Paprika_Paprika_layer2.off",
            "Paprika_Paprika_layer1.off",
            "Paprika_Paprika_layer0.off",
        ],
    ),
    ("glasses", &["Glasses.off"]),
];

/// The drags the browser test measures (`tests/browser.rs`, `drag_latency_in_a_real_browser`):
/// artwork, layer and point.
const BROWSER_DRAGS: [(&str, usize, usize); 4] = [
    ("tucan", 3, 28),
    ("paprika", 1, 37),
    ("glasses", 0, 74),
    ("glasses", 0, 64),
];

fn artwork(files: &[&str]) -> Document {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL);
    let layers = files
        .iter()
        .map(|name| {
            let path = dir.join(name);
            let doc = gradmesh::formats::read_path(&path)
                .unwrap_or_else(|e| panic!("the artwork file {}: {e}", path.display()));
            doc.layers.into_iter().next().expect("one layer")
        })
        .collect();
    Document::new(layers)
}

/// The options of the editor's first view of `doc` on a canvas of 1024 x 900 pixels, as the
/// page fits it: the document's bounds with 8% of their longer side around, widened to the
/// canvas's shape about their centre.
fn options(doc: &Document) -> RenderOptions {
    let b = View::fit(doc, 0.08);
    let aspect = WIDTH as f64 / HEIGHT as f64;
    let width = b.width().max(b.height() * aspect);
    let height = width / aspect;
    let (cx, cy) = (0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1));
    let view = View::new(
        cx - 0.5 * width,
        cy - 0.5 * height,
        cx + 0.5 * width,
        cy + 0.5 * height,
    );
    RenderOptions::new(WIDTH, HEIGHT, view)
}

/// A layer and point of the artwork, and the size of a pixel of the view in plane units.
#[derive(Clone, Copy, Debug)]
struct Target {
    layer: usize,
    point: usize,
    pixel: f64,
}

/// The point whose change of colour redraws the most pixels, and the point whose move (by 2
/// pixels, as a drag step, drawn as a draft) takes the longest to render, each through a
/// `RenderCache` as the editor renders (the quicker of two tries, against interference).
fn costliest_points(doc: &Document, opts: &RenderOptions) -> (Target, Target) {
    let mut cache = RenderCache::new();
    let mut pixels = vec![0u8; 4 * opts.width as usize * opts.height as usize];
    let draft = RenderOptions {
        draft: true,
        ..opts.clone()
    };
    let mut render = |d: &Document, opts: &RenderOptions, cache: &mut RenderCache| {
        render::render_document_into_cached(d, opts, cache, &mut pixels).expect("renders")
    };
    render(doc, opts, &mut cache);
    let pixel = opts.view.width() / opts.width as f64;
    let mut colour = (
        0,
        Target {
            layer: 0,
            point: 0,
            pixel,
        },
    );
    let mut drag = (
        Duration::ZERO,
        Target {
            layer: 0,
            point: 0,
            pixel,
        },
    );
    let mut edited = doc.clone();
    for layer in 0..doc.layers.len() {
        for point in 0..doc.layers[layer].points.len() {
            let target = Target {
                layer,
                point,
                pixel,
            };
            edited.layers[layer].points[point].colour[0] += 30.0;
            let info = render(&edited, opts, &mut cache);
            edited.layers[layer].points[point].colour[0] -= 30.0;
            render(&edited, opts, &mut cache);
            if info.drawn_pixels > colour.0 {
                colour = (info.drawn_pixels, target);
            }
            let mut quickest = Duration::MAX;
            for _ in 0..2 {
                edited.layers[layer].points[point].position.x += 2.0 * pixel;
                let start = Instant::now();
                render(&edited, &draft, &mut cache);
                quickest = quickest.min(start.elapsed());
                edited.layers[layer].points[point].position.x -= 2.0 * pixel;
                render(&edited, opts, &mut cache);
            }
            if quickest > drag.0 {
                drag = (quickest, target);
            }
        }
    }
    (drag.1, colour.1)
}

/// A session showing `doc` at 1024 pixels wide, its first frame drawn.
fn session(doc: &Document) -> Session {
    let opts = options(doc);
    let folder = Folder::new(&std::env::temp_dir()).expect("temp folder");
    let editor = Editor {
        history: History::new(Picture::new(doc.clone())),
        path: None,
    };
    let app = Arc::new(App::new(editor, folder));
    // As the WebSocket runs it: the folds after a gesture come after its frame.
    let mut session = Session::deferring_folds(app);
    let v = opts.view;
    let view = format!(
        r#"{{"type":"view","width":{},"height":{},"view":[{},{},{},{}]}}"#,
        opts.width, opts.height, v.x0, v.y0, v.x1, v.y1
    );
    let first = session.handle_texts(&[view]);
    assert!(first.iter().any(|m| matches!(m, Outgoing::Binary(_))));
    session.owed_folds();
    session
}

/// Step `step` of a drag as the browser test makes it: out by 12 pixels and back, 2 pixels a
/// step, with 1 pixel up and down at every other step (offsets from where the drag began).
fn drag_command(t: Target, step: usize) -> String {
    let phase = step % 12;
    let dx = 2.0 * if phase <= 6 { phase } else { 12 - phase } as f64;
    let dy = (step % 2) as f64;
    format!(
        r#"{{"type":"edit","gesture":1,"op":{{"op":"move_points","layer":{},"points":[{}],"dx":{},"dy":{}}}}}"#,
        t.layer,
        t.point,
        dx * t.pixel,
        dy * t.pixel
    )
}

fn colour_command(t: Target, step: usize) -> String {
    let css = ["#d04020", "#2060c0", "#40a040"][step % 3];
    format!(
        r#"{{"type":"edit","gesture":2,"op":{{"op":"set_colour","layer":{},"points":[{}],"css":"{css}"}}}}"#,
        t.layer, t.point
    )
}

/// The artworks to measure: those named in `GRADMESH_LATENCY_ARTWORKS` (comma-separated), or
/// all.
fn chosen() -> Vec<(&'static str, &'static [&'static str])> {
    let names = std::env::var("GRADMESH_LATENCY_ARTWORKS").unwrap_or_default();
    (ARTWORKS.into_iter())
        .filter(|(name, _)| names.is_empty() || names.split(',').any(|n| n == *name))
        .collect()
}

fn steps() -> usize {
    std::env::var("GRADMESH_LATENCY_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100)
}

/// Runs `command(target, step)` for the steps and prints the median, 95th percentile and worst
/// time of one step.
fn report(name: &str, edit: &str, doc: &Document, t: Target, command: fn(Target, usize) -> String) {
    let mut session = session(doc);
    let n = steps();
    let mut bytes: Vec<usize> = Vec::with_capacity(n);
    let mut texts: Vec<usize> = Vec::with_capacity(n);
    let mut times: Vec<Duration> = (0..n)
        .map(|step| {
            let text = command(t, step + 1);
            let start = Instant::now();
            let out = session.handle_texts(&[text]);
            let elapsed = start.elapsed();
            assert!(!out.iter().any(|m| matches!(m, Outgoing::Error(_))));
            let frame: usize = (out.iter())
                .filter(|m| matches!(m, Outgoing::Binary(_)))
                .map(message_bytes)
                .sum();
            bytes.push(frame);
            texts.push(out.iter().map(message_bytes).sum::<usize>() - frame);
            elapsed
        })
        .collect();
    times.sort();
    bytes.sort();
    texts.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "{name} {edit} (layer {}, point {}), {n} steps at {WIDTH} px: median {:.2} ms, 95th {:.2} ms, \
         worst {:.2} ms; medians of the bytes sent: frame {:.0} kB, state {:.0} kB",
        t.layer,
        t.point,
        ms(times[n / 2]),
        ms(times[(n * 95 / 100).min(n - 1)]),
        ms(times[n - 1]),
        bytes[n / 2] as f64 / 1e3,
        texts[n / 2] as f64 / 1e3
    );
}

/// The bytes of a message to the page.
fn message_bytes(message: &Outgoing) -> usize {
    match message {
        Outgoing::Text(t) | Outgoing::Error(t) | Outgoing::Notice(t) | Outgoing::Select(t) => {
            t.len()
        }
        Outgoing::Binary(b) => b.len(),
        Outgoing::Done => 0,
    }
}

/// The stages of one drag step, timed apart (the medians of the steps): applying the move and
/// validating the changed layer (`History::apply`), the document of the visible layers (a
/// copy), the cached render (with the renderer's own prepare and draw times), and the whole
/// step through the session (the rest: the changed rows, the frame, the state JSON).
fn profile_drag(name: &str, doc: &Document, t: Target) {
    let opts = options(doc);
    let mut history = History::new(Picture::new(doc.clone()));
    let mut cache = RenderCache::new();
    let mut pixels = vec![0u8; 4 * opts.width as usize * opts.height as usize];
    render::render_document_into_cached(doc, &opts, &mut cache, &mut pixels).expect("renders");
    let mut session = session(doc);
    // The session draws a drag as a draft, and exactly at its end.
    let draft = RenderOptions {
        draft: true,
        ..opts.clone()
    };
    // The same steps rendered exactly through a cache of their own, for comparison.
    let mut exact_cache = RenderCache::new();
    render::render_document_into_cached(doc, &opts, &mut exact_cache, &mut pixels)
        .expect("renders");
    let n = steps();
    let mut stages: Vec<[Duration; 10]> = Vec::with_capacity(n);
    for step in 1..=n {
        let text = drag_command(t, step);
        let command: gradmesh_serve::Command = serde_json::from_str(&text).expect("a command");
        let gradmesh_serve::Command::Edit { op, gesture } = command else {
            unreachable!("an edit")
        };
        let start = Instant::now();
        history.apply(&op, gesture).expect("applies");
        let applied = start.elapsed();
        let start = Instant::now();
        let visible = history.current().visible();
        let copied = start.elapsed();
        let start = Instant::now();
        let info = render::render_document_into_cached(&visible, &draft, &mut cache, &mut pixels)
            .expect("renders");
        let rendered = start.elapsed();
        let start = Instant::now();
        render::render_document_into_cached(&visible, &opts, &mut exact_cache, &mut pixels)
            .expect("renders");
        let exact = start.elapsed();
        let start = Instant::now();
        session.handle_texts(&[text]);
        let whole = start.elapsed();
        stages.push([
            applied,
            copied,
            rendered,
            info.timings.prepare,
            info.timings.draw,
            whole,
            exact,
            info.layers.iter().map(|l| l.timings.refine).sum(),
            info.layers.iter().map(|l| l.timings.evaluate).sum(),
            info.layers.iter().map(|l| l.timings.tessellate).sum(),
        ]);
    }
    let start = Instant::now();
    session.handle_texts(&[r#"{"type":"end_gesture"}"#.to_string()]);
    let release = start.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    session.owed_folds();
    let folds = start.elapsed().as_secs_f64() * 1e3;
    let median = |k: usize| {
        let mut v: Vec<Duration> = stages.iter().map(|s| s[k]).collect();
        v.sort();
        v[n / 2].as_secs_f64() * 1e3
    };
    println!(
        "{name} drag stages (medians): apply and validate {:.2} ms, copy of the visible layers {:.2} ms, \
         draft render {:.2} ms (prepare {:.2}: refine {:.2}, evaluate {:.2}, triangles {:.2}; draw {:.2}; exact render {:.2} ms); whole step {:.2} ms; \
         the exact frame at the drag's end {release:.2} ms, then its folds {folds:.2} ms",
        median(0),
        median(1),
        median(2),
        median(3),
        median(7),
        median(8),
        median(9),
        median(4),
        median(6),
        median(5)
    );
}

fn edit_latency(c: &mut Criterion) {
    for (name, files) in chosen() {
        let doc = artwork(files);
        let (drag, colour) = costliest_points(&doc, &options(&doc));
        let mut group = c.benchmark_group(format!("edit_latency_{name}_1024"));
        let mut s = session(&doc);
        let mut step = 0;
        group.bench_function("drag_point", |b| {
            b.iter(|| {
                step += 1;
                s.handle_texts(&[drag_command(drag, step)])
            })
        });
        let mut s = session(&doc);
        group.bench_function("set_colour", |b| {
            b.iter(|| {
                step += 1;
                s.handle_texts(&[colour_command(colour, step)])
            })
        });
        group.finish();
    }
}

criterion_group!(benches, edit_latency);

/// The drag named by `GRADMESH_LATENCY_DRAG=LAYER,POINT`, if any: the reports then profile
/// that drag alone (for `perf record`), without searching for the costliest points.
fn named_drag() -> Option<(usize, usize)> {
    let text = std::env::var("GRADMESH_LATENCY_DRAG").ok()?;
    let (layer, point) = text.split_once(',')?;
    Some((layer.trim().parse().ok()?, point.trim().parse().ok()?))
}

fn main() {
    let criterion_only = std::env::args().skip(1).any(|a| !a.starts_with('-'));
    if let Some((layer, point)) = named_drag() {
        for (name, files) in chosen() {
            let doc = artwork(files);
            let opts = options(&doc);
            let pixel = opts.view.width() / opts.width as f64;
            let t = Target {
                layer,
                point,
                pixel,
            };
            report(name, "drag", &doc, t, drag_command);
            profile_drag(name, &doc, t);
        }
        return;
    }
    if !criterion_only {
        for (name, files) in chosen() {
            let doc = artwork(files);
            let (drag, colour) = costliest_points(&doc, &options(&doc));
            report(name, "drag", &doc, drag, drag_command);
            report(name, "colour", &doc, colour, colour_command);
            profile_drag(name, &doc, drag);
            for &(artwork, layer, point) in BROWSER_DRAGS.iter().filter(|d| d.0 == name) {
                if (layer, point) != (drag.layer, drag.point) {
                    let t = Target {
                        layer,
                        point,
                        ..drag
                    };
                    report(artwork, "drag", &doc, t, drag_command);
                }
            }
        }
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
