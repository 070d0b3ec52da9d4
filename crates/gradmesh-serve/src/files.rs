//! What keeps the user's work: saving without replacing a file the session did not write
//! unless asked to, the recovery copy ([`crate::recovery`]), layers imported from files, and
//! what the page is told about them (the file's name, the last save, a copy to restore).

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use axum::http::StatusCode;
use serde_json::{json, Value};

use gradmesh::GradientMesh;

use crate::backdrop::Backdrop;
use crate::editor::Editor;
use crate::ops::Picture;
use crate::recovery::Recovery;
use crate::security::Folder;

/// The code of the error refusing to replace a file the session did not write.
pub const FILE_EXISTS: &str = "file_exists";

/// The code of the error refusing edits while a recovery copy waits to be restored or
/// discarded.
pub const RECOVERY_PENDING: &str = "recovery_pending";

/// A command refused: the message for the user and, for refusals the page answers by asking
/// the user, a code naming the question.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    /// What went wrong, for the user.
    pub message: String,
    /// What the page may ask the user before trying again (see [`FILE_EXISTS`]).
    pub code: Option<&'static str>,
}

impl From<String> for Refusal {
    fn from(message: String) -> Refusal {
        Refusal {
            message,
            code: None,
        }
    }
}

impl Refusal {
    /// The error message for the page: `{"type": "error", "message": …, "code": …}`.
    pub fn to_json(&self) -> String {
        let mut message = json!({"type": "error", "message": self.message});
        if let Some(code) = self.code {
            message["code"] = code.into();
        }
        message.to_string()
    }
}

/// The HTTP status of an error message made by [`Refusal::to_json`]: 409 for a refusal the
/// user can lift by answering a question, 422 for the others.
pub fn status_of_error(text: &str) -> StatusCode {
    let code = serde_json::from_str::<Value>(text)
        .ok()
        .and_then(|v| v["code"].as_str().map(str::to_owned));
    match code.as_deref() {
        Some(FILE_EXISTS | RECOVERY_PENDING) => StatusCode::CONFLICT,
        _ => StatusCode::UNPROCESSABLE_ENTITY,
    }
}

/// What the server knows about the files of the session.
#[derive(Debug, Default)]
pub struct FileState {
    /// The files the session may replace without asking: the JSON documents it opened and
    /// the files it wrote.
    replaceable: HashSet<PathBuf>,
    /// The last save of the document: the file's name in the folder, and when (milliseconds
    /// since the Unix epoch).
    last_save: Option<(String, u64)>,
    /// Changes whenever what the page is told about the files changes.
    generation: u64,
    /// The recovery copy of the document.
    pub recovery: Recovery,
    /// What a document without a file was made from (the folder and the files opened), which
    /// names its recovery copy.
    key: String,
}

impl FileState {
    /// A number that changes whenever [`describe`] would say something else.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Notes that `editor` was just opened from `source` (or made new, without one): the
    /// source may be replaced if the document is saved to it, no save is reported yet, and
    /// the recovery copy follows the document (`key`: what a document without a file was
    /// made from). Returns a message if a recovery copy there cannot be read.
    pub fn opened(&mut self, source: Option<&Path>, editor: &Editor, key: &str) -> Option<String> {
        if let (Some(source), Some(path)) = (source, &editor.path) {
            if source == path {
                self.replaceable.insert(path.clone());
            }
        }
        self.last_save = None;
        self.generation += 1;
        self.key = key.to_string();
        self.recovery.attach(editor.path.as_deref(), key)
    }

    /// Turns recovery copies on (`state_dir`: the folder for documents without a file) and
    /// looks for a copy of `editor`'s document. Returns a message if one cannot be read.
    pub fn enable_recovery(
        &mut self,
        state_dir: Option<PathBuf>,
        editor: &Editor,
    ) -> Option<String> {
        self.recovery.enable(state_dir);
        self.generation += 1;
        let key = self.key.clone();
        self.recovery.attach(editor.path.as_deref(), &key)
    }

    /// Whether a recovery copy waits for the user's choice.
    pub fn recovery_pending(&self) -> bool {
        self.recovery.found().is_some()
    }

