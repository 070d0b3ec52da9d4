//! The mesh tools and tracing in a real browser (headless Chromium through chromedriver, real
//! pointer and keyboard events): a 2 x 2 grid in two actions (G, a drag), a loop cut, a point
//! in a face, dissolving a point and an edge, an ellipse, an outline, and a point coloured from
//! a reference image with the eyedropper. Fails (never skips) when Chromium or chromedriver is
//! missing.
//!
//! Screenshots go to `target/editor-screenshots/`; with `GRADMESH_UPDATE_SCREENSHOTS=1` they
//! are also copied to `docs/` (`tools-*.png`).

mod support;

use std::path::Path;

use fantoccini::{Client, Locator};
use gradmesh_serve::{start, Config, Running};
use serde_json::{json, Value};
use support::*;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn mesh_tools_and_tracing_in_a_real_browser() {
    let _one = ONE_BROWSER.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let running = start(&Config {
        file: None,
        folder: Some(dir.path().to_path_buf()),
        port: 0,
        ..Config::default()
    })
    .await
    .unwrap();
    let (_driver, client) = open_browser().await;
    let result = run_session(&client, &running, dir.path()).await;
    client.close().await.ok();
    result.expect("the browser session");
}

/// Presses `keys` with the canvas focused, as a user does after a click on it.
async fn press(client: &Client, keys: &str) -> Result<(), String> {
    let overlay = client
        .find(Locator::Id("overlay"))
        .await
        .map_err(|e| e.to_string())?;
    overlay.send_keys(keys).await.map_err(|e| e.to_string())
}

/// Counts of the layer's points and faces, and the page's selection and selected face.
async fn counts(client: &Client, layer: usize) -> (u64, u64, Value, Value) {
    let v = js(
        client,
        &format!(
            "const g = window.gradmesh; const l = g.state.layers[{layer}]; \
             return [l.points.length, l.faces.length, g.selection, g.face];"
        ),
    )
    .await;
    (
        v[0].as_u64().unwrap(),
        v[1].as_u64().unwrap(),
        v[2].clone(),
        v[3].clone(),
    )
}

/// The screen position (viewport pixels) of plane point `(x, y)`.
async fn on_screen(client: &Client, x: f64, y: f64) -> (f64, f64) {
    let at = js(
        client,
        &format!(
            "const [x, y] = window.gradmesh.toScreen({x}, {y}); \
             const r = document.getElementById('overlay').getBoundingClientRect(); \
             return [r.left + x, r.top + y];"
        ),
    )
    .await;
    (at[0].as_f64().unwrap(), at[1].as_f64().unwrap())
}

/// The midpoint of points `a` and `b` of layer 0 on screen.
async fn between(client: &Client, a: usize, b: usize) -> (f64, f64) {
    let (pa, pb) = (
        point_on_screen(client, a).await,
        point_on_screen(client, b).await,
    );
    ((pa.0 + pb.0) / 2.0, (pa.1 + pb.1) / 2.0)
}

