//! The server's API without a browser: the token, `Host` and `Origin` checks, the folder's
//! bounds, body limits, malformed requests, saving, a page that goes away mid-edit, and the
//! multi-resolution and side edits.

use std::path::Path;

use futures_util::{SinkExt, StreamExt};
use gradmesh_serve::{start, Config, Running};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::Message;

const SQUARE: &str = r##"{"format":"gradmesh","version":1,"layers":[{"name":"square","points":[
  {"position":[0,0],"colour":"#d04020"},{"position":[100,0],"colour":"#e0c030"},
  {"position":[100,100],"colour":"#2060c0"},{"position":[0,100],"colour":"#40a040"}],
  "faces":[[0,1,2,3]]}]}"##;

/// A server on a folder holding `square.json`.
async fn serve_square() -> (Running, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("square.json");
    std::fs::write(&file, SQUARE).unwrap();
    gradmesh::formats::read_path(&file).expect("the test document reads");
    let running = start(&Config {
        file: Some(file),
        folder: None,
        port: 0,
        ..Config::default()
    })
    .await
    .unwrap();
    (running, dir)
}

/// Sends one HTTP/1.1 request with exactly the headers given (and `Content-Length`); returns
/// the status code and the body.
async fn request(
    running: &Running,
    method: &str,
    target: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> (u16, String) {
    let mut stream = TcpStream::connect(running.address).await.unwrap();
    let mut head = format!("{method} {target} HTTP/1.1\r\nConnection: close\r\n");
    for (name, value) in headers {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str(&format!("Content-Length: {}\r\n\r\n", body.len()));
    stream.write_all(head.as_bytes()).await.unwrap();
    // A server may answer (413) before reading a large body, and close.
    let _ = stream.write_all(body).await;
    let mut answer = Vec::new();
    let _ = stream.read_to_end(&mut answer).await;
    let text = String::from_utf8_lossy(&answer).to_string();
    let status = text
        .split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no HTTP answer: {text:?}"));
    let body = text.split_once("\r\n\r\n").map(|(_, b)| b.to_string());
    (status, body.unwrap_or_default())
}

fn host(running: &Running) -> String {
    format!("127.0.0.1:{}", running.address.port())
}

async fn get(running: &Running, target: &str) -> (u16, String) {
    request(running, "GET", target, &[("Host", &host(running))], b"").await
}

async fn command(running: &Running, json: &str) -> (u16, String) {
    let target = format!("/api/command?token={}", running.token);
    let headers = [
        ("Host", host(running)),
        ("Content-Type", "application/json".to_string()),
    ];
    let headers: Vec<(&str, &str)> = headers.iter().map(|(n, v)| (*n, v.as_str())).collect();
    request(running, "POST", &target, &headers, json.as_bytes()).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn listens_on_loopback_only() {
    let (running, _dir) = serve_square().await;
    assert!(running.address.ip().is_loopback(), "{}", running.address);
    assert!(running.url().starts_with("http://127.0.0.1:"));
    assert!(running.url().ends_with(&running.token));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_route_needs_the_token() {
    let (running, _dir) = serve_square().await;
    let token = &running.token;
    let wrong = "0".repeat(token.len());
    for route in [
        "/",
        "/app.js",
        "/style.css",
        "/api/state",
        "/api/files",
        "/api/picture.png",
    ] {
        let (status, body) = get(&running, route).await;
        assert_eq!(status, 401, "{route} without a token: {body}");
        assert!(body.contains("token"), "{body}");
        let join = if route.contains('?') { '&' } else { '?' };
        let (status, _) = get(&running, &format!("{route}{join}token={wrong}")).await;
        assert_eq!(status, 401, "{route} with a wrong token");
        let (status, _) = get(&running, &format!("{route}{join}token={token}")).await;
        assert_eq!(status, 200, "{route} with the token");
    }
    let (status, page) = get(&running, &format!("/?token={token}")).await;
    assert_eq!(status, 200);
    assert!(page.contains(&format!("/app.js?token={token}")));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn foreign_host_and_origin_are_refused() {
    let (running, _dir) = serve_square().await;
    let target = format!("/api/state?token={}", running.token);
    let port = running.address.port();
    let rebinding = format!("attacker.example:{port}");
    let (status, body) = request(&running, "GET", &target, &[("Host", &rebinding)], b"").await;
    assert_eq!(status, 403, "{body}");
    assert!(body.contains("Host"), "{body}");
    let (status, _) = request(&running, "GET", &target, &[], b"").await;
    assert_eq!(status, 403, "no Host header");
    let good_host = host(&running);
    for origin in ["http://attacker.example", "null", "https://127.0.0.1:1"] {
        let headers = [("Host", good_host.as_str()), ("Origin", origin)];
        let (status, body) = request(&running, "GET", &target, &headers, b"").await;
        assert_eq!(status, 403, "{origin}: {body}");
    }
    let own = format!("http://localhost:{port}");
    let headers = [("Host", good_host.as_str()), ("Origin", own.as_str())];
    assert_eq!(
        request(&running, "GET", &target, &headers, b"").await.0,
        200
    );
}

/// Opens the WebSocket with the given token and origin; the HTTP status if refused.
async fn open_socket(
    running: &Running,
    token: &str,
    origin: &str,
) -> Result<tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<TcpStream>>, u16> {
    let url = format!("ws://{}/ws?token={token}", running.address);
    let mut request = url.into_client_request().unwrap();
    request
        .headers_mut()
        .insert("Origin", origin.parse().unwrap());
    match tokio_tungstenite::connect_async(request).await {
        Ok((socket, _)) => Ok(socket),
        Err(tokio_tungstenite::tungstenite::Error::Http(response)) => {
            Err(response.status().as_u16())
        }
        Err(e) => panic!("WebSocket: {e}"),
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_websocket_needs_the_token_and_origin() {
    let (running, _dir) = serve_square().await;
    let own = format!("http://127.0.0.1:{}", running.address.port());
    assert_eq!(open_socket(&running, "nope", &own).await.err(), Some(401));
    let foreign = open_socket(&running, &running.token, "http://attacker.example").await;
    assert_eq!(foreign.err(), Some(403));
    assert!(open_socket(&running, &running.token, &own).await.is_ok());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn nothing_outside_the_folder_is_read_or_written() {
    let (running, dir) = serve_square().await;
    let outside = tempfile::tempdir().unwrap();
    std::fs::write(outside.path().join("secret.json"), SQUARE).unwrap();
    std::os::unix::fs::symlink(outside.path(), dir.path().join("link")).unwrap();
    std::os::unix::fs::symlink(
        outside.path().join("secret.json"),
        dir.path().join("secret.json"),
    )
    .unwrap();
    let secret = outside.path().join("secret.json");
    let names = [
        "../secret.json".to_string(),
        secret.display().to_string(),
        "link/secret.json".to_string(),
        "secret.json".to_string(),
        "link/new.json".to_string(),
    ];
    for name in &names {
        let (status, body) =
            command(&running, &format!(r#"{{"type":"open","name":{name:?}}}"#)).await;
        assert!((400..500).contains(&status), "open {name}: {status} {body}");
        assert!(body.contains("refused"), "{body}");
        let (status, body) = command(
            &running,
            &format!(r#"{{"type":"save_as","name":{name:?}}}"#),
        )
        .await;
        assert!(
            (400..500).contains(&status),
            "save as {name}: {status} {body}"
        );
    }
    assert_eq!(std::fs::read_to_string(&secret).unwrap(), SQUARE);
    assert!(!outside.path().join("new.json").exists());
    let (status, _) = get(
        &running,
        &format!("/../secret.json?token={}", running.token),
    )
    .await;
    assert_eq!(status, 404);
    let (status, files) = get(&running, &format!("/api/files?token={}", running.token)).await;
    assert_eq!((status, files.as_str()), (200, r#"["square.json"]"#));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn large_and_malformed_requests_get_4xx_with_a_message() {
    let (running, _dir) = serve_square().await;
    let big = format!(r#"{{"type":"open","name":"{}"}}"#, "a".repeat(2 << 20));
    let (status, _) = command(&running, &big).await;
    assert_eq!(status, 413);
    for (json, expected) in [
        ("{", 400),
        (r#"{"type":"fly"}"#, 400),
        (
            r#"{"type":"edit","op":{"op":"move_points","layer":0}}"#,
            400,
        ),
        (
            r#"{"type":"edit","op":{"op":"move_points","layer":7,"points":[0],"dx":1,"dy":1}}"#,
            422,
        ),
        (
            r#"{"type":"edit","op":{"op":"move_points","layer":0,"points":[99],"dx":1,"dy":1}}"#,
            422,
        ),
        (
            r#"{"type":"edit","op":{"op":"add_face","layer":0,"points":[0,1]}}"#,
            422,
        ),
        (
            r#"{"type":"edit","op":{"op":"set_colour","layer":0,"points":[0],"css":"no colour"}}"#,
            422,
        ),
        (r#"{"type":"save_as","name":"square.txt"}"#, 422),
    ] {
        let (status, body) = command(&running, json).await;
        assert_eq!(status, expected, "{json}: {body}");
        assert!(!body.is_empty());
    }
    // Nothing was changed, and the server still answers.
    let (status, state) = get(&running, &format!("/api/state?token={}", running.token)).await;
    assert_eq!(status, 200);
    assert!(state.contains(r#""can_undo":false"#), "{state}");
}

fn read_x0(path: &Path) -> f64 {
    let doc = gradmesh::formats::read_path(path).unwrap();
    doc.layers[0].points[0].position.x
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn saving_is_whole_and_a_page_leaving_mid_edit_loses_nothing_saved() {
    let (running, dir) = serve_square().await;
    let file = dir.path().join("square.json");
    let edit = r#"{"type":"edit","op":{"op":"move_points","layer":0,"points":[0],"dx":5,"dy":0}}"#;
    assert_eq!(command(&running, edit).await.0, 200);
    assert_eq!(command(&running, r#"{"type":"save"}"#).await.0, 200);
    assert_eq!(read_x0(&file), 5.0);

    // A page sends a view and a drag, and goes away without reading the answers.
    let own = format!("http://127.0.0.1:{}", running.address.port());
    let mut socket = open_socket(&running, &running.token, &own).await.unwrap();
    let view = r#"{"type":"view","width":300,"height":300,"view":[-10,-10,110,110]}"#;
    let drag = r#"{"type":"edit","gesture":9,"op":{"op":"move_points","layer":0,"points":[0],"dx":20,"dy":0}}"#;
    for text in [view, drag, drag] {
        socket.send(Message::Text(text.into())).await.unwrap();
    }
    drop(socket);
    // What the server received before the connection closed is applied (what was still in
    // flight may be lost with the connection); the saved file stays whole and as saved.
    tokio::time::sleep(std::time::Duration::from_millis(300)).await;
    assert_eq!(read_x0(&file), 5.0);
    let mut socket = open_socket(&running, &running.token, &own).await.unwrap();
    socket
        .send(Message::Text(r#"{"type":"state"}"#.into()))
        .await
        .unwrap();
    let mut got_state = false;
    while let Some(Ok(message)) = socket.next().await {
        match message {
            Message::Text(text) if text.contains(r#""type":"state""#) => got_state = true,
            Message::Text(text) if text.contains(r#""type":"done""#) => break,
            _ => {}
        }
    }
    assert!(got_state);
    let state = get(&running, &format!("/api/state?token={}", running.token))
        .await
        .1;
    let x_now = if state.contains("[25.0,0.0]") {
        25.0
    } else {
        5.0
    };
    assert_eq!(read_x0(&file), 5.0);
    assert_eq!(command(&running, r#"{"type":"save"}"#).await.0, 200);
    assert_eq!(read_x0(&file), x_now);
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    assert_eq!(
        names,
        vec!["square.json".to_string()],
        "no temporary files left"
    );
    // Save as: a new file in the folder; "save" then writes it.
    assert_eq!(
        command(&running, r#"{"type":"save_as","name":"copy.json"}"#)
            .await
            .0,
        200
    );
    assert_eq!(read_x0(&dir.path().join("copy.json")), x_now);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_new_document_is_drawn_and_saved_as() {
    let dir = tempfile::tempdir().unwrap();
    let running = start(&Config {
        file: None,
        folder: Some(dir.path().to_path_buf()),
        port: 0,
        ..Config::default()
    })
    .await
    .unwrap();
    let rectangle = r#"{"type":"edit","op":{"op":"add_rectangle","layer":0,"rect":[0,0,40,30]}}"#;
    assert_eq!(command(&running, rectangle).await.0, 200);
    let (status, body) = command(&running, r#"{"type":"save"}"#).await;
    assert_eq!(status, 422, "{body}");
    assert!(body.contains("Save as"), "{body}");
    let (status, _) = command(&running, r#"{"type":"save_as","name":"new.json"}"#).await;
    assert_eq!(status, 200);
    let doc = gradmesh::formats::read_path(&dir.path().join("new.json")).unwrap();
    assert_eq!(
        (doc.layers[0].points.len(), doc.layers[0].faces.len()),
        (4, 1)
    );
    let (status, png) = get(
        &running,
        &format!("/api/picture.png?token={}", running.token),
    )
    .await;
    assert_eq!(status, 200);
    assert!(png.contains("PNG"));
    // Open another document of the folder: a copy of the example with its creases.
    let example =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/edge-kinds.json");
    std::fs::copy(example, dir.path().join("edges.json")).unwrap();
    let (status, state) = command(&running, r#"{"type":"open","name":"edges.json"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert!(state.contains(r#""file":"edges.json""#), "{state}");
    assert!(state.contains(r#""crease""#), "{state}");
    assert!(state.contains(r#""can_undo":false"#), "{state}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_oversized_websocket_message_closes_only_that_connection() {
    let (running, _dir) = serve_square().await;
    let own = format!("http://127.0.0.1:{}", running.address.port());
    let mut socket = open_socket(&running, &running.token, &own).await.unwrap();
    let huge = format!(r#"{{"type":"open","name":"{}"}}"#, "a".repeat(2 << 20));
    let _ = socket.send(Message::Text(huge.into())).await;
    // The server ends the connection: the stream closes (or errs) instead of waiting.
    let ended = tokio::time::timeout(std::time::Duration::from_secs(10), async {
        while let Some(Ok(message)) = socket.next().await {
            if let Message::Close(_) = message {
                break;
            }
        }
    })
    .await;
    assert!(
        ended.is_ok(),
        "the connection stays open after an oversized message"
    );
    let (status, _) = get(&running, &format!("/api/state?token={}", running.token)).await;
    assert_eq!(status, 200, "the server goes on");
}

// ---- multi-resolution and side edits through the API ----------------------------------------

async fn edit_command(
    running: &Running,
    op: serde_json::Value,
    gesture: Option<u64>,
) -> (u16, String) {
    let mut command_json = serde_json::json!({"type": "edit", "op": op});
    if let Some(g) = gesture {
        command_json["gesture"] = g.into();
    }
    command(running, &command_json.to_string()).await
}

async fn document(running: &Running) -> gradmesh::Document {
    let (status, text) = get(
        running,
        &format!("/api/document.json?token={}", running.token),
    )
    .await;
    assert_eq!(status, 200, "{text}");
    gradmesh::formats::json::read_document(&text).unwrap()
}

/// The limit position of the refined vertex `at` of the sector of `point` in face 0, level 2.
async fn refined_position(running: &Running, point: u32, at: [u32; 2]) -> [f64; 2] {
    let target = format!(
        "/api/refined?token={}&layer=0&face=0&level=2",
        running.token
    );
    let (status, text) = get(running, &target).await;
    assert_eq!(status, 200, "{text}");
    let vertices: serde_json::Value = serde_json::from_str(&text).unwrap();
    let v = (vertices.as_array().unwrap().iter())
        .find(|v| v["point"] == point && v["at"] == serde_json::json!(at))
        .expect("the vertex is listed");
    [
        v["position"][0].as_f64().unwrap(),
        v["position"][1].as_f64().unwrap(),
    ]
}

fn assert_near(got: [f64; 2], want: [f64; 2]) {
    let d = (got[0] - want[0]).hypot(got[1] - want[1]);
    assert!(d < 1e-6, "at {got:?}, expected {want:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_refined_vertex_moves_where_it_is_dragged_and_undoes() {
    let (running, _dir) = serve_square().await;
    let centre = [50.0, 50.0];
    let mv = |dx: f64, dy: f64| {
        serde_json::json!({"op": "move_refined_vertex", "layer": 0, "level": 2, "face": 0,
            "point": 0, "at": [1, 2], "dx": dx, "dy": dy})
    };
    let start = refined_position(&running, 0, [1, 2]).await;
    assert_near(refined_position(&running, 0, [3, 3]).await, centre);
    // Two moves of one gesture: each from where the gesture began, so the second wins.
    assert_eq!(edit_command(&running, mv(30.0, 5.0), Some(1)).await.0, 200);
    assert_eq!(edit_command(&running, mv(12.0, -7.0), Some(1)).await.0, 200);
    assert_eq!(command(&running, r#"{"type":"end_gesture"}"#).await.0, 200);
    let moved = [start[0] + 12.0, start[1] - 7.0];
    assert_near(refined_position(&running, 0, [1, 2]).await, moved);
    let edit = document(&running).await.layers[0].edits[0].clone();
    assert!(edit.offset.is_some() && edit.colour.is_none());
    // A second drag starts from where the first left it.
    assert_eq!(edit_command(&running, mv(-2.0, 4.0), Some(2)).await.0, 200);
    assert_near(
        refined_position(&running, 0, [1, 2]).await,
        [moved[0] - 2.0, moved[1] + 4.0],
    );
    assert_eq!(command(&running, r#"{"type":"undo"}"#).await.0, 200);
    assert_near(refined_position(&running, 0, [1, 2]).await, moved);
    assert_eq!(command(&running, r#"{"type":"undo"}"#).await.0, 200);
    assert_near(refined_position(&running, 0, [1, 2]).await, start);
    assert!(document(&running).await.layers[0].edits.is_empty());
    assert_eq!(command(&running, r#"{"type":"redo"}"#).await.0, 200);
    assert_near(refined_position(&running, 0, [1, 2]).await, moved);
    // Setting a colour keeps the move; an offset can be given outright, in the vertex's frame.
    let set = serde_json::json!({"op": "set_refined_edit", "layer": 0, "level": 2, "face": 0,
        "point": 0, "at": [1, 2], "colour": [50.0, 20.0, 0.0]});
    assert_eq!(edit_command(&running, set, None).await.0, 200);
    assert_near(refined_position(&running, 0, [1, 2]).await, moved);
    let set = serde_json::json!({"op": "set_refined_edit", "layer": 0, "level": 2, "face": 0,
        "point": 0, "at": [1, 2], "colour": [50.0, 20.0, 0.0], "offset": [0.0, 0.0]});
    assert_eq!(edit_command(&running, set, None).await.0, 200);
    assert_near(refined_position(&running, 0, [1, 2]).await, start);
    // The centre was not moved by any of it.
    assert_near(refined_position(&running, 0, [3, 3]).await, centre);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_colour_only_layer_refuses_moving_a_refined_vertex_with_the_validators_message() {
    let (running, dir) = serve_square().await;
    let colour_only = SQUARE.replace(
        r#""name":"square","#,
        r#""name":"square","fine_edits":"colour-only","#,
    );
    std::fs::write(dir.path().join("colour-only.json"), colour_only).unwrap();
    let open = r#"{"type":"open","name":"colour-only.json"}"#;
    assert_eq!(command(&running, open).await.0, 200);
    let mv = serde_json::json!({"op": "move_refined_vertex", "layer": 0, "level": 2, "face": 0,
        "point": 0, "at": [1, 2], "dx": 3.0, "dy": 0.0});
    let (status, text) = edit_command(&running, mv, None).await;
    assert_eq!(status, 422, "{text}");
    assert!(text.contains("colour edits only"), "{text}");
    let set = serde_json::json!({"op": "set_refined_edit", "layer": 0, "level": 2, "face": 0,
        "point": 0, "at": [1, 2], "offset": [0.5, 0.0]});
    let (status, text) = edit_command(&running, set, None).await;
    assert_eq!(status, 422, "{text}");
    assert!(text.contains("colour edits only"), "{text}");
    assert!(document(&running).await.layers[0].edits.is_empty());
    let state = get(&running, &format!("/api/state?token={}", running.token))
        .await
        .1;
    assert!(
        state.contains(r#""can_undo":false"#),
        "a refused edit makes no step"
    );
}

/// Two squares side by side, the edge between them (points 1 and 4) discontinuous.
const TWO_SIDES: &str = r##"{"format":"gradmesh","version":1,"layers":[{"name":"two","points":[
  {"position":[0,0],"colour":"#d04020"},{"position":[100,0],"colour":"#e0c030"},
  {"position":[200,0],"colour":"#2060c0"},{"position":[0,100],"colour":"#40a040"},
  {"position":[100,100],"colour":"#802080"},{"position":[200,100],"colour":"#208080"}],
  "faces":[[0,1,4,3],[1,2,5,4]],
  "edges":[{"points":[1,4],"kind":"discontinuous"}]}]}"##;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_side_of_a_discontinuity_takes_its_own_opacity_and_undoes() {
    let (running, dir) = serve_square().await;
    std::fs::write(dir.path().join("two.json"), TWO_SIDES).unwrap();
    assert_eq!(
        command(&running, r#"{"type":"open","name":"two.json"}"#)
            .await
            .0,
        200
    );
    let side_opacity = |opacity: Option<f64>| {
        let mut op =
            serde_json::json!({"op": "set_side_opacity", "layer": 0, "point": 1, "face": 1});
        if let Some(o) = opacity {
            op["opacity"] = o.into();
        }
        op
    };
    // A side without an entry gets one, with the point's colour.
    let (status, state) = edit_command(&running, side_opacity(Some(0.25)), None).await;
    assert_eq!(status, 200, "{state}");
    assert!(
        state.contains(r##""sides":[[1,1,"#e0c030",0.25]]"##),
        "{state}"
    );
    let layer = document(&running).await.layers.remove(0);
    assert_eq!(layer.wedges.len(), 1);
    let side = &layer.wedges[0];
    assert_eq!((side.point, side.face, side.opacity), (1, 1, Some(0.25)));
    assert_eq!(side.colour, layer.points[1].colour);
    assert_eq!(
        layer.points[1].opacity, 1.0,
        "the point itself keeps its opacity"
    );
    // A side's colour and opacity are kept apart: recolouring keeps the opacity, and no
    // opacity keeps the colour.
    let colour = serde_json::json!({"op": "set_side_colour", "layer": 0, "point": 1, "face": 1,
        "css": "#00ff00"});
    assert_eq!(edit_command(&running, colour, None).await.0, 200);
    assert_eq!(
        document(&running).await.layers[0].wedges[0].opacity,
        Some(0.25)
    );
    assert_eq!(
        edit_command(&running, side_opacity(None), None).await.0,
        200
    );
    let side = document(&running).await.layers[0].wedges[0].clone();
    assert_eq!(
        (side.opacity, side.colour_text.as_deref()),
        (None, Some("#00ff00"))
    );
    // Out of range: the validator's message, nothing changed.
    let (status, text) = edit_command(&running, side_opacity(Some(1.5)), None).await;
    assert_eq!(status, 422, "{text}");
    assert!(text.contains("opacity"), "{text}");
    // Undo walks back through each step.
    for _ in 0..2 {
        assert_eq!(command(&running, r#"{"type":"undo"}"#).await.0, 200);
    }
    assert_eq!(
        document(&running).await.layers[0].wedges[0].opacity,
        Some(0.25)
    );
    assert_eq!(command(&running, r#"{"type":"undo"}"#).await.0, 200);
    assert!(document(&running).await.layers[0].wedges.is_empty());
    // A face that does not hold the point names no side.
    let wrong = serde_json::json!({"op": "set_side_opacity", "layer": 0, "point": 0, "face": 1,
        "opacity": 0.5});
    let (status, text) = edit_command(&running, wrong, None).await;
    assert_eq!(status, 422, "{text}");
    assert!(text.contains("not a corner of face 1"), "{text}");
}

/// Three squares in a row (faces 0, 1, 2 from the left), with a colour edit in face 0 and a
/// colour and position edit at the far right corner of face 2.
const STRIP: &str = r##"{"format":"gradmesh","version":1,"layers":[{"name":"strip","points":[
  {"position":[0,0],"colour":"#d04020"},{"position":[100,0],"colour":"#e0c030"},
  {"position":[200,0],"colour":"#2060c0"},{"position":[300,0],"colour":"#40a040"},
  {"position":[0,100],"colour":"#802080"},{"position":[100,100],"colour":"#208080"},
  {"position":[200,100],"colour":"#a0a0a0"},{"position":[300,100],"colour":"#f08000"}],
  "faces":[[0,1,5,4],[1,2,6,5],[2,3,7,6]],
  "edits":[{"level":2,"face":0,"point":0,"at":[1,1],"colour":"#ffffff"},
    {"level":2,"face":2,"point":3,"at":[1,2],"colour":"#000000","offset":[0.4,-0.3]}]}]}"##;

async fn refined_vertex(running: &Running, face: u32, point: u32, at: [u32; 2]) -> [f64; 2] {
    let target = format!(
        "/api/refined?token={}&layer=0&face={face}&level=2",
        running.token
    );
    let (status, text) = get(running, &target).await;
    assert_eq!(status, 200, "{text}");
    let vertices: serde_json::Value = serde_json::from_str(&text).unwrap();
    let v = (vertices.as_array().unwrap().iter())
        .find(|v| v["point"] == point && v["at"] == serde_json::json!(at))
        .expect("the vertex is listed");
    [
        v["position"][0].as_f64().unwrap(),
        v["position"][1].as_f64().unwrap(),
    ]
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn deleting_faces_renumbers_the_edits_and_drops_those_on_deleted_faces() {
    let (running, dir) = serve_square().await;
    std::fs::write(dir.path().join("strip.json"), STRIP).unwrap();
    assert_eq!(
        command(&running, r#"{"type":"open","name":"strip.json"}"#)
            .await
            .0,
        200
    );
    let before = document(&running).await.layers.remove(0);
    let moved = refined_vertex(&running, 2, 3, [1, 2]).await;
    let delete = serde_json::json!({"op": "delete_faces", "layer": 0, "faces": [0]});
    let (status, state) = edit_command(&running, delete, None).await;
    assert_eq!(status, 200, "{state}");
    let state: serde_json::Value = serde_json::from_str(&state).unwrap();
    assert_eq!(
        state["notices"],
        serde_json::json!(["1 multi-resolution edit on the deleted faces went with them"])
    );
    // Points 0 and 4 went with face 0: point 3 is now 2, face 2 is now 1.
    let after = document(&running).await.layers.remove(0);
    assert_eq!(after.edits.len(), 1);
    let edit = &after.edits[0];
    let address = (
        edit.address.level,
        edit.address.face,
        edit.address.point,
        edit.address.at,
    );
    assert_eq!(address, (2, 1, 2, [1, 2]));
    assert_eq!(
        (edit.colour, edit.offset),
        (before.edits[1].colour, before.edits[1].offset)
    );
    // It names the same vertex: far from the deleted face, it is where it was.
    assert_near(refined_vertex(&running, 1, 2, [1, 2]).await, moved);
    // Undo brings the face and both edits back.
    assert_eq!(command(&running, r#"{"type":"undo"}"#).await.0, 200);
    assert_eq!(document(&running).await.layers[0], before);
    // Deleting a point deletes its faces and their edits alike.
    let delete = serde_json::json!({"op": "delete_points", "layer": 0, "points": [7]});
    let (status, state) = edit_command(&running, delete, None).await;
    assert_eq!(status, 200, "{state}");
    assert!(
        state.contains("1 multi-resolution edit on the deleted faces"),
        "{state}"
    );
    let after = document(&running).await.layers.remove(0);
    assert_eq!(after.faces.len(), 2);
    assert_eq!(after.edits, before.edits[..1].to_vec());
}

/// A 2 x 2 grid of squares whose middle column line (points 1, 4, 7) is discontinuous: point 4
/// has two sides, faces 0 and 2 on the left, 1 and 3 on the right.
const GRID: &str = r##"{"format":"gradmesh","version":1,"layers":[{"name":"grid","points":[
  {"position":[0,0],"colour":"#d04020"},{"position":[100,0],"colour":"#e0c030"},
  {"position":[200,0],"colour":"#2060c0"},{"position":[0,100],"colour":"#40a040"},
  {"position":[100,100],"colour":"#802080"},{"position":[200,100],"colour":"#208080"},
  {"position":[0,200],"colour":"#a0a0a0"},{"position":[100,200],"colour":"#f08000"},
  {"position":[200,200],"colour":"#104010"}],
  "faces":[[0,1,4,3],[1,2,5,4],[3,4,7,6],[4,5,8,7]],
  "edges":[{"points":[1,4],"kind":"discontinuous"},{"points":[4,7],"kind":"discontinuous"}]}]}"##;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_side_is_found_through_any_of_its_faces() {
    let (running, dir) = serve_square().await;
    std::fs::write(dir.path().join("grid.json"), GRID).unwrap();
    assert_eq!(
        command(&running, r#"{"type":"open","name":"grid.json"}"#)
            .await
            .0,
        200
    );
    let op = |name: &str, face: u32, field: (&str, serde_json::Value)| {
        let mut op = serde_json::json!({"op": name, "layer": 0, "point": 4, "face": face});
        op[field.0] = field.1;
        op
    };
    let opacity = op("set_side_opacity", 1, ("opacity", 0.5.into()));
    assert_eq!(edit_command(&running, opacity, None).await.0, 200);
    // Face 3 is on the same side as face 1: the same entry takes the colour.
    let colour = op("set_side_colour", 3, ("css", "#00ff00".into()));
    let (status, text) = edit_command(&running, colour, None).await;
    assert_eq!(status, 200, "{text}");
    let sides = document(&running).await.layers.remove(0).wedges;
    assert_eq!(sides.len(), 1);
    assert_eq!((sides[0].face, sides[0].opacity), (1, Some(0.5)));
    assert_eq!(sides[0].colour_text.as_deref(), Some("#00ff00"));
    // Face 2 is on the other side: a second entry.
    let opacity = op("set_side_opacity", 2, ("opacity", 0.25.into()));
    assert_eq!(edit_command(&running, opacity, None).await.0, 200);
    let sides = document(&running).await.layers.remove(0).wedges;
    let named: Vec<_> = sides.iter().map(|w| (w.face, w.opacity)).collect();
    assert_eq!(named, vec![(1, Some(0.5)), (2, Some(0.25))]);
    // Clearing through face 0 removes the left side's entry.
    let clear = serde_json::json!({"op": "set_side_colour", "layer": 0, "point": 4, "face": 0});
    assert_eq!(edit_command(&running, clear, None).await.0, 200);
    let sides = document(&running).await.layers.remove(0).wedges;
    assert_eq!(sides.iter().map(|w| w.face).collect::<Vec<_>>(), vec![1]);
}