    /// Restores the recovery copy into `editor` (one step of the history, so undo goes back
    /// to the file), or discards it.
    pub fn choose_recovery(&mut self, editor: &mut Editor, restore: bool) -> Result<(), String> {
        if !self.recovery_pending() {
            return Err("there is no recovery copy to restore or discard".into());
        }
        self.generation += 1;
        if restore {
            let doc = self.recovery.take_found().expect("pending");
            let mut picture = Picture::new(doc);
            picture.backdrops = editor.history.current().backdrops.clone();
            editor.history.replace(picture)
        } else {
            self.recovery.discard_found()
        }
    }
}

/// The refusal of an edit while a recovery copy waits.
pub fn recovery_pending_refusal() -> Refusal {
    Refusal {
        message: "a recovery copy of unsaved edits waits: restore or discard it first".into(),
        code: Some(RECOVERY_PENDING),
    }
}

/// Saves the document of `editor` to `path`, a file of the starting folder. A file that exists
/// and was neither opened as the document nor written by this session is replaced only with
/// `overwrite`; else the refusal has the code [`FILE_EXISTS`].
pub fn save(
    folder: &Folder,
    files: &mut FileState,
    editor: &mut Editor,
    path: &Path,
    overwrite: bool,
) -> Result<(), Refusal> {
    let name = folder.name_of(path);
    if !overwrite && path.exists() && !files.replaceable.contains(path) {
        return Err(Refusal {
            message: format!(
                "{name} exists and was not written by this editor: replace it, or save under \
                 another name"
            ),
            code: Some(FILE_EXISTS),
        });
    }
    editor.save_to(path)?;
    files.replaceable.insert(path.to_path_buf());
    files.last_save = Some((name, unix_millis()));
    files.generation += 1;
    let key = files.key.clone();
    files.recovery.saved(path, &key)?;
    Ok(())
}

/// The layers of the document in `path`, named after the file where they have no name, and an
/// SVG file's backdrop.
pub fn read_layers(path: &Path) -> Result<(Vec<GradientMesh>, Option<Backdrop>), String> {
    let read = crate::backdrop::read_document(path)?;
    let doc = read.document;
    let stem = path.file_stem().map(|s| s.to_string_lossy().to_string());
    let count = doc.layers.len();
    let layers = doc.layers.into_iter().enumerate().map(|(i, mut layer)| {
        if layer.name.is_none() {
            layer.name = match (&stem, count) {
                (Some(stem), 1) => Some(stem.clone()),
                (Some(stem), _) => Some(format!("{stem} {}", i + 1)),
                (None, _) => None,
            };
        }
        layer
    });
    Ok((layers.collect(), read.backdrop))
}

/// Adds the layers of the document `name` (a file of the folder, any format gradmesh reads)
/// above the layers of `editor`'s document, with an SVG or PDF file's backdrop above the
/// picture's backdrops, as one step of the history (undo takes both away).
pub fn import_layers(folder: &Folder, editor: &mut Editor, name: &str) -> Result<(), String> {
    let path = folder.resolve(name)?;
    let (layers, backdrop) = read_layers(&path)?;
    if layers.is_empty() {
        return Err(format!("{name} has no layers"));
    }
    let mut next = editor.history.current().clone().with_backdrop(backdrop);
    next.hidden.extend(layers.iter().map(|_| false));
    next.doc.layers.extend(layers);
    editor.history.replace(next)
}

/// Adds what the page shows of the files to the state message `state`: `saved` (the file and
/// the time of the last save, or null) and `recovery` (the recovery copy waiting for the
/// user's choice: its path and time, or null).
pub fn describe(files: &FileState, state: &mut Value) {
    state["saved"] = match &files.last_save {
        Some((file, at)) => json!({"file": file, "at": at}),
        None => Value::Null,
    };
    state["recovery"] = match files.recovery.found() {
        Some(found) => json!({"file": found.path.display().to_string(), "at": found.at}),
        None => Value::Null,
    };
}

fn unix_millis() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_millis() as u64)
        .unwrap_or(0)
}
