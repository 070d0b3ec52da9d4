//! The editor's files in a real browser (headless Chromium through chromedriver, real pointer
//! and keyboard events): the save state and the question before a file is replaced, the
//! recovery copy restored from the page, the six layers of the Tucan opened as layers with
//! picking across layers, the preview, import as layer, the PDF export from the page, and a
//! document's own view as the first view.
//! Fails (never skips) when Chromium, chromedriver or the shared data is missing.
//!
//! Screenshots go to `target/editor-screenshots/`; with `GRADMESH_UPDATE_SCREENSHOTS=1` also
//! to `docs/editor-*.png`.

mod support;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use fantoccini::{Client, ClientBuilder, Locator};
use gradmesh_serve::{start, Config, Running};
use hyper_util::client::legacy::connect::HttpConnector;
use serde_json::{json, Value};
use support::*;

const SQUARE: &str = r##"{"format":"gradmesh","version":1,"layers":[{"name":"square","points":[
  {"position":[0,0],"colour":"#d04020"},{"position":[100,0],"colour":"#e0c030"},
  {"position":[100,100],"colour":"#2060c0"},{"position":[0,100],"colour":"#40a040"}],
  "faces":[[0,1,2,3]]}]}"##;

const CTRL: &str = "\u{E009}";
const TAB: &str = "\u{E004}";

/// The folder of the paper authors' OFF files, or a clear failure.
fn shared_off() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/realdata/gradientmeshimproved-off");
    assert!(
        dir.join("Tucan_Tucan_Layer0.off").is_file(),
        "the browser tests need the shared data in {}",
        dir.display()
    );
    dir
}

async fn serve(file: &Path, layers_above: Vec<PathBuf>) -> Running {
    start(&Config {
        file: Some(file.to_path_buf()),
        layers_above,
        ..Config::default()
    })
    .await
    .unwrap()
}

/// Runs `session` in a browser of its own (one browser at a time), closing it after.
macro_rules! in_browser {
    ($client:ident, $open:expr, $body:expr) => {{
        let _one = ONE_BROWSER.lock().await;
        let (_driver, $client) = $open;
        let result: Result<(), String> = $body;
        $client.close().await.ok();
        result.expect("the browser session");
    }};
}

async fn goto(client: &Client, running: &Running) -> Result<(), String> {
    client
        .goto(&running.url())
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    Ok(())
}

async fn text_of(client: &Client, id: &str) -> String {
    let script = format!("return document.getElementById('{id}').textContent;");
    js(client, &script).await.as_str().unwrap_or("").to_string()
}

async fn press_keys(client: &Client, keys: &str) -> Result<(), String> {
    let overlay = client
        .find(Locator::Id("overlay"))
        .await
        .map_err(|e| e.to_string())?;
    overlay.send_keys(keys).await.map_err(|e| e.to_string())
}

