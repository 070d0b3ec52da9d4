//! The editor in a real browser: Debian's headless Chromium driven through chromedriver
//! (WebDriver). Loads a document, drags a point with mouse events, changes a colour, toggles a
//! crease, makes a multi-resolution colour edit, undoes, saves, and compares the canvas with
//! gradmesh's own render of the saved file. Fails (never skips) when Chromium or chromedriver
//! is missing: `scripts/test.sh` installs them.
//!
//! Screenshots go to `target/editor-screenshots/`; with `GRADMESH_UPDATE_SCREENSHOTS=1` they
//! are also copied to `docs/editor.png` and `docs/editor-edited.png`.

mod support;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use fantoccini::actions::{InputSource, MouseActions, PointerAction, MOUSE_BUTTON_LEFT};
use fantoccini::{Client, Locator};
use gradmesh_serve::{start, Config, Running};
use serde_json::json;
use support::*;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn edit_in_a_real_browser() {
    let _one = ONE_BROWSER.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let file = copy_example(dir.path());
    let running = start(&Config {
        file: Some(file.clone()),
        folder: None,
        port: 0,
        ..Config::default()
    })
    .await
    .unwrap();
    let (_driver, client) = open_browser().await;
    let result = run_session(&client, &running, &file).await;
    client.close().await.ok();
    result.expect("the browser session");
}

