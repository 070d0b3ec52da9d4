//! `gradmesh serve`: a local web editor for gradient meshes.
//!
//! The server holds the document, its undo history and a [`gradmesh::render::RenderCache`]
//! per page; the page (plain HTML, CSS and JavaScript embedded in the binary) draws the
//! control mesh over the picture and sends edits over a WebSocket. After each batch of edits
//! the server renders the picture with gradmesh's renderer at the canvas's size and sends the
//! rows that changed as raw RGBA8 (see [`viewer::encode_frame`]).
//!
//! The server listens on 127.0.0.1 only; every request needs the launch's random token, and
//! requests whose `Host` or `Origin` is not this server are refused ([`security`]). It reads
//! and writes documents only inside the starting folder, and saves atomically.

pub mod editor;
pub mod files;
pub mod ops;
pub mod refined;
pub mod security;
pub mod server;
pub mod session;
pub mod state;
pub mod tools;
pub mod viewer;

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use editor::{Editor, History};
pub use ops::{Op, Picture};
pub use session::{App, Command, Outgoing, Session};

use security::{Folder, Gate};

/// What to serve.
#[derive(Clone, Debug, Default)]
pub struct Config {
    /// The document to open (any format gradmesh reads); `None` for a new document.
    pub file: Option<PathBuf>,
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
    let (editor, source) = match &config.file {
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
    let app = App::new(editor, folder);
    app.files()
        .opened(source.as_deref(), &app.editor.lock().expect("a new lock"));
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
    let task = tokio::spawn(async move { axum::serve(listener, router).await });
    Ok(Running {
        address,
        token,
        app,
        task,
    })
}

/// Serves `config` until the process ends, printing the URL to open.
pub fn run(config: &Config) -> Result<(), String> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the server's runtime: {e}"))?;
    runtime.block_on(async {
        let running = start(config).await?;
        println!("gradmesh editor: open {}", running.url());
        println!("(listening on 127.0.0.1 only; stop with Ctrl-C)");
        match running.task.await {
            Ok(result) => result.map_err(|e| format!("the server stopped: {e}")),
            Err(e) => Err(format!("the server stopped: {e}")),
        }
    })
}
