//! The HTTP routes and the WebSocket.

use std::net::{Ipv4Addr, SocketAddr};
use std::sync::Arc;
use std::time::{Duration, Instant};

use axum::body::Bytes;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{DefaultBodyLimit, Query, State};
use axum::http::{header, StatusCode};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use futures_util::stream::SplitSink;
use futures_util::{SinkExt, StreamExt};
use gradmesh::render::{self, RenderOptions};
use tokio::net::TcpListener;
use tokio::sync::mpsc;

use crate::security::{guard, Gate};
use crate::session::{App, Command, Outgoing, Session};

/// The largest request body and WebSocket message accepted, in bytes.
pub const MAX_BODY: usize = 1 << 20;

/// The largest side of a downloaded PNG, in pixels.
pub const PNG_SIDE: u32 = 2048;

const INDEX_HTML: &str = include_str!("../assets/index.html");
const APP_JS: &str = include_str!("../assets/app.js");
const FILES_JS: &str = include_str!("../assets/files.js");
const TOOLS_JS: &str = include_str!("../assets/tools.js");
const STYLE_CSS: &str = include_str!("../assets/style.css");

/// The routes, each behind the gate.
pub fn router(app: Arc<App>, gate: Gate) -> Router {
    let token = gate.token.clone();
    Router::new()
        .route("/", get(move || index(token.clone())))
        .route(
            "/app.js",
            get(|| asset(APP_JS, "text/javascript; charset=utf-8")),
        )
        .route(
            "/files.js",
            get(|| asset(FILES_JS, "text/javascript; charset=utf-8")),
        )
        .route(
            "/tools.js",
            get(|| asset(TOOLS_JS, "text/javascript; charset=utf-8")),
        )
        .route(
            "/style.css",
            get(|| asset(STYLE_CSS, "text/css; charset=utf-8")),
        )
        .route("/api/state", get(state))
        .route("/api/command", post(command))
        .route("/api/files", get(files))
        .route("/api/document.json", get(document_json))
        .route("/api/picture.png", get(picture_png))
        .route("/api/refined", get(refined_vertices))
        .route("/api/export", get(crate::exports::export_route))
        .route("/api/backdrop.png", get(backdrop_png))
        .route("/api/trace", post(trace_route))
        .route("/ws", get(websocket))
        .fallback(|| async { (StatusCode::NOT_FOUND, "no such page") })
        .layer(DefaultBodyLimit::max(MAX_BODY))
        .layer(axum::middleware::from_fn_with_state(gate, guard))
        .with_state(app)
}

/// Binds to the loopback address at `port` (0: any free port).
pub async fn bind_loopback(port: u16) -> std::io::Result<TcpListener> {
    TcpListener::bind(SocketAddr::from((Ipv4Addr::LOCALHOST, port))).await
}

async fn index(token: String) -> Response {
    let page = INDEX_HTML.replace("{{TOKEN}}", &token);
    let mut response = Html(page).into_response();
    let headers = response.headers_mut();
    headers.insert(header::CACHE_CONTROL, "no-store".parse().expect("header"));
    headers.insert(
        header::CONTENT_SECURITY_POLICY,
        "default-src 'self'; img-src 'self' blob: data:; connect-src 'self'; frame-ancestors 'none'"
            .parse()
            .expect("header"),
    );
    headers.insert(
        header::REFERRER_POLICY,
        "no-referrer".parse().expect("header"),
    );
    response
}

async fn asset(body: &'static str, kind: &'static str) -> Response {
    ([(header::CONTENT_TYPE, kind)], body).into_response()
}

/// Runs commands on a blocking thread (they validate and render) with a session of its own.
async fn run_blocking(app: Arc<App>, commands: Vec<Command>) -> Vec<Outgoing> {
    tokio::task::spawn_blocking(move || Session::new(app).handle(&commands))
        .await
        .unwrap_or_default()
}

async fn state(State(app): State<Arc<App>>) -> Response {
    reply(run_blocking(app, Vec::new()).await)
}

async fn command(State(app): State<Arc<App>>, body: Bytes) -> Response {
    let command: Command = match serde_json::from_slice(&body) {
        Ok(c) => c,
        Err(e) => {
            return (StatusCode::BAD_REQUEST, format!("malformed command: {e}")).into_response()
        }
    };
    reply(run_blocking(app, vec![command]).await)
}