async fn run_session(client: &Client, running: &Running, dir: &Path) -> Result<(), String> {
    client
        .goto(&running.url())
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;

    // A 2 x 2 grid: G, then one drag (two actions).
    press(client, "g").await?;
    drag(client, (300.0, 250.0), (300.0, 200.0)).await;
    settle(client).await;
    let (points, faces, selection, _) = counts(client, 0).await;
    assert_eq!((points, faces), (9, 4), "a 2 x 2 grid");
    assert_eq!(
        selection,
        json!([0, 1, 2, 3, 4, 5, 6, 7, 8]),
        "the grid is selected"
    );
    screenshot(client, "tools-grid.png").await;

    // A loop cut across the left column: L, a click on the top edge of its first quad.
    press(client, "l").await?;
    click(client, between(client, 0, 1).await).await;
    settle(client).await;
    let (points, faces, selection, _) = counts(client, 0).await;
    assert_eq!(
        (points, faces),
        (12, 6),
        "the cut splits the column's two quads"
    );
    assert_eq!(
        selection,
        json!([9, 10, 11]),
        "the cut's new points are selected"
    );
    let xs = js(
        client,
        "const l = window.gradmesh.state.layers[0]; return [9, 10, 11].map((p) => l.points[p][0]);",
    )
    .await;
    let x: Vec<f64> = (0..3).map(|i| xs[i].as_f64().unwrap()).collect();
    assert!(
        (x[0] - x[1]).abs() < 1e-9 && (x[1] - x[2]).abs() < 1e-9,
        "the new points lie on one line down the column: {xs}"
    );
    screenshot(client, "tools-loop-cut.png").await;

    // A point in the bottom right face: I, a click inside it.
    press(client, "i").await?;
    let inside = between(client, 4, 8).await;
    click(client, (inside.0 + 7.0, inside.1 - 5.0)).await;
    settle(client).await;
    let (points, faces, selection, _) = counts(client, 0).await;
    let message = js(client, "return window.gradmesh.error;").await;
    assert_eq!(
        (points, faces),
        (13, 9),
        "the quad became four triangles ({message})"
    );
    assert_eq!(selection, json!([12]), "the new point is selected");
    screenshot(client, "tools-point.png").await;

    // Dissolve it again (it is selected): X. The four triangles merge into one quad.
    press(client, "x").await?;
    settle(client).await;
    let (points, faces, selection, face) = counts(client, 0).await;
    assert_eq!((points, faces), (12, 6), "the point dissolved");
    assert_eq!(selection, json!([]));
    assert!(face.is_u64(), "the merged face is selected: {face}");
    // Dissolve an edge: click the middle edge of the right column (points 5 and 4), X.
    click(client, between(client, 4, 5).await).await;
    settle(client).await;
    let edge = js(client, "return window.gradmesh.edge;").await;
    assert_eq!(edge, json!([4, 5]), "the edge is selected");
    press(client, "x").await?;
    settle(client).await;
    let (points, faces, _, face) = counts(client, 0).await;
    assert_eq!((points, faces), (12, 5), "the edge's two faces merged");
    let size = js(
        client,
        &format!("return window.gradmesh.state.layers[0].faces[{face}].length;"),
    )
    .await;
    assert_eq!(size, json!(6), "the merged face has six corners");
    screenshot(client, "tools-dissolve.png").await;

    // Undo takes the dissolve back.
    press(client, "\u{E009}z\u{E009}").await?;
    settle(client).await;
    assert_eq!(counts(client, 0).await.1, 6, "undo restores the two faces");

    // An ellipse to the right of the grid (O, a drag) and an outline below it (P, clicks).
    press(client, "o").await?;
    drag(client, (640.0, 250.0), (200.0, 150.0)).await;
    settle(client).await;
    assert_eq!(
        counts(client, 0).await.0,
        12 + 17,
        "the ellipse's 17 points"
    );
    press(client, "p").await?;
    let corners = [
        (650.0, 460.0),
        (820.0, 470.0),
        (800.0, 600.0),
        (690.0, 620.0),
        (640.0, 540.0),
    ];
    for &at in &corners {
        click(client, at).await;
    }
    click(client, corners[0]).await;
    settle(client).await;
    let (points, faces, selection, _) = counts(client, 0).await;
    // Five corners and one added on the longest side, six inner points, the middle.
    assert_eq!(points, 12 + 17 + 13, "the outline's mesh");
    assert_eq!(faces, 6 + 12 + 9);
    assert_eq!(selection.as_array().map(Vec::len), Some(13));
    screenshot(client, "tools-shapes.png").await;

    trace_a_colour(client, dir).await
}

