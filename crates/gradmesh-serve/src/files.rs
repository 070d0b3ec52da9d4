//! What keeps the user's work: saving without replacing a file the session did not write
//! unless asked to, and what the page is told about the file (its name, the last save).

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use axum::http::StatusCode;
use serde_json::{json, Value};

use crate::editor::Editor;
use crate::security::Folder;

/// The code of the error refusing to replace a file the session did not write.
pub const FILE_EXISTS: &str = "file_exists";

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
        Some(FILE_EXISTS) => StatusCode::CONFLICT,
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
}

impl FileState {
    /// A number that changes whenever [`describe`] would say something else.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Notes that `editor` was just opened from `source` (or made new, without one): the
    /// source may be replaced if the document is saved to it, and no save is reported yet.
    pub fn opened(&mut self, source: Option<&Path>, editor: &Editor) {
        if let (Some(source), Some(path)) = (source, &editor.path) {
            if source == path {
                self.replaceable.insert(path.clone());
            }
        }
        self.last_save = None;
        self.generation += 1;
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
    Ok(())
}

/// Adds what the page shows of the files to the state message `state`: `saved` (the file and
/// the time of the last save, or null).
pub fn describe(files: &FileState, state: &mut Value) {
    state["saved"] = match &files.last_save {
        Some((file, at)) => json!({"file": file, "at": at}),
        None => Value::Null,
    };
}

fn unix_millis() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_millis() as u64)
        .unwrap_or(0)
}