/// The answer of the HTTP API: the first error (422) or the state (200), with the edits' notes
/// in its `notices` and what a mesh tool left selected in its `selection`.
fn reply(messages: Vec<Outgoing>) -> Response {
    let mut state = None;
    let mut notices = Vec::new();
    let mut selection = None;
    for message in messages {
        match message {
            Outgoing::Error(text) => {
                return (
                    crate::files::status_of_error(&text),
                    [(header::CONTENT_TYPE, "application/json")],
                    text,
                )
                    .into_response();
            }
            Outgoing::Text(text) => state = Some(text),
            Outgoing::Notice(text) => notices.push(text),
            Outgoing::Select(text) => selection = Some(text),
            Outgoing::Binary(_) | Outgoing::Done => {}
        }
    }
    match state {
        Some(text) if notices.is_empty() && selection.is_none() => {
            ([(header::CONTENT_TYPE, "application/json")], text).into_response()
        }
        Some(text) => {
            let mut state: serde_json::Value =
                serde_json::from_str(&text).expect("the state is JSON");
            let notes = notices.iter().map(|n| {
                let notice: serde_json::Value = serde_json::from_str(n).expect("a notice is JSON");
                notice["message"].clone()
            });
            state["notices"] = notes.collect();
            if let Some(text) = selection {
                state["selection"] = serde_json::from_str(&text).expect("a selection is JSON");
            }
            let text = state.to_string();
            ([(header::CONTENT_TYPE, "application/json")], text).into_response()
        }
        None => (StatusCode::INTERNAL_SERVER_ERROR, "no state").into_response(),
    }
}

async fn files(State(app): State<Arc<App>>) -> Response {
    let names = tokio::task::spawn_blocking(move || app.folder.documents())
        .await
        .unwrap_or_default();
    axum::Json(names).into_response()
}

async fn document_json(State(app): State<Arc<App>>) -> Response {
    let text = gradmesh::formats::json::write_document(&app.editor().history.current().doc);
    ([(header::CONTENT_TYPE, "application/json")], text).into_response()
}

async fn picture_png(State(app): State<Arc<App>>) -> Response {
    let doc = app.editor().history.current().visible();
    let png = tokio::task::spawn_blocking(move || -> Result<Vec<u8>, String> {
        let opts = RenderOptions::fit(&doc, PNG_SIDE);
        let mut pixels = vec![0u8; 4 * opts.width as usize * opts.height as usize];
        render::render_document_into(&doc, &opts, &mut pixels).map_err(|e| e.to_string())?;
        render::encode_png_rgba8(opts.width, opts.height, &pixels).map_err(|e| e.to_string())
    })
    .await
    .unwrap_or_else(|_| Err("the render failed".into()));
    match png {
        Ok(bytes) => (
            [
                (header::CONTENT_TYPE, "image/png"),
                (
                    header::CONTENT_DISPOSITION,
                    "attachment; filename=\"picture.png\"",
                ),
            ],
            bytes,
        )
            .into_response(),
        Err(e) => (StatusCode::UNPROCESSABLE_ENTITY, e).into_response(),
    }
}