/// Places a reference image of four coloured quarters over the document and colours the grid's
/// left side from it with the eyedropper (a box around the side, K).
async fn trace_a_colour(client: &Client, dir: &Path) -> Result<(), String> {
    load_quarters(client, dir).await?;
    // Place it over the grid alone: its box is the grid's points 0 to 8.
    let grid = js(
        client,
        "const p = window.gradmesh.state.layers[0].points; return [p[0], p[8]];",
    )
    .await;
    let (x0, y0) = (grid[0][0].as_f64().unwrap(), grid[0][1].as_f64().unwrap());
    let (x1, y1) = (grid[1][0].as_f64().unwrap(), grid[1][1].as_f64().unwrap());
    // A square image a little larger than the grid, so that its corners fall inside.
    let side = (x1 - x0).max(y1 - y0) * 1.1;
    let (left, top) = ((x0 + x1 - side) / 2.0, (y0 + y1 - side) / 2.0);
    type_into(client, "reference-x", &format!("{left}\n")).await?;
    type_into(client, "reference-y", &format!("{top}\n")).await?;
    type_into(client, "reference-width", &format!("{side}\n")).await?;
    // Select the grid's left side (a box drag around it), K.
    let (top_left, bottom_left) = (
        on_screen(client, x0, y0).await,
        on_screen(client, x0, y1).await,
    );
    let start = (top_left.0.round() - 20.0, top_left.1.round() - 20.0);
    let down = ((bottom_left.1 - top_left.1 + 40.0) / 10.0).ceil() * 10.0;
    drag(client, start, (40.0, down)).await;
    let selection = js(client, "return window.gradmesh.selection;").await;
    assert_eq!(
        selection,
        json!([0, 3, 6]),
        "the grid's left side is selected"
    );
    press(client, "k").await?;
    settle(client).await;
    let hex = js(
        client,
        "const l = window.gradmesh.state.layers[0]; return [l.hex[0], l.hex[6]];",
    )
    .await;
    assert_eq!(
        hex,
        json!(["#ff0000", "#0000ff"]),
        "the corners took the image's colours under them"
    );
    screenshot(client, "tools-trace.png").await;
    Ok(())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn trace_in_a_real_browser() {
    let _one = ONE_BROWSER.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let running = start(&Config {
        file: None,
        folder: Some(dir.path().to_path_buf()),
        port: 0,
        ..Config::default()
    })
    .await
    .unwrap();
    let (_driver, client) = open_browser().await;
    let result = trace_session(&client, &running, dir.path()).await;
    client.close().await.ok();
    result.expect("the browser session");
}

/// A new document, the four quarters as reference image: keys typed in
/// a number field stay there, and Trace makes a layer of the image's left half.
async fn trace_session(client: &Client, running: &Running, dir: &Path) -> Result<(), String> {
    client
        .goto(&running.url())
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    load_quarters(client, dir).await?;
    // A square of 200 units, inside the view of a new document (0 to 400 by 0 to 300).
    type_into(client, "reference-x", "60\n").await?;
    type_into(client, "reference-y", "40\n").await?;
    type_into(client, "reference-width", "200\n").await?;
    number_fields_keep_their_keys(client).await?;
    trace_the_image(client, [60.0, 40.0, 200.0]).await
}

/// Keys typed into a number field stay there: "g5" in the grid's columns starts no tool.
async fn number_fields_keep_their_keys(client: &Client) -> Result<(), String> {
    type_into(client, "grid-columns", "g5").await?;
    let typed = js(
        client,
        "return [window.gradmesh.tools.mode, document.getElementById('grid-columns').value];",
    )
    .await;
    assert_eq!(
        typed,
        json!([null, "5"]),
        "the keys went to the field alone"
    );
    type_into(client, "grid-columns", "2").await
}

/// Traces the left half of the reference image (placed at `left`, `top`, `side` wide and
/// high): T, a box dragged over it; a new layer within the box, its corners red and blue.
async fn trace_the_image(client: &Client, [left, top, side]: [f64; 3]) -> Result<(), String> {
    let before = js(client, "return window.gradmesh.state.layers.length;").await;
    let before = before.as_u64().unwrap();
    type_into(client, "trace-points", "40").await?;
    press(client, "t").await?;
    let from = on_screen(client, left - 0.05 * side, top - 0.05 * side).await;
    let to = on_screen(client, left + 0.5 * side, top + 1.05 * side).await;
    let by = |a: f64, b: f64| ((b - a.round()) / 10.0).round() * 10.0;
    drag(client, from, (by(from.0, to.0), by(from.1, to.1))).await;
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(180);
    while js(client, "return window.gradmesh.state.layers.length;").await != json!(before + 1) {
        let message = js(client, "return window.gradmesh.error;").await;
        assert!(
            std::time::Instant::now() < deadline,
            "no traced layer ({message})"
        );
        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
    }
    settle(client).await;
    let traced = js(
        client,
        "const g = window.gradmesh; const l = g.state.layers[g.state.layers.length - 1];          return [l.name, g.activeLayer, l.points, l.hex];",
    )
    .await;
    assert_eq!(traced[0], json!("Trace"));
    assert_eq!(traced[1], json!(before), "the traced layer is active");
    let points = traced[2].as_array().unwrap();
    assert!(points.len() <= 40, "within the budget: {}", points.len());
    let (mut nearest_top, mut nearest_bottom) = ((f64::MAX, 0), (f64::MAX, 0));
    for (i, p) in points.iter().enumerate() {
        let (x, y) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
        assert!(
            x >= left - 1e-6
                && x <= left + 0.55 * side
                && y >= top - 1e-6
                && y <= top + side + 1e-6,
            "point {i} at ({x}, {y}) lies in the box over the image"
        );
        let top_distance = (x - left).hypot(y - top);
        let bottom_distance = (x - left).hypot(y - top - side);
        if top_distance < nearest_top.0 {
            nearest_top = (top_distance, i);
        }
        if bottom_distance < nearest_bottom.0 {
            nearest_bottom = (bottom_distance, i);
        }
    }
    let rgb = |i: usize| {
        let hex = traced[3][i]
            .as_str()
            .unwrap()
            .trim_start_matches('#')
            .to_string();
        (0..3)
            .map(|k| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).unwrap())
            .collect::<Vec<u8>>()
    };
    let (red, blue) = (rgb(nearest_top.1), rgb(nearest_bottom.1));
    assert!(red[0] > 180 && red[2] < 90, "the top left is red: {red:?}");
    assert!(
        blue[2] > 180 && blue[0] < 90,
        "the bottom left is blue: {blue:?}"
    );
    screenshot(client, "tools-trace-fit.png").await;
    // One undo step takes the traced layer away.
    press(client, "\u{E009}z\u{E009}").await?;
    settle(client).await;
    let after = js(client, "return window.gradmesh.state.layers.length;").await;
    assert_eq!(after, json!(before), "undo removes the traced layer");
    Ok(())
}

