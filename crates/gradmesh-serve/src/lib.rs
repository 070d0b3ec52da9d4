//! `gradmesh serve`: a local web editor for gradient meshes.
//!
//! The server holds the document, its undo history and a [`gradmesh::render::RenderCache`]
//! per page; the page (plain HTML, CSS and JavaScript embedded in the binary) draws the
//! control mesh over the picture and sends edits over a WebSocket. After each batch of edits
//! the server renders the picture with gradmesh's renderer at the canvas's size and sends the
//! rectangles that changed as raw RGBA8 (see [`viewer::encode_frame`]).
//!
//! The server listens on 127.0.0.1 only; every request needs the launch's random token, and
//! requests whose `Host` or `Origin` is not this server are refused ([`security`]). It reads
//! and writes documents only inside the starting folder, and saves atomically.

pub mod backdrop;
pub mod clipboard;
pub mod editor;
pub mod exports;
pub mod files;
pub mod ops;
pub mod recovery;
pub mod refined;
pub mod security;
pub mod server;
pub mod session;
pub mod state;
pub mod tools;
pub mod trace;
pub mod viewer;

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use axum::serve::ListenerExt;

pub use editor::{Editor, History};
pub use ops::{Op, Picture};
pub use session::{App, Command, Outgoing, Session};

use security::{Folder, Gate};

/// What to serve.
#[derive(Clone, Debug, Default)]
pub struct Config {
    /// The document to open (any format gradmesh reads); `None` for a new document.
    pub file: Option<PathBuf>,
    /// Documents whose layers go above those of `file`, in order. With any, the document has
    /// no file to save to until "Save as".
    pub layers_above: Vec<PathBuf>,
    /// The folder documents are opened from and saved to: the file's folder by default, else
    /// the current folder.
    pub folder: Option<PathBuf>,
    /// The port on 127.0.0.1 (0: any free port).
    pub port: u16,
}

/// A server started by [`start`].
pub struct Running {
    /// The address it listens on.
    pub address: SocketAddr,
    /// The launch token.
    pub token: String,
    /// The shared state.
    pub app: Arc<App>,
    /// The task serving requests.
    pub task: tokio::task::JoinHandle<std::io::Result<()>>,
}

impl Running {
    /// The URL to open, with the token.
    pub fn url(&self) -> String {
        format!("http://{}/?token={}", self.address, self.token)
    }
}

/// Opens the document and the folder of `config`.
pub fn open_app(config: &Config) -> Result<Arc<App>, String> {
    let folder_path = match (&config.folder, &config.file) {
        (Some(folder), _) => folder.clone(),
        (None, Some(file)) => file
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf(),
        (None, None) => PathBuf::from("."),
    };
    let folder = Folder::new(&folder_path)
        .map_err(|e| format!("cannot use the folder {}: {e}", folder_path.display()))?;
    let (mut editor, mut source) = match &config.file {
        Some(file) => {
            let mut editor = Editor::open(file)?;
            // "save" writes inside the folder only.
            if let Some(path) = &editor.path {
                let name = path.file_name().map(|n| n.to_string_lossy().to_string());
                editor.path = name.and_then(|n| folder.resolve(&n).ok());
            }
            let source = file.canonicalize().ok();
            (editor, source)
        }
        None => (Editor::new_document(), None),
    };
    if !config.layers_above.is_empty() {
        let mut picture = editor.history.current().clone();
        for file in &config.layers_above {
            let (layers, backdrop) =
                files::read_layers(file).map_err(|e| format!("{}: {e}", file.display()))?;
            picture = picture.with_backdrop(backdrop);
            picture.hidden.extend(layers.iter().map(|_| false));
            picture.doc.layers.extend(layers);
        }
        editor = Editor {
            history: History::new(picture),
            path: None,
        };
        source = None;
    }
    // What a document without a file was made from: it names the recovery copy.
    let mut key = folder.root().display().to_string();
    for file in config.file.iter().chain(&config.layers_above) {
        let file = file.canonicalize().unwrap_or_else(|_| file.clone());
        key.push('\n');
        key.push_str(&file.display().to_string());
    }
    let app = App::new(editor, folder);
    let editor = app.editor();
    let warning = app.files().opened(source.as_deref(), &editor, &key);
    drop(editor);
    if let Some(warning) = warning {
        eprintln!("gradmesh editor: {warning}");
    }
    Ok(Arc::new(app))
}

