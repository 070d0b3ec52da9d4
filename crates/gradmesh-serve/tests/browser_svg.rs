//! SVG files in a real browser (headless Chromium through chromedriver, real pointer events):
//! a file of a mesh gradient and other shapes opens with its other shapes as a locked backdrop
//! under the layer and a message saying what is not editable; an SVG exported by the editor
//! opens again (from the "open a file…" menu) with its gradients joined into one large layer
//! per layer exported. Fails (never skips) when Chromium or chromedriver is missing.
//!
//! Screenshots go to `target/editor-screenshots/`; with `GRADMESH_UPDATE_SCREENSHOTS=1` they
//! are also copied to `docs/` (`editor-svg-*.png`).

mod support;

use std::path::Path;
use std::time::{Duration, Instant};

use fantoccini::{Client, Locator};
use gradmesh_serve::exports::{export_document, ExportFormat};
use gradmesh_serve::{start, Config, Running};
use serde_json::json;
use support::*;

/// A 2 x 1 mesh gradient over the middle of the page, a dark blue square behind it and an
/// orange circle in front of a corner of it, and a stroked line.
const DRAWING: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" width="400" height="300" viewBox="0 0 400 300">
  <meshgradient id="sky" gradientUnits="userSpaceOnUse" x="100" y="80">
    <meshrow>
      <meshpatch>
        <stop path="c 30,-20 70,-20 100,0" stop-color="#ff4040"/>
        <stop path="l 0,140" stop-color="#ffe060"/>
        <stop path="l -100,0" stop-color="#40a0ff"/>
        <stop path="l 0,-140" stop-color="#8040c0"/>
      </meshpatch>
      <meshpatch>
        <stop path="c 30,20 70,20 100,0" stop-color="#40ff80"/>
        <stop path="l 0,140" stop-color="#ffffff"/>
        <stop path="l -100,0"/>
      </meshpatch>
    </meshrow>
  </meshgradient>
  <rect x="20" y="20" width="360" height="260" fill="#1a2a5a"/>
  <rect x="100" y="60" width="200" height="160" fill="url(#sky)"/>
  <circle cx="320" cy="230" r="40" fill="#ff8000"/>
  <line x1="30" y1="270" x2="370" y2="270" stroke="#ffffff" stroke-width="4"/>
</svg>"##;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn svg_files_open_with_their_backdrop_and_joined_layers() {
    let _one = ONE_BROWSER.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let drawing = dir.path().join("drawing.svg");
    std::fs::write(&drawing, DRAWING).unwrap();
    write_exported_svg(dir.path());
    let running = start(&Config {
        file: Some(drawing),
        folder: Some(dir.path().to_path_buf()),
        port: 0,
        ..Config::default()
    })
    .await
    .unwrap();
    let (_driver, client) = open_browser().await;
    let result = run_session(&client, &running).await;
    client.close().await.ok();
    result.expect("the browser session");
}

/// Writes `exported.svg`: the non-rectangular example (two layers) and the annulus, exported as
/// the page's "export… SVG" does, and checks that its mesh gradients read as many more layers.
fn write_exported_svg(dir: &Path) {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut doc = gradmesh::Document::default();
    for name in ["non-rectangular.json", "annulus.json"] {
        let read = gradmesh::formats::read_path(&examples.join(name))
            .unwrap_or_else(|e| panic!("the example {name}: {e}"));
        doc.layers.extend(read.layers);
    }
    let svg = export_document(&doc, ExportFormat::Svg, 600).expect("the SVG export");
    let path = dir.join("exported.svg");
    std::fs::write(&path, svg).unwrap();
    let fills = gradmesh::formats::read_path(&path).unwrap().layers.len();
    assert!(
        fills > 500,
        "the export writes each layer as many mesh gradients ({fills})"
    );
}

