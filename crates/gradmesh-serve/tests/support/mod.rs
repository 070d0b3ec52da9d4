//! What the browser tests share: Chromium through chromedriver (WebDriver), one browser at a
//! time, and helpers that read the canvas, move the mouse and compare with gradmesh's render.
//! Each test binary uses a part of it.
#![allow(dead_code)]

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use fantoccini::actions::{InputSource, MouseActions, PointerAction, MOUSE_BUTTON_LEFT};
use fantoccini::{Client, ClientBuilder, Locator};
use gradmesh::render::{self, RenderOptions, View};
use hyper_util::client::legacy::connect::HttpConnector;
use serde_json::{json, Value};

pub const WINDOW: (u32, u32) = (1280, 900);

/// `name` on the `PATH`, or a clear failure.
pub fn program(names: &[&str]) -> PathBuf {
    let path = std::env::var_os("PATH").unwrap_or_default();
    for dir in std::env::split_paths(&path) {
        for name in names {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return candidate;
            }
        }
    }
    panic!(
        "the browser tests need {} on the PATH (Debian: apt-get install chromium chromium-driver)",
        names.join(" or ")
    );
}

/// chromedriver on a free loopback port, ended when dropped.
pub struct Driver {
    child: Child,
    /// The driver's WebDriver address.
    pub url: String,
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub fn start_driver() -> Driver {
    let binary = program(&["chromedriver"]);
    let port = TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port();
    let child = Command::new(binary)
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromedriver starts");
    let url = format!("http://127.0.0.1:{port}");
    let deadline = Instant::now() + Duration::from_secs(20);
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            Instant::now() < deadline,
            "chromedriver did not listen on {url}"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    Driver { child, url }
}

/// A Chromium session through a chromedriver of its own. Chromium's first start on a fresh
/// machine can reset the driver's connection; a session that fails to start is retried with a
/// new driver, three times at most.
pub async fn open_browser() -> (Driver, Client) {
    let mut attempt = 1;
    loop {
        let driver = start_driver();
        match try_open_browser(&driver).await {
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

pub async fn try_open_browser(
    driver: &Driver,
) -> Result<Client, fantoccini::error::NewSessionError> {
    let chromium = program(&["chromium", "chromium-browser"]);
    let mut caps = serde_json::Map::new();
    caps.insert(
        "goog:chromeOptions".into(),
        json!({
            "binary": chromium,
            "args": [
                "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                format!("--window-size={},{}", WINDOW.0, WINDOW.1),
                "--force-device-scale-factor=1",
            ],
        }),
    );
    ClientBuilder::new(HttpConnector::new())
        .capabilities(caps)
        .connect(&driver.url)
        .await
}

/// One browser at a time: two Chromium starts at once on two cores are what makes a start
/// fail.
pub static ONE_BROWSER: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

pub async fn js(client: &Client, script: &str) -> Value {
    client
        .execute(script, vec![])
        .await
        .unwrap_or_else(|e| panic!("script failed: {e}\n{script}"))
}

/// Waits until the page has its state and a frame, nothing is out or waiting, and the overlay
/// is drawn.
pub async fn settle(client: &Client) {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let ready = js(
            client,
            "const g = window.gradmesh; return !!g && g.state !== null && g.framesReceived > 0 \
             && !g.busy && g.pending.length === 0 && !g.overlayQueued && !g.foldsToCome;",
        )
        .await;
        if ready == json!(true) {
            // Each answer ends with "done", after its frame and state, and the folds a
            // state left out have come in the next: all has arrived.
            return;
        }
        assert!(Instant::now() < deadline, "the page did not settle");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// The picture canvas's pixels (RGBA8), width and height.
pub async fn canvas_pixels(client: &Client) -> (u32, u32, Vec<u8>) {
    let data = js(
        client,
        "const c = document.getElementById('picture'); \
         const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; \
         let s = ''; for (let i = 0; i < d.length; i += 8192) \
           s += String.fromCharCode.apply(null, d.subarray(i, i + 8192)); \
         return [c.width, c.height, btoa(s)];",
    )
    .await;
    let (w, h) = (
        data[0].as_u64().unwrap() as u32,
        data[1].as_u64().unwrap() as u32,
    );
    let bytes = decode_base64(data[2].as_str().unwrap());
    assert_eq!(bytes.len(), 4 * w as usize * h as usize);
    (w, h, bytes)
}

pub fn decode_base64(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => (c - b'A') as u32,
            b'a'..=b'z' => (c - b'a' + 26) as u32,
            b'0'..=b'9' => (c - b'0' + 52) as u32,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {c}"),
        }
    };
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    for chunk in text.as_bytes().chunks(4) {
        let pad = chunk.iter().filter(|&&c| c == b'=').count();
        let n = chunk
            .iter()
            .take(4 - pad)
            .fold(0u32, |acc, &c| (acc << 6) | value(c))
            << (6 * pad);
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    out
}

/// The screen position (viewport pixels) of point `p` of layer 0.
pub async fn point_on_screen(client: &Client, p: usize) -> (f64, f64) {
    let at = js(
        client,
        &format!(
            "const g = window.gradmesh; const [x, y] = g.toScreen(...g.state.layers[0].points[{p}]); \
             const r = document.getElementById('overlay').getBoundingClientRect(); \
             return [r.left + x, r.top + y];"
        ),
    )
    .await;
    (at[0].as_f64().unwrap(), at[1].as_f64().unwrap())
}

/// Drags from `from` by `by` in ten steps; the driver moves by whole pixels, so `by` should be
/// a multiple of ten.
pub async fn drag(client: &Client, from: (f64, f64), by: (f64, f64)) {
    let mut mouse = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: from.0.round(),
            y: from.1.round(),
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        });
    for _ in 0..10 {
        mouse = mouse.then(PointerAction::MoveBy {
            duration: Some(Duration::from_millis(20)),
            x: by.0 / 10.0,
            y: by.1 / 10.0,
        });
    }
    mouse = mouse.then(PointerAction::Up {
        button: MOUSE_BUTTON_LEFT,
    });
    client.perform_actions(mouse).await.expect("mouse drag");
}

pub async fn click(client: &Client, at: (f64, f64)) {
    let mouse = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: at.0.round(),
            y: at.1.round(),
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        })
        .then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
    client.perform_actions(mouse).await.expect("mouse click");
}