async fn run_session(client: &Client, running: &Running, file: &Path) -> Result<(), String> {
    client
        .goto(&running.url())
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let initial = canvas_pixels(client).await;
    assert!(
        initial.2.chunks_exact(4).filter(|p| p[3] == 255).count() > 10_000,
        "the canvas shows the picture"
    );
    screenshot(client, "editor.png").await;

    // Drag interior point 7 by (60, 40) pixels.
    let before = js(client, "return window.gradmesh.state.layers[0].points[7];").await;
    let from = point_on_screen(client, 7).await;
    drag(client, from, (60.0, 40.0)).await;
    settle(client).await;
    let after = js(client, "return window.gradmesh.state.layers[0].points[7];").await;
    let scale = js(client, "const g = window.gradmesh; return document.getElementById('overlay').getBoundingClientRect().width / (g.view.x1 - g.view.x0);").await.as_f64().unwrap();
    let moved = (
        (after[0].as_f64().unwrap() - before[0].as_f64().unwrap()) * scale,
        (after[1].as_f64().unwrap() - before[1].as_f64().unwrap()) * scale,
    );
    assert!(
        (moved.0 - 60.0).abs() < 2.0 && (moved.1 - 40.0).abs() < 2.0,
        "the point moved by {moved:?} pixels, not (60, 40)"
    );
    let dragged = canvas_pixels(client).await;
    let changed = differing_pixels(&initial.2, &dragged.2);
    assert!(changed > 1000, "the drag changed only {changed} pixels");
    let undo_steps = js(client, "return window.gradmesh.state.can_undo;").await;
    assert_eq!(undo_steps, json!(true));

    // Undo restores the pixels exactly; redo brings the drag back.
    client
        .find(Locator::Id("undo"))
        .await
        .map_err(|e| e.to_string())?
        .click()
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let undone = canvas_pixels(client).await;
    assert_eq!(
        differing_pixels(&initial.2, &undone.2),
        0,
        "undo restores the picture"
    );
    client
        .find(Locator::Id("redo"))
        .await
        .map_err(|e| e.to_string())?
        .click()
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    assert_eq!(
        differing_pixels(&dragged.2, &canvas_pixels(client).await.2),
        0
    );

    // Select point 7 and set its colour by hex.
    click(client, point_on_screen(client, 7).await).await;
    settle(client).await;
    let hex = client
        .find(Locator::Id("colour-hex"))
        .await
        .map_err(|e| e.to_string())?;
    hex.clear().await.map_err(|e| e.to_string())?;
    hex.send_keys("#ff00ff\n")
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let colour = js(client, "return window.gradmesh.state.layers[0].hex[7];").await;
    assert_eq!(colour, json!("#ff00ff"));
    let coloured = canvas_pixels(client).await;
    assert!(
        differing_pixels(&dragged.2, &coloured.2) > 1000,
        "the colour changed the picture"
    );

    // Toggle a crease on edge 7-12: click its middle, press C.
    let middle = js(client, "const g = window.gradmesh; const p = g.state.layers[0].points; \
        const [x, y] = g.toScreen((p[7][0] + p[12][0]) / 2, (p[7][1] + p[12][1]) / 2); \
        const r = document.getElementById('overlay').getBoundingClientRect(); return [r.left + x, r.top + y];").await;
    click(
        client,
        (middle[0].as_f64().unwrap(), middle[1].as_f64().unwrap()),
    )
    .await;
    let edge = js(client, "return window.gradmesh.edge;").await;
    assert_eq!(edge, json!([7, 12]), "clicking the edge selects it");
    client
        .find(Locator::Id("overlay"))
        .await
        .map_err(|e| e.to_string())?
        .send_keys("c")
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let kind = js(
        client,
        "return window.gradmesh.state.layers[0].edges.find(e => e[0] === 7 && e[1] === 12)[2];",
    )
    .await;
    assert_eq!(kind, json!("crease"));
    let creased = canvas_pixels(client).await;
    assert!(
        differing_pixels(&coloured.2, &creased.2) > 100,
        "the crease changed the picture"
    );

    // A multi-resolution colour edit at level 2: select face 5 (click inside it), show its
    // refined vertices, click the one at [1, 1] of the sector at point 7.
    let centre = js(client, "const g = window.gradmesh; const l = g.state.layers[0]; \
        const c = l.faces[5].map(p => l.points[p]).reduce((a, p) => [a[0] + p[0] / 4, a[1] + p[1] / 4], [0, 0]); \
        const [x, y] = g.toScreen(...c); \
        const r = document.getElementById('overlay').getBoundingClientRect(); return [r.left + x, r.top + y];").await;
    click(
        client,
        (centre[0].as_f64().unwrap(), centre[1].as_f64().unwrap()),
    )
    .await;
    assert_eq!(js(client, "return window.gradmesh.face;").await, json!(5));
    type_into(client, "mr-level", "2").await?;
    click_id(client, "mr-show").await?;
    let deadline = Instant::now() + Duration::from_secs(20);
    while js(client, "return !!window.gradmesh.refined;").await != json!(true) {
        assert!(
            Instant::now() < deadline,
            "the refined vertices did not come"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let count = js(client, "return window.gradmesh.refined.vertices.length;").await;
    assert_eq!(count, json!(64), "four sectors of 4 x 4 names at level 2");
    let dot = js(client, "const g = window.gradmesh; \
        const v = g.refined.vertices.find(v => v.point === 7 && v.at[0] === 1 && v.at[1] === 1); \
        const [x, y] = g.toScreen(...v.position); \
        const r = document.getElementById('overlay').getBoundingClientRect(); return [r.left + x, r.top + y];").await;
    click(client, (dot[0].as_f64().unwrap(), dot[1].as_f64().unwrap())).await;
    let fields = js(
        client,
        "return ['mr-level', 'mr-face', 'mr-point', 'mr-i', 'mr-j'] \
        .map(id => document.getElementById(id).value);",
    )
    .await;
    assert_eq!(
        fields,
        json!(["2", "5", "7", "1", "1"]),
        "clicking the refined vertex fills in its address"
    );
    js(
        client,
        "document.getElementById('mr-colour').value = '#00ffff'; return 0;",
    )
    .await;
    client
        .find(Locator::Id("mr-set"))
        .await
        .map_err(|e| e.to_string())?
        .click()
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let edits = js(client, "return window.gradmesh.state.layers[0].edits;").await;
    assert_eq!(
        edits,
        json!([[2, 5, 7, [1, 1], null]]),
        "{}",
        js(client, "return window.gradmesh.error;").await
    );
    let recoloured = canvas_pixels(client).await;
    assert!(
        differing_pixels(&creased.2, &recoloured.2) > 20,
        "the refined edit changed the picture"
    );

    // Drag the same refined vertex: its edit gets a position offset, and its dot (the limit
    // position, fetched again from the server) lands where the mouse let go.
    let from = (dot[0].as_f64().unwrap(), dot[1].as_f64().unwrap());
    drag(client, from, (30.0, 20.0)).await;
    settle(client).await;
    let target = (from.0.round() + 30.0, from.1.round() + 20.0);
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let at = js(client, "const g = window.gradmesh; \
            const v = g.refined.vertices.find(v => v.point === 7 && v.at[0] === 1 && v.at[1] === 1); \
            const [x, y] = g.toScreen(...v.position); \
            const r = document.getElementById('overlay').getBoundingClientRect(); return [r.left + x, r.top + y];").await;
        let (x, y) = (at[0].as_f64().unwrap(), at[1].as_f64().unwrap());
        if (x - target.0).hypot(y - target.1) < 1.0 {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the dragged refined vertex is at {x}, {y}, not {target:?}"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let offset = js(
        client,
        "return window.gradmesh.state.layers[0].edits[0][4];",
    )
    .await;
    assert!(
        offset.is_array(),
        "the drag gave the edit an offset: {offset}"
    );
    let refined = canvas_pixels(client).await;
    assert!(
        differing_pixels(&recoloured.2, &refined.2) > 20,
        "moving the refined vertex changed the picture"
    );

    // The opacity of one side of the discontinuity at point 8: the side in face 7 (selected
    // here by script: point 8, then face 7, as a click and a Shift+click inside it would).
    js(
        client,
        "const g = window.gradmesh; g.selection = [8]; g.face = 7; g.edge = null; return 0;",
    )
    .await;
    type_into(client, "side-opacity", "0.2").await?;
    click_id(client, "side-opacity-set").await?;
    settle(client).await;
    let sides = js(client, "return window.gradmesh.state.layers[0].sides;").await;
    assert!(
        sides
            .as_array()
            .unwrap()
            .contains(&json!([8, 7, "#6a4c93", 0.2])),
        "the side has its opacity: {sides}"
    );
    let side_faded = canvas_pixels(client).await;
    assert!(
        differing_pixels(&refined.2, &side_faded.2) > 100,
        "the side's opacity changed the picture"
    );
    screenshot(client, "editor-edited.png").await;

    // Save (Ctrl+S), and compare the canvas with gradmesh's render of the saved file.
    client
        .find(Locator::Id("overlay"))
        .await
        .map_err(|e| e.to_string())?
        .send_keys("\u{E009}s\u{E009}")
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let saved = gradmesh::formats::read_path(file).map_err(|e| e.to_string())?;
    let layer = &saved.layers[0];
    assert_eq!(layer.edits.len(), 1, "the saved file has the refined edit");
    assert_eq!(layer.edge_tag(7, 12).kind, gradmesh::EdgeKind::Crease);
    assert_eq!(layer.points[7].colour_text.as_deref(), Some("#ff00ff"));
    assert_eq!(
        layer
            .wedges
            .iter()
            .find(|w| (w.point, w.face) == (8, 7))
            .unwrap()
            .opacity,
        Some(0.2)
    );
    let worst = compare_with_render(client, file, &side_faded).await;
    assert!(
        worst <= 2,
        "the canvas differs from the render of the saved file by {worst} levels"
    );

    // The page's own requests need the token, and a page of another origin cannot open the
    // WebSocket even with it.
    let status = js(client, "return fetch('/api/state').then(r => r.status);").await;
    assert_eq!(status, json!(401));
    let socket_url = format!("ws://{}/ws?token={}", running.address, running.token);
    client
        .goto("data:text/html,<p>another site</p>")
        .await
        .map_err(|e| e.to_string())?;
    let opened = client
        .execute_async(
            "const done = arguments[arguments.length - 1]; const s = new WebSocket(arguments[0]); \
             s.onopen = () => done('opened'); s.onerror = () => done('refused');",
            vec![json!(socket_url)],
        )
        .await
        .map_err(|e| e.to_string())?;
    assert_eq!(opened, json!("refused"));
    Ok(())
}

/// The paper authors' Tucan (six layers, bottom first) as one document in `dir`.
fn write_tucan(dir: &Path) -> PathBuf {
    let files: Vec<String> = (0..6)
        .rev()
        .map(|i| format!("Tucan_Tucan_Layer{i}.off"))
        .collect();
    write_artwork(dir, "tucan", &files)
}

/// The paper authors' artwork files (`../shared/realdata/gradientmeshimproved-off`, bottom
/// layer first) as one document `NAME.json` in `dir`, so that the editor's recovery copy goes
/// beside it.
fn write_artwork(dir: &Path, name: &str, files: &[String]) -> PathBuf {
    let source = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/realdata/gradientmeshimproved-off");
    let layers = files
        .iter()
        .map(|file| {
            let path = source.join(file);
            let mut doc = gradmesh::formats::read_path(&path)
                .unwrap_or_else(|e| panic!("the artwork file {}: {e}", path.display()));
            doc.layers.remove(0)
        })
        .collect();
    let file = dir.join(format!("{name}.json"));
    let text = gradmesh::formats::json::write_document(&gradmesh::Document::new(layers));
    std::fs::write(&file, text).unwrap();
    file
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_tucan_in_a_real_browser() {
    let _one = ONE_BROWSER.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let file = write_tucan(dir.path());
    let running = start(&Config {
        file: Some(file),
        folder: None,
        port: 0,
        ..Config::default()
    })
    .await
    .unwrap();
    let (_driver, client) = open_browser().await;
    let result = show_tucan(&client, &running).await;
    client.close().await.ok();
    result.expect("the browser session");
}

/// Opens the Tucan, selects the beak's layer and a box of its points, and compares the canvas
/// with gradmesh's render of the file.
async fn show_tucan(client: &Client, running: &Running) -> Result<(), String> {
    client
        .goto(&running.url())
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let layers = js(
        client,
        "return document.querySelectorAll('#layers li').length;",
    )
    .await;
    assert_eq!(layers, json!(6), "the layer list shows the six layers");
    let canvas = canvas_pixels(client).await;
    let file = dir_file(running);
    let worst = compare_with_render(client, &file, &canvas).await;
    assert!(
        worst <= 2,
        "the canvas differs from the render of the file by {worst} levels"
    );
    // The beak's layer (third in the list, which shows the top layer first) becomes the
    // active one; a box selects some of its points.
    let items = client
        .find_all(Locator::Css("#layers li"))
        .await
        .map_err(|e| e.to_string())?;
    items[2].click().await.map_err(|e| e.to_string())?;
    let active = js(client, "return window.gradmesh.activeLayer;").await;
    assert_eq!(active, json!(3));
    let bounds = js(
        client,
        "const r = document.getElementById('overlay').getBoundingClientRect(); \
        return [r.left, r.top, r.width, r.height];",
    )
    .await;
    let b: Vec<f64> = (0..4).map(|i| bounds[i].as_f64().unwrap()).collect();
    drag(
        client,
        (b[0] + 0.55 * b[2], b[1] + 0.2 * b[3]),
        (0.25 * b[2], 0.3 * b[3]),
    )
    .await;
    let selected = js(client, "return window.gradmesh.selection.length;").await;
    assert!(selected.as_u64().unwrap() > 0, "the box selects points");
    screenshot(client, "editor-tucan.png").await;
    Ok(())
}

/// The file the server saves to (the one it opened, here).
fn dir_file(running: &Running) -> PathBuf {
    let editor = running.app.editor();
    editor.path.clone().expect("the document's file")
}

/// The drags whose latency the page measures: artwork, its files (bottom first), and the
/// layer and point dragged (the costliest drags of `benches/edit_latency.rs`, and a point
/// inside Glasses' lens).
fn latency_drags() -> Vec<(&'static str, Vec<String>, usize, usize)> {
    let tucan = (0..6)
        .rev()
        .map(|i| format!("Tucan_Tucan_Layer{i}.off"))
        .collect::<Vec<_>>();
    let paprika = (0..3)
        .rev()
        .map(|i| format!("Paprika_Paprika_layer{i}.off"))
        .collect::<Vec<_>>();
    let glasses = vec!["Glasses.off".to_string()];
    vec![
        ("tucan", tucan, 3, 28),
        ("paprika", paprika, 1, 37),
        ("glasses", glasses.clone(), 0, 74),
        ("glasses", glasses, 0, 64),
    ]
}

/// The time from a mouse move to its frame on the canvas, as the page measures it
/// (`window.gradmesh.latency`), for a drag on each artwork with the picture 1024 pixels wide.
/// Prints the median, 95th percentile and worst (`-- --nocapture`); asserts that every move
/// was answered by a frame and that the drag moved the point.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn drag_latency_in_a_real_browser() {
    let _one = ONE_BROWSER.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let (_driver, client) = open_browser().await;
    let mut result = Ok(());
    for (name, files, layer, point) in latency_drags() {
        let file = write_artwork(dir.path(), name, &files);
        let running = start(&Config {
            file: Some(file),
            folder: None,
            port: 0,
            ..Config::default()
        })
        .await
        .unwrap();
        result = measure_drag(&client, &running, name, layer, point).await;
        running.task.abort();
        if result.is_err() {
            break;
        }
    }
    client.close().await.ok();
    result.expect("the browser session");
}

/// Opens the artwork with a picture 1024 pixels wide, drags the point back and forth with 120
/// mouse moves 16 ms apart, and reports the page's figures.
async fn measure_drag(
    client: &Client,
    running: &Running,
    name: &str,
    layer: usize,
    point: usize,
) -> Result<(), String> {
    client
        .set_window_size(1024 + 300, WINDOW.1)
        .await
        .map_err(|e| e.to_string())?;
    client
        .goto(&running.url())
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let width = js(client, "return document.getElementById('picture').width;").await;
    assert_eq!(width, json!(1024), "the picture's width in pixels");
    js(
        client,
        &format!("window.gradmesh.activeLayer = {layer}; window.gradmesh.selection = [];"),
    )
    .await;
    let before = server_point(running, layer, point);
    let at = point_on_layer(client, layer, point).await;
    let moves = 120;
    let mut mouse = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: at.0.round(),
            y: at.1.round(),
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        });
    for step in 0..moves {
        // Out by 12 pixels and back, 2 pixels a move, as a hand moves a point to and fro.
        let dx = if (step / 6) % 2 == 0 { 2.0 } else { -2.0 };
        mouse = mouse.then(PointerAction::MoveBy {
            duration: Some(Duration::from_millis(16)),
            x: dx,
            y: 1.0 - (step % 2) as f64 * 2.0,
        });
    }
    mouse = mouse
        .then(PointerAction::MoveBy {
            duration: Some(Duration::from_millis(16)),
            x: 6.0,
            y: 0.0,
        })
        .then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
    client
        .perform_actions(mouse)
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let after = server_point(running, layer, point);
    assert!(
        after.0 > before.0 + 1.0,
        "the drag moved {name}'s point ({layer}, {point}) to the right: {before:?} to {after:?}"
    );
    let latency = js(
        client,
        "const l = window.gradmesh.latency; \
         return [l.samples, l.moves.length, l.inFlight.length, l.waits, l.roundTrips, l.server, \
         l.work];",
    )
    .await;
    let numbers = |v: &serde_json::Value| -> Vec<f64> {
        let mut list: Vec<f64> = v
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        list.sort_by(f64::total_cmp);
        list
    };
    let samples = numbers(&latency[0]);
    let parts = [3, 4, 5, 6].map(|k| median(&numbers(&latency[k])));
    assert_eq!(latency[1], json!(0), "moves not sent");
    assert_eq!(latency[2], json!(0), "moves not answered");
    assert!(
        samples.len() >= moves / 4,
        "{} of {moves} moves measured",
        samples.len()
    );
    assert!(samples.iter().all(|t| t.is_finite() && *t >= 0.0));
    let rank = |q: f64| samples[((samples.len() - 1) as f64 * q).round() as usize];
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "browser drag latency, {name} ({layer}, {point}) at 1024 px: {} moves, median {:.1} ms, \
         95th {:.1} ms, worst {:.1} ms; medians of its parts: wait to be sent {:.1} ms, \
         round trip {:.1} ms, of which the server {:.1} ms and the page's handling {:.1} ms \
         (load {})",
        samples.len(),
        rank(0.5),
        rank(0.95),
        samples[samples.len() - 1],
        parts[0],
        parts[1],
        parts[2],
        parts[3],
        load.split_whitespace().next().unwrap_or("?")
    );
    Ok(())
}

/// The median of sorted `values` (not a number when there are none).
fn median(values: &[f64]) -> f64 {
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Point `point` of layer `layer` in the server's document.
fn server_point(running: &Running, layer: usize, point: usize) -> (f64, f64) {
    let editor = running.app.editor();
    let p = editor.history.current().doc.layers[layer].points[point].position;
    (p.x, p.y)
}

/// The screen position (viewport pixels) of point `point` of layer `layer`.
async fn point_on_layer(client: &Client, layer: usize, point: usize) -> (f64, f64) {
    let at = js(
        client,
        &format!(
            "const g = window.gradmesh; const [x, y] = g.toScreen(...g.state.layers[{layer}].points[{point}]); \
             const r = document.getElementById('overlay').getBoundingClientRect(); \
             return [r.left + x, r.top + y];"
        ),
    )
    .await;
    (at[0].as_f64().unwrap(), at[1].as_f64().unwrap())
}