/// Waits until the backdrop image has loaded for the page's current view.
async fn wait_for_backdrop(client: &Client) {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let loaded = js(
            client,
            "const i = document.getElementById('backdrop'); \
             return i.style.display === 'block' && i.complete && i.naturalWidth > 0;",
        )
        .await;
        if loaded == json!(true) {
            return;
        }
        assert!(Instant::now() < deadline, "the backdrop did not load");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// The backdrop image's pixel (RGBA8) under plane point `(x, y)`.
async fn backdrop_pixel(client: &Client, x: f64, y: f64) -> Vec<u64> {
    let px = js(
        client,
        &format!(
            "const i = document.getElementById('backdrop'); \
             const c = document.createElement('canvas'); c.width = i.naturalWidth; \
             c.height = i.naturalHeight; const g = c.getContext('2d'); g.drawImage(i, 0, 0); \
             const [sx, sy] = window.gradmesh.toScreen({x}, {y}); \
             const k = i.naturalWidth / i.getBoundingClientRect().width; \
             return Array.from(g.getImageData(Math.round(sx * k), Math.round(sy * k), 1, 1).data);"
        ),
    )
    .await;
    px.as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect()
}

async fn run_session(client: &Client, running: &Running) -> Result<(), String> {
    client
        .goto(&running.url())
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let state = js(
        client,
        "const s = window.gradmesh.state; return [s.layers.length, s.backdrops];",
    )
    .await;
    assert_eq!(state[0], json!(1), "the mesh gradient is one layer");
    let message = state[1][0]["message"]
        .as_str()
        .unwrap_or_default()
        .to_string();
    assert!(
        message.starts_with("drawing.svg: not editable, drawn as a locked backdrop: ")
            && message.contains("parts that are not mesh gradients left out")
            && message.ends_with("Colours fitted to the file's own painting of its meshes"),
        "the message lists what is not editable: {message}"
    );
    let shown = js(
        client,
        "const b = document.getElementById('backdrop-info'); return [b.hidden, b.textContent];",
    )
    .await;
    assert_eq!(shown[0], json!(false), "the panel shows the message");
    assert!(shown[1].as_str().unwrap().contains(&message));
    wait_for_backdrop(client).await;
    // The dark square shows beside the mesh and the circle over its corner; under the mesh the
    // square shows too, as the mesh fill is left out of the backdrop (for the layer to draw).
    assert_eq!(
        backdrop_pixel(client, 90.0, 150.0).await,
        vec![0x1a, 0x2a, 0x5a, 255]
    );
    assert_eq!(
        backdrop_pixel(client, 315.0, 228.0).await,
        vec![0xff, 0x80, 0, 255]
    );
    assert_eq!(
        backdrop_pixel(client, 200.0, 150.0).await,
        vec![0x1a, 0x2a, 0x5a, 255]
    );
    // The backdrop takes no clicks: a click on it leaves the selection empty.
    click(client, {
        let at = js(
            client,
            "const [x, y] = window.gradmesh.toScreen(90, 150); \
             const r = document.getElementById('overlay').getBoundingClientRect(); \
             return [r.left + x, r.top + y];",
        )
        .await;
        (at[0].as_f64().unwrap(), at[1].as_f64().unwrap())
    })
    .await;
    settle(client).await;
    assert_eq!(
        js(client, "return window.gradmesh.selection;").await,
        json!([])
    );
    // Zooming out draws the backdrop again at the new view.
    let before = js(client, "return document.getElementById('backdrop').src;").await;
    client
        .find(Locator::Id("overlay"))
        .await
        .map_err(|e| e.to_string())?
        .send_keys("-")
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let deadline = Instant::now() + Duration::from_secs(30);
    while js(client, "return document.getElementById('backdrop').src;").await == before {
        assert!(Instant::now() < deadline, "the backdrop follows the view");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    wait_for_backdrop(client).await;
    assert_eq!(
        backdrop_pixel(client, 70.0, 150.0).await,
        vec![0x1a, 0x2a, 0x5a, 255],
        "the square beside the mesh, which the view before did not show"
    );
    screenshot(client, "editor-svg-backdrop.png").await;

    open_exported(client).await
}

/// Opens `exported.svg` from the menu: its gradients joined, one large layer per layer exported.
async fn open_exported(client: &Client) -> Result<(), String> {
    let menu = client
        .find(Locator::Id("files"))
        .await
        .map_err(|e| e.to_string())?;
    menu.click().await.map_err(|e| e.to_string())?;
    let deadline = Instant::now() + Duration::from_secs(20);
    while js(
        client,
        "return [...document.querySelectorAll('#files option')].some((o) => o.value === 'exported.svg');",
    )
    .await
        != json!(true)
    {
        assert!(Instant::now() < deadline, "the menu lists no files");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    menu.select_by_value("exported.svg")
        .await
        .map_err(|e| e.to_string())?;
    let deadline = Instant::now() + Duration::from_secs(60);
    while js(
        client,
        "const s = window.gradmesh.state; return s ? s.file : null;",
    )
    .await
        != json!("exported.json")
    {
        assert!(Instant::now() < deadline, "the exported file did not open");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    settle(client).await;
    let layers = js(
        client,
        "return window.gradmesh.state.layers.map((l) => [l.points.length, l.faces.length]);",
    )
    .await;
    let layers = layers.as_array().unwrap();
    // Each of the three layers exported is one large mesh again; what stays apart are the
    // finer rings the export writes around irregular points (they meet at T-junctions).
    let large = layers
        .iter()
        .filter(|l| l[1].as_u64().unwrap() > 100)
        .count();
    assert_eq!(large, 3, "one large layer per layer exported: {layers:?}");
    assert!(
        layers.len() < 30,
        "far fewer layers than gradients: {layers:?}"
    );
    screenshot(client, "editor-svg-joined.png").await;
    Ok(())
}