/// Starts serving `config` on 127.0.0.1 in the current tokio runtime.
pub async fn start(config: &Config) -> Result<Running, String> {
    let app = open_app(config)?;
    let listener = server::bind_loopback(config.port)
        .await
        .map_err(|e| format!("cannot listen on 127.0.0.1:{}: {e}", config.port))?;
    let address = listener.local_addr().map_err(|e| e.to_string())?;
    let gate = Gate {
        token: security::new_token(),
        port: address.port(),
    };
    let token = gate.token.clone();
    let router = server::router(Arc::clone(&app), gate);
    // Without Nagle's algorithm: a frame's state and "done" are small messages right after a
    // large one, which would wait for the page's delayed acknowledgement (tens of milliseconds).
    let listener = listener.tap_io(|stream| {
        // The connection works without it, only slower.
        let _ = stream.set_nodelay(true);
    });
    let task = tokio::spawn(async move { axum::serve(listener, router).await });
    Ok(Running {
        address,
        token,
        app,
        task,
    })
}

/// Serves `config` until the process is stopped, printing the URL to open. Recovery copies
/// are kept ([`recovery`]); on Ctrl-C or SIGTERM the unsaved edits are written to the copy and
/// its path printed.
pub fn run(config: &Config) -> Result<(), String> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the server's runtime: {e}"))?;
    let result = runtime.block_on(async {
        let running = start(config).await?;
        announce_recovery(&running.app);
        println!("gradmesh editor: open {}", running.url());
        println!("(listening on 127.0.0.1 only; stop with Ctrl-C)");
        tokio::select! {
            ended = running.task => match ended {
                Ok(result) => result.map_err(|e| format!("the server stopped: {e}")),
                Err(e) => Err(format!("the server stopped: {e}")),
            },
            signal = stop_signal() => {
                report_exit(&running.app, signal);
                Ok(())
            }
        }
    });
    runtime.shutdown_timeout(std::time::Duration::from_secs(2));
    result
}

/// Turns recovery copies on and says if a copy of the document waits to be restored.
fn announce_recovery(app: &App) {
    let editor = app.editor();
    let mut files = app.files();
    if let Some(warning) = files.enable_recovery(recovery::default_state_dir(), &editor) {
        eprintln!("gradmesh editor: {warning}");
    }
    if let Some(found) = files.recovery.found() {
        println!(
            "gradmesh editor: unsaved edits of this document were kept in {}; the page offers \
             to restore or discard them",
            found.path.display()
        );
    }
}

/// Waits for Ctrl-C or SIGTERM; returns which.
async fn stop_signal() -> &'static str {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{signal, SignalKind};
        if let Ok(mut terminate) = signal(SignalKind::terminate()) {
            return tokio::select! {
                _ = tokio::signal::ctrl_c() => "Ctrl-C",
                _ = terminate.recv() => "SIGTERM",
            };
        }
    }
    let _ = tokio::signal::ctrl_c().await;
    "Ctrl-C"
}

/// Keeps the unsaved edits in the recovery copy and says where they are.
fn report_exit(app: &App, signal: &str) {
    let editor = app.editor();
    let mut files = app.files();
    let kept = files.recovery.at_exit(&editor.history);
    let end = match kept {
        Ok(Some(path)) => format!(
            " with unsaved edits; they are kept in {} (serve the same document again to restore \
             them)",
            path.display()
        ),
        Ok(None) if editor.history.modified() => "; the unsaved edits could not be kept (no \
             state folder: set XDG_STATE_HOME or HOME)"
            .into(),
        Ok(None) => "; nothing was left unsaved".into(),
        Err(e) => format!("; the unsaved edits could not be kept: {e}"),
    };
    println!("gradmesh editor: stopped by {signal}{end}");
}