/// Writes a 64 x 64 picture of four coloured quarters (red, green; blue, yellow) and loads it
/// as the reference image through the file field.
async fn load_quarters(client: &Client, dir: &Path) -> Result<(), String> {
    let (w, h) = (64u32, 64u32);
    let mut pixels = Vec::with_capacity(4 * 64 * 64);
    for y in 0..h {
        for x in 0..w {
            let colour = match (x < w / 2, y < h / 2) {
                (true, true) => [255, 0, 0],
                (false, true) => [0, 255, 0],
                (true, false) => [0, 0, 255],
                (false, false) => [255, 255, 0],
            };
            pixels.extend_from_slice(&[colour[0], colour[1], colour[2], 255]);
        }
    }
    let png = gradmesh::render::encode_png_rgba8(w, h, &pixels).expect("a PNG");
    let path = dir.join("quarters.png");
    std::fs::write(&path, png).unwrap();
    let input = client
        .find(Locator::Id("reference-file"))
        .await
        .map_err(|e| e.to_string())?;
    input
        .send_keys(path.to_str().unwrap())
        .await
        .map_err(|e| e.to_string())?;
    // The image is placed once it has loaded: over the document's points.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while js(client, "return window.gradmesh.tools.reference !== null;").await != json!(true) {
        assert!(
            std::time::Instant::now() < deadline,
            "the reference image did not load"
        );
        tokio::time::sleep(std::time::Duration::from_millis(50)).await;
    }
    Ok(())
}