pub async fn screenshot(client: &Client, name: &str) {
    let png = client.screenshot().await.expect("a screenshot");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = root.join("target/editor-screenshots");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(name), &png).unwrap();
    if std::env::var_os("GRADMESH_UPDATE_SCREENSHOTS").is_some() {
        std::fs::write(root.join("docs").join(name), &png).unwrap();
    }
}

pub async fn click_id(client: &Client, id: &str) -> Result<(), String> {
    let element = client
        .find(Locator::Id(id))
        .await
        .map_err(|e| e.to_string())?;
    element.click().await.map_err(|e| e.to_string())
}

pub async fn type_into(client: &Client, id: &str, text: &str) -> Result<(), String> {
    let element = client
        .find(Locator::Id(id))
        .await
        .map_err(|e| e.to_string())?;
    element.clear().await.map_err(|e| e.to_string())?;
    element.send_keys(text).await.map_err(|e| e.to_string())
}

/// How many pixels differ between two images of the same size.
pub fn differing_pixels(a: &[u8], b: &[u8]) -> usize {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(p, q)| p != q)
        .count()
}

/// Compares the canvas with gradmesh's render of `file` in the page's view: pixels drawn
/// opaque must agree within 2 levels per channel (the canvas stores premultiplied colour);
/// returns the largest difference.
pub async fn compare_with_render(client: &Client, file: &Path, canvas: &(u32, u32, Vec<u8>)) -> u8 {
    let view = js(
        client,
        "const v = window.gradmesh.view; return [v.x0, v.y0, v.x1, v.y1];",
    )
    .await;
    let v: Vec<f64> = (0..4).map(|i| view[i].as_f64().unwrap()).collect();
    let doc = gradmesh::formats::read_path(file).expect("the saved file reads");
    let (w, h, pixels) = canvas;
    let opts = RenderOptions::new(*w, *h, View::new(v[0], v[1], v[2], v[3]));
    let mut expected = vec![0u8; pixels.len()];
    render::render_document_into(&doc, &opts, &mut expected).expect("the saved file renders");
    let mut worst = 0u8;
    for (p, q) in pixels.chunks_exact(4).zip(expected.chunks_exact(4)) {
        if q[3] == 255 {
            for c in 0..4 {
                worst = worst.max(p[c].abs_diff(q[c]));
            }
        } else {
            worst = worst.max(p[3].abs_diff(q[3]));
        }
    }
    worst
}

pub fn copy_example(dir: &Path) -> PathBuf {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/edge-kinds.json");
    let file = dir.join("edge-kinds.json");
    std::fs::copy(example, &file).expect("the example document");
    file
}