/// The view a backdrop is drawn for: the canvas's size in pixels and the rectangle of the plane.
#[derive(serde::Deserialize)]
struct BackdropQuery {
    width: u32,
    height: u32,
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

/// `GET /api/backdrop.png?width=W&height=H&x0=…&y0=…&x1=…&y1=…`: what the SVG files opened draw
/// besides their mesh fills, at that view (204 when there is nothing to draw).
async fn backdrop_png(State(app): State<Arc<App>>, Query(q): Query<BackdropQuery>) -> Response {
    let viewport = crate::viewer::Viewport {
        width: q.width,
        height: q.height,
        view: render::View::new(q.x0, q.y0, q.x1, q.y1),
    };
    if let Err(e) = viewport.check() {
        return (StatusCode::BAD_REQUEST, e).into_response();
    }
    let backdrops = app.editor().history.current().backdrops.clone();
    let png = tokio::task::spawn_blocking(move || -> Result<Option<Vec<u8>>, String> {
        let Some(rgba) = crate::backdrop::render(&backdrops, &viewport)? else {
            return Ok(None);
        };
        render::encode_png_rgba8(viewport.width, viewport.height, &rgba)
            .map(Some)
            .map_err(|e| e.to_string())
    })
    .await
    .unwrap_or_else(|_| Err("the backdrop's render failed".into()));
    match png {
        Ok(Some(bytes)) => (
            [
                (header::CONTENT_TYPE, "image/png"),
                (header::CACHE_CONTROL, "no-store"),
            ],
            bytes,
        )
            .into_response(),
        Ok(None) => StatusCode::NO_CONTENT.into_response(),
        Err(e) => (StatusCode::UNPROCESSABLE_ENTITY, e).into_response(),
    }
}

/// `POST /api/trace?x0=…&y0=…&x1=…&y1=…&points=N` with a PNG or JPEG body: a mesh fitted to
/// the picture (on a blocking thread: the server answers other requests meanwhile), placed
/// over the rectangle, added as a new layer in one step of the history. The answer:
/// `{"type": "traced", "layer": L, "points": N, "psnr": DB}`; 422 with a message when the
/// picture or the request is refused, 409 while a recovery copy waits for the user's choice.
async fn trace_route(
    State(app): State<Arc<App>>,
    Query(request): Query<crate::trace::TraceRequest>,
    body: Bytes,
) -> Response {
    let refused = |status: StatusCode, message: String| {
        let body = serde_json::json!({"type": "error", "message": message}).to_string();
        (status, [(header::CONTENT_TYPE, "application/json")], body).into_response()
    };
    if app.files().recovery_pending() {
        let message = "a recovery copy waits: restore or discard it first".to_string();
        return refused(StatusCode::CONFLICT, message);
    }
    let fitted = tokio::task::spawn_blocking(move || crate::trace::trace(&body, &request))
        .await
        .unwrap_or_else(|_| Err("the trace failed".into()));
    let traced = match fitted {
        Ok(traced) => traced,
        Err(e) => return refused(StatusCode::UNPROCESSABLE_ENTITY, e),
    };
    let (points, psnr) = (traced.points, traced.psnr);
    let added = crate::trace::add_layer(&mut app.editor(), traced.mesh);
    match added {
        Ok(layer) => axum::Json(serde_json::json!({
            "type": "traced", "layer": layer, "points": points, "psnr": psnr
        }))
        .into_response(),
        Err(e) => refused(StatusCode::UNPROCESSABLE_ENTITY, e),
    }
}

/// Which refined vertices the page asks for.
#[derive(serde::Deserialize)]
struct RefinedQuery {
    layer: usize,
    face: u32,
    level: u32,
}

async fn refined_vertices(State(app): State<Arc<App>>, Query(q): Query<RefinedQuery>) -> Response {
    let mesh = app
        .editor()
        .history
        .current()
        .doc
        .layers
        .get(q.layer)
        .cloned();
    let Some(mesh) = mesh else {
        return (
            StatusCode::UNPROCESSABLE_ENTITY,
            format!("there is no layer {}", q.layer),
        )
            .into_response();
    };
    let found =
        tokio::task::spawn_blocking(move || crate::refined::face_vertices(&mesh, q.face, q.level))
            .await
            .unwrap_or_else(|_| Err("the refinement failed".into()));
    match found {
        Ok(vertices) => axum::Json(vertices).into_response(),
        Err(e) => (StatusCode::UNPROCESSABLE_ENTITY, e).into_response(),
    }
}

async fn websocket(State(app): State<Arc<App>>, upgrade: WebSocketUpgrade) -> Response {
    upgrade
        .max_message_size(MAX_BODY)
        .max_frame_size(MAX_BODY)
        .on_upgrade(move |socket| run_socket(socket, app))
}

/// Serves one page's WebSocket. A reader task queues the page's commands; the loop takes every
/// command queued so far, runs them, and sends one frame for the lot. Commands that arrive
/// while a frame renders wait for the next batch, so the page never gets a stale frame and
/// rendering keeps up with the mouse however fast it moves.
async fn run_socket(socket: WebSocket, app: Arc<App>) {
    let (mut sink, mut stream) = socket.split();
    let (queue, mut queued) = mpsc::unbounded_channel::<String>();
    let reader = tokio::spawn(async move {
        while let Some(Ok(message)) = stream.next().await {
            match message {
                Message::Text(text) if queue.send(text.to_string()).is_err() => break,
                Message::Close(_) => break,
                _ => {}
            }
        }
    });
    let mut session = Session::deferring_folds(app);
    while let Some(first) = queued.recv().await {
        let mut batch = vec![first];
        while let Ok(next) = queued.try_recv() {
            batch.push(next);
        }
        let Some((back, messages, took)) =
            on_session(session, move |s| s.handle_texts(&batch)).await
        else {
            break;
        };
        session = back;
        if send_all(&mut sink, messages, took).await.is_err() {
            break;
        }
        // The page has its frame: now the folds its state left out, unless commands wait.
        if session.owes_folds() && queued.is_empty() {
            let Some((back, messages, took)) =
                on_session(session, |s| s.owed_folds().into_iter().collect()).await
            else {
                break;
            };
            session = back;
            if send_all(&mut sink, messages, took).await.is_err() {
                break;
            }
        }
    }
    reader.abort();
}

/// Runs `work` on the session on a blocking thread; gives the session back with the messages
/// and the time taken (`None` if the work panicked).
async fn on_session<F>(mut session: Session, work: F) -> Option<(Session, Vec<Outgoing>, Duration)>
where
    F: FnOnce(&mut Session) -> Vec<Outgoing> + Send + 'static,
{
    tokio::task::spawn_blocking(move || {
        let start = Instant::now();
        let messages = work(&mut session);
        (session, messages, start.elapsed())
    })
    .await
    .ok()
}

/// Sends `messages` to the page; "done" carries the time the batch took on the server (`took`),
/// for the page's latency figures.
async fn send_all(
    sink: &mut SplitSink<WebSocket, Message>,
    messages: Vec<Outgoing>,
    took: Duration,
) -> Result<(), axum::Error> {
    for message in messages {
        let message = match message {
            Outgoing::Text(text)
            | Outgoing::Error(text)
            | Outgoing::Notice(text)
            | Outgoing::Select(text) => Message::Text(text.into()),
            Outgoing::Binary(bytes) => Message::Binary(bytes.into()),
            Outgoing::Done => {
                let ms = took.as_secs_f64() * 1e3;
                Message::Text(format!(r#"{{"type":"done","ms":{ms:.3}}}"#).into())
            }
        };
        sink.send(message).await?;
    }
    Ok(())
}