/// The text of the dialog the page opened, waiting for it.
async fn dialog_text(client: &Client) -> String {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        if let Ok(text) = client.get_alert_text().await {
            return text;
        }
        assert!(Instant::now() < deadline, "the page asked nothing");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// The screen position (viewport pixels) of point `p` of layer `layer`.
async fn layer_point_on_screen(client: &Client, layer: usize, p: usize) -> (f64, f64) {
    let at = js(
        client,
        &format!(
            "const g = window.gradmesh; const [x, y] = g.toScreen(...g.state.layers[{layer}].points[{p}]); \
             const r = document.getElementById('overlay').getBoundingClientRect(); \
             return [r.left + x, r.top + y];"
        ),
    )
    .await;
    (at[0].as_f64().unwrap(), at[1].as_f64().unwrap())
}

fn first_x(path: &Path) -> f64 {
    let doc = gradmesh::formats::read_path(path).unwrap();
    doc.layers[0].points[0].position.x
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_page_shows_the_save_state_and_asks_before_replacing_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("Tucan.off");
    std::fs::copy(shared_off().join("Tucan_Tucan_Layer0.off"), &off).unwrap();
    let json_file = dir.path().join("Tucan.json");
    std::fs::write(&json_file, SQUARE).unwrap();
    let running = serve(&off, Vec::new()).await;
    in_browser!(client, open_browser().await, {
        save_state(&client, &running, &json_file).await
    });
}

async fn save_state(client: &Client, running: &Running, json_file: &Path) -> Result<(), String> {
    goto(client, running).await?;
    assert_eq!(text_of(client, "file-name").await, "Tucan.json");
    assert_eq!(text_of(client, "file-modified").await, "");
    drag(client, point_on_screen(client, 0).await, (30.0, 20.0)).await;
    settle(client).await;
    assert_eq!(text_of(client, "file-modified").await, "modified");
    let leaving = "const e = new Event('beforeunload', {cancelable: true}); \
                   window.dispatchEvent(e); return e.defaultPrevented;";
    assert_eq!(
        js(client, leaving).await,
        json!(true),
        "leaving is questioned"
    );

    // Ctrl+S: Tucan.json exists and this editor did not write it: the page asks. No: untouched.
    // The question may open before the driver's answer to the keys: that answer is not needed.
    let _ = press_keys(client, &format!("{CTRL}s{CTRL}")).await;
    let question = dialog_text(client).await;
    assert!(question.contains("Tucan.json exists"), "{question}");
    client.dismiss_alert().await.map_err(|e| e.to_string())?;
    settle(client).await;
    assert_eq!(std::fs::read_to_string(json_file).unwrap(), SQUARE);
    assert_eq!(text_of(client, "file-modified").await, "modified");

    // Again, from the colour field (a text field has the focus): yes replaces it.
    click(client, point_on_screen(client, 0).await).await;
    let hex = client
        .find(Locator::Id("colour-hex"))
        .await
        .map_err(|e| e.to_string())?;
    hex.click().await.map_err(|e| e.to_string())?;
    let _ = hex.send_keys(&format!("{CTRL}s{CTRL}")).await;
    dialog_text(client).await;
    client.accept_alert().await.map_err(|e| e.to_string())?;
    settle(client).await;
    let saved_x = first_x(json_file);
    assert_ne!(saved_x, 0.0, "the Tucan's layer replaced the square");
    assert_eq!(text_of(client, "file-modified").await, "");
    let saved = text_of(client, "file-saved").await;
    assert!(saved.starts_with("Saved to Tucan.json at "), "{saved}");
    assert_eq!(js(client, leaving).await, json!(false), "nothing to lose");
    screenshot(client, "editor-saved.png").await;

    // The editor wrote it: the next Ctrl+S saves without a question.
    drag(client, point_on_screen(client, 0).await, (20.0, 0.0)).await;
    settle(client).await;
    press_keys(client, &format!("{CTRL}s{CTRL}")).await?;
    settle(client).await;
    assert!(client.get_alert_text().await.is_err(), "no question");
    assert!(first_x(json_file) > saved_x, "saved again");
    Ok(())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_page_offers_the_recovery_copy_and_restores_it() {
    let dir = tempfile::tempdir().unwrap();
    let state_dir = tempfile::tempdir().unwrap();
    let file = copy_example(dir.path());
    let mut recovered = gradmesh::formats::read_path(&file).unwrap();
    recovered.layers[0].points[7].position.x += 0.25;
    recovered.layers[0].points[7].colour = [60.0, 70.0, -40.0];
    recovered.layers[0].points[7].colour_text = None;
    let text = gradmesh::formats::json::write_document(&recovered);
    let copy = dir.path().join(".edge-kinds.json.recover");
    std::fs::write(&copy, &text).unwrap();
    // The same document under a name the renderer reads, to compare the canvas with.
    let same = dir.path().join("recovered.json");
    std::fs::write(&same, &text).unwrap();
    let running = serve(&file, Vec::new()).await;
    {
        let editor = running.app.editor();
        let mut files = running.app.files();
        let warning = files.enable_recovery(Some(state_dir.path().to_path_buf()), &editor);
        assert_eq!(warning, None);
    }
    in_browser!(client, open_browser().await, {
        restore(&client, &running, &text, &same).await
    });
}

async fn restore(
    client: &Client,
    running: &Running,
    text: &str,
    same: &Path,
) -> Result<(), String> {
    goto(client, running).await?;
    let shown = js(
        client,
        "return !document.getElementById('recovery').hidden;",
    )
    .await;
    assert_eq!(shown, json!(true), "the page offers the copy");
    assert!(text_of(client, "recovery-text")
        .await
        .contains(".edge-kinds.json.recover"));
    screenshot(client, "editor-recovery.png").await;
    // Edits wait for the choice.
    drag(client, point_on_screen(client, 7).await, (40.0, 0.0)).await;
    settle(client).await;
    let message = text_of(client, "message").await;
    assert!(message.contains("restore or discard"), "{message}");

    click_id(client, "recovery-restore").await?;
    settle(client).await;
    let shown = js(
        client,
        "return !document.getElementById('recovery').hidden;",
    )
    .await;
    assert_eq!(shown, json!(false));
    assert_eq!(text_of(client, "file-modified").await, "modified");
    let doc = gradmesh::formats::json::write_document(&running.app.editor().history.current().doc);
    assert_eq!(doc, text, "the document is the copy");
    let canvas = canvas_pixels(client).await;
    let worst = compare_with_render(client, same, &canvas).await;
    assert!(
        worst <= 2,
        "the canvas differs from the copy's render by {worst}"
    );
    Ok(())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_six_tucan_layers_open_as_layers_with_picking_and_preview() {
    let shared = shared_off();
    let files: Vec<PathBuf> = (0..6)
        .rev()
        .map(|i| shared.join(format!("Tucan_Tucan_Layer{i}.off")))
        .collect();
    let running = serve(&files[0], files[1..].to_vec()).await;
    in_browser!(client, open_browser().await, {
        tucan_layers(&client, &running, &files).await
    });
}

async fn tucan_layers(client: &Client, running: &Running, files: &[PathBuf]) -> Result<(), String> {
    goto(client, running).await?;
    let names = js(
        client,
        "return window.gradmesh.state.layers.map((l) => l.name);",
    )
    .await;
    let expected: Vec<Value> = (0..6)
        .rev()
        .map(|i| json!(format!("Tucan_Tucan_Layer{i}")))
        .collect();
    assert_eq!(
        names,
        Value::Array(expected),
        "the files in order, bottom first"
    );
    assert_eq!(
        text_of(client, "file-name").await,
        "new document (not saved)"
    );
    // The canvas is the render of the six files drawn in order.
    let joined = tempfile::tempdir().unwrap();
    let mut layers = Vec::new();
    for file in files {
        layers.extend(gradmesh::formats::read_path(file).unwrap().layers);
    }
    let whole = joined.path().join("tucan.json");
    let text = gradmesh::formats::json::write_document(&gradmesh::Document::new(layers));
    std::fs::write(&whole, text).unwrap();
    let canvas = canvas_pixels(client).await;
    let worst = compare_with_render(client, &whole, &canvas).await;
    assert!(
        worst <= 2,
        "the canvas differs from the render by {worst} levels"
    );

    // A click on a point of another layer selects it there and makes that layer active.
    let state = js(
        client,
        "return window.gradmesh.state.layers.map((l) => l.points);",
    )
    .await;
    for layer in [5usize, 0, 3] {
        let p = lonely_point(client, &state, layer).await;
        click(client, layer_point_on_screen(client, layer, p).await).await;
        settle(client).await;
        let picked = js(
            client,
            "const g = window.gradmesh; return [g.activeLayer, g.selection];",
        )
        .await;
        assert_eq!(
            picked,
            json!([layer, [p]]),
            "a click on point {p} of layer {layer}"
        );
    }

    // Preview (Tab): the overlay is empty; Tab again brings the mesh back.
    let overlay_pixels = "const c = document.getElementById('overlay'); \
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; \
        let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i]) n++; return n;";
    assert!(js(client, overlay_pixels).await.as_u64().unwrap() > 100);
    press_keys(client, TAB).await?;
    assert_eq!(
        js(client, overlay_pixels).await,
        json!(0),
        "preview hides the mesh"
    );
    screenshot(client, "editor-preview.png").await;
    press_keys(client, TAB).await?;
    assert!(js(client, overlay_pixels).await.as_u64().unwrap() > 100);
    // The layer's "mesh shown" box hides its mesh alone; its picture stays.
    let boxes = client
        .find_all(Locator::Css("#layers li .mesh-shown"))
        .await
        .map_err(|e| e.to_string())?;
    let active = js(client, "return window.gradmesh.activeLayer;")
        .await
        .as_u64()
        .unwrap() as usize;
    boxes[5 - active].click().await.map_err(|e| e.to_string())?;
    assert_eq!(
        js(client, overlay_pixels).await,
        json!(0),
        "the active layer's mesh is hidden"
    );
    settle(client).await;
    assert_eq!(
        differing_pixels(&canvas.2, &canvas_pixels(client).await.2),
        0,
        "the picture stays"
    );
    boxes[5 - active].click().await.map_err(|e| e.to_string())?;
    screenshot(client, "editor-layers.png").await;
    Ok(())
}

/// A point of `layer` with no point of any other layer within 12 pixels on screen.
async fn lonely_point(client: &Client, points: &Value, layer: usize) -> usize {
    let scale = js(client, "const g = window.gradmesh; return document.getElementById('overlay').getBoundingClientRect().width / (g.view.x1 - g.view.x0);").await.as_f64().unwrap();
    let xy = |v: &Value| (v[0].as_f64().unwrap(), v[1].as_f64().unwrap());
    let layers = points.as_array().unwrap();
    let own = layers[layer].as_array().unwrap();
    (0..own.len())
        .find(|&p| {
            let (x, y) = xy(&own[p]);
            layers.iter().enumerate().all(|(l, others)| {
                others.as_array().unwrap().iter().enumerate().all(|(q, o)| {
                    let (ox, oy) = xy(o);
                    (l == layer && q == p) || ((ox - x).hypot(oy - y) * scale > 12.0)
                })
            })
        })
        .unwrap_or_else(|| panic!("layer {layer} has no point apart from the others"))
}

/// A Chromium session that downloads into `dir` without asking.
async fn open_downloading_browser(dir: &Path) -> (Driver, Client) {
    let mut attempt = 1;
    loop {
        let driver = start_driver();
        let mut caps = serde_json::Map::new();
        caps.insert(
            "goog:chromeOptions".into(),
            json!({
                "binary": program(&["chromium", "chromium-browser"]),
                "args": [
                    "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                    format!("--window-size={},{}", WINDOW.0, WINDOW.1),
                    "--force-device-scale-factor=1",
                ],
                "prefs": {
                    "download.default_directory": dir,
                    "download.prompt_for_download": false,
                },
            }),
        );
        let connected = ClientBuilder::new(HttpConnector::new())
            .capabilities(caps)
            .connect(&driver.url)
            .await;
        match connected {
            Ok(client) => return (driver, client),
            Err(e) if attempt < 3 => {
                eprintln!("a Chromium session did not start ({e}); retrying");
                attempt += 1;
                tokio::time::sleep(Duration::from_secs(1)).await;
            }
            Err(e) => panic!("a Chromium session through chromedriver: {e}"),
        }
    }
}

/// A document with a view of its own (a vectorised picture's rectangle) opens showing that
/// rectangle, not the bounds of its points.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_document_opens_on_its_own_view() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("framed.json");
    let framed = SQUARE.replacen(
        r#""version":1,"#,
        r#""version":1,"view":[-100,-50,300,150],"#,
        1,
    );
    std::fs::write(&file, framed).unwrap();
    let running = serve(&file, Vec::new()).await;
    in_browser!(client, open_browser().await, {
        own_view(&client, &running).await
    });
}

async fn own_view(client: &Client, running: &Running) -> Result<(), String> {
    goto(client, running).await?;
    let v = js(
        client,
        "const v = window.gradmesh.view; return [v.x0, v.y0, v.x1, v.y1];",
    )
    .await;
    let v: Vec<f64> = (0..4).map(|k| v[k].as_f64().unwrap()).collect();
    // The points span 0..100 both ways (centre (50, 50)); the document's view -100..300 x
    // -50..150 (centre (100, 50)).
    let centre = [(v[0] + v[2]) / 2.0, (v[1] + v[3]) / 2.0];
    assert!(
        (centre[0] - 100.0).abs() < 1e-6 && (centre[1] - 50.0).abs() < 1e-6,
        "the first view {v:?} is not centred on the document's view"
    );
    assert!(
        v[0] <= -100.0 && v[1] <= -50.0 && v[2] >= 300.0 && v[3] >= 150.0,
        "the first view {v:?} does not hold the document's view"
    );
    assert!(
        v[2] - v[0] < 1.5 * 400.0,
        "the first view {v:?} is far wider"
    );
    Ok(())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_layer_is_imported_and_the_pdf_exported_from_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let downloads = tempfile::tempdir().unwrap();
    let file = dir.path().join("square.json");
    std::fs::write(&file, SQUARE).unwrap();
    std::fs::copy(
        shared_off().join("Tucan_Tucan_Layer0.off"),
        dir.path().join("beak.off"),
    )
    .unwrap();
    let running = serve(&file, Vec::new()).await;
    in_browser!(client, open_downloading_browser(downloads.path()).await, {
        import_and_export(&client, &running, downloads.path()).await
    });
}

async fn import_and_export(
    client: &Client,
    running: &Running,
    downloads: &Path,
) -> Result<(), String> {
    goto(client, running).await?;
    let import = client
        .find(Locator::Id("import-layer"))
        .await
        .map_err(|e| e.to_string())?;
    import.click().await.map_err(|e| e.to_string())?;
    // The menu lists the folder's documents when it opens.
    let deadline = Instant::now() + Duration::from_secs(20);
    while js(
        client,
        "return document.querySelectorAll('#import-layer option').length;",
    )
    .await
        != json!(3)
    {
        assert!(Instant::now() < deadline, "the import menu lists no files");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    import
        .select_by_value("beak.off")
        .await
        .map_err(|e| e.to_string())?;
    settle(client).await;
    let layers = js(client, "const g = window.gradmesh; return [g.state.layers.length, g.activeLayer, g.state.layers[1].name];").await;
    assert_eq!(layers, json!([2, 1, "beak"]), "imported above, and active");
    // Keys reach the canvas after the menu: Ctrl+A selects the new layer's points.
    press_keys(client, &format!("{CTRL}a{CTRL}")).await?;
    let selected = js(client, "return window.gradmesh.selection.length;").await;
    assert_eq!(selected, json!(12));

    let export = client
        .find(Locator::Id("export"))
        .await
        .map_err(|e| e.to_string())?;
    export
        .select_by_value("pdf")
        .await
        .map_err(|e| e.to_string())?;
    let pdf = downloads.join("square.pdf");
    let deadline = Instant::now() + Duration::from_secs(120);
    while !pdf.is_file() {
        assert!(
            Instant::now() < deadline,
            "no square.pdf downloaded; the folder holds {:?}",
            std::fs::read_dir(downloads)
                .unwrap()
                .map(|e| e.unwrap().file_name())
                .collect::<Vec<_>>()
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    let bytes = std::fs::read(&pdf).unwrap();
    assert!(bytes.starts_with(b"%PDF-"), "a PDF");
    assert!(
        bytes.windows(12).any(|w| w == b"/ShadingType"),
        "with the mesh as shadings"
    );
    Ok(())
}
