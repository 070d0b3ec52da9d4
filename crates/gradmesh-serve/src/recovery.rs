//! Recovery copies: the unsaved edits of the document, written after each batch of edits
//! beside its file (`.NAME.json.recover`) or, for a document without a file, in the user's
//! state folder (`$XDG_STATE_HOME/gradmesh/untitled-HASH.json.recover`), and offered back when
//! the same document is served again.

use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

use gradmesh::{formats, Document};

use crate::editor::History;

/// A recovery copy found when the document was opened, waiting for the user to restore or
/// discard it.
#[derive(Debug)]
pub struct Found {
    /// Where it is.
    pub path: PathBuf,
    /// What it holds.
    pub doc: Document,
    /// When it was written, in milliseconds since the Unix epoch.
    pub at: u64,
}

/// The recovery copy of the document being edited.
#[derive(Debug, Default)]
pub struct Recovery {
    /// The folder copies of documents without a file go in; `None` with recovery off.
    state_dir: Option<PathBuf>,
    /// Whether copies are kept (the command line turns this on; tests of the API leave it off).
    enabled: bool,
    /// Where the document's copy goes.
    path: Option<PathBuf>,
    /// The history version this session last wrote to `path`.
    written: Option<u64>,
    /// A copy found at `path` when the document was opened.
    found: Option<Found>,
}

/// The user's state folder: `$XDG_STATE_HOME`, else `~/.local/state`.
pub fn default_state_dir() -> Option<PathBuf> {
    let xdg = std::env::var_os("XDG_STATE_HOME").map(PathBuf::from);
    if let Some(dir) = xdg.filter(|d| d.is_absolute()) {
        return Some(dir);
    }
    let home = std::env::var_os("HOME").map(PathBuf::from)?;
    Some(home.join(".local/state"))
}

/// Where the recovery copy of a document goes: beside `document` if it has a file, else in
/// `state_dir/gradmesh`, named by a hash of `key` (what the document was made from).
pub fn recovery_path(
    document: Option<&Path>,
    key: &str,
    state_dir: Option<&Path>,
) -> Option<PathBuf> {
    match document {
        Some(file) => {
            let name = file.file_name()?.to_string_lossy();
            Some(file.with_file_name(format!(".{name}.recover")))
        }
        None => {
            let name = format!("untitled-{:016x}.json.recover", fnv1a(key.as_bytes()));
            Some(state_dir?.join("gradmesh").join(name))
        }
    }
}

/// The 64-bit FNV-1a hash: stable across runs and builds, as a file name needs.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &b| {
        (hash ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

impl Recovery {
    /// Turns recovery copies on, with `state_dir` for documents without a file.
    pub fn enable(&mut self, state_dir: Option<PathBuf>) {
        self.enabled = true;
        self.state_dir = state_dir;
    }

    /// Follows the document just opened (its file, or `key` naming what it was made from): a
    /// copy already there is offered. Returns a message if a copy there cannot be read (it is
    /// moved aside, never lost).
    pub fn attach(&mut self, document: Option<&Path>, key: &str) -> Option<String> {
        self.written = None;
        self.found = None;
        self.path = None;
        if !self.enabled {
            return None;
        }
        self.path = recovery_path(document, key, self.state_dir.as_deref());
        let path = self.path.clone()?;
        if !path.is_file() {
            return None;
        }
        let read = std::fs::read_to_string(&path)
            .map_err(|e| e.to_string())
            .and_then(|text| formats::json::read_document(&text).map_err(|e| e.to_string()));
        match read {
            Ok(doc) => {
                let at = modified_millis(&path);
                self.found = Some(Found { path, doc, at });
                None
            }
            Err(e) => {
                let aside =
                    path.with_extension(format!("recover.unreadable-{}", std::process::id()));
                let moved = std::fs::rename(&path, &aside).is_ok();
                Some(format!(
                    "the recovery copy {} cannot be read ({e}); {}",
                    path.display(),
                    if moved {
                        format!("it was moved to {}", aside.display())
                    } else {
                        "it was left in place".into()
                    }
                ))
            }
        }
    }

    /// The copy found and not yet restored or discarded.
    pub fn found(&self) -> Option<&Found> {
        self.found.as_ref()
    }

    /// Writes the copy if the document has edits not saved and not yet written (not while a
    /// gesture is open: its last move is written when it ends), and removes it when there are
    /// none. Returns the error of a failed write.
    pub fn keep(&mut self, history: &History) -> Result<(), String> {
        if !self.enabled || self.found.is_some() || history.gesture_open() {
            return Ok(());
        }
        let Some(path) = self.path.clone() else {
            return Ok(());
        };
        if history.modified() {
            if self.written != Some(history.version()) {
                self.write(&path, history)?;
            }
        } else if self.written.take().is_some() {
            remove(&path)?;
        }
        Ok(())
    }

    fn write(&mut self, path: &Path, history: &History) -> Result<(), String> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("cannot make the folder {}: {e}", dir.display()))?;
        }
        let text = formats::json::write_document(&history.current().doc);
        formats::write_atomic(path, text.as_bytes()).map_err(|e| e.to_string())?;
        self.written = Some(history.version());
        Ok(())
    }

    /// Writes the copy now if there are edits not saved, gesture or not: the process is about
    /// to end. Returns where the unsaved work is (the copy written, or a copy found at start
    /// and not yet chosen), or the error of a failed write.
    pub fn at_exit(&mut self, history: &History) -> Result<Option<PathBuf>, String> {
        if let Some(found) = &self.found {
            return Ok(Some(found.path.clone()));
        }
        let Some(path) = self.path.clone().filter(|_| self.enabled) else {
            return Ok(None);
        };
        if !history.modified() {
            return Ok(None);
        }
        if self.written != Some(history.version()) {
            self.write(&path, history)?;
        }
        Ok(Some(path))
    }

    /// The document was saved (to `document`): its copy goes, and the next follows its file.
    pub fn saved(&mut self, document: &Path, key: &str) -> Result<(), String> {
        if let (Some(path), Some(_)) = (&self.path, self.written.take()) {
            remove(path)?;
        }
        if self.enabled {
            self.path = recovery_path(Some(document), key, self.state_dir.as_deref());
        }
        Ok(())
    }

    /// The copy found, to restore: the copy stays on disk until the document is saved.
    pub fn take_found(&mut self) -> Option<Document> {
        self.found.take().map(|found| found.doc)
    }

    /// Deletes the copy found.
    pub fn discard_found(&mut self) -> Result<(), String> {
        match self.found.take() {
            Some(found) => remove(&found.path),
            None => Ok(()),
        }
    }
}

fn remove(path: &Path) -> Result<(), String> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("cannot remove {}: {e}", path.display())),
    }
}

fn modified_millis(path: &Path) -> u64 {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
        .map(|d| d.as_millis() as u64)
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_go_beside_the_file_or_in_the_state_folder() {
        let beside = recovery_path(Some(Path::new("/a/art.json")), "k", None).unwrap();
        assert_eq!(beside, Path::new("/a/.art.json.recover"));
        assert_eq!(recovery_path(None, "k", None), None);
        let state = Path::new("/s");
        let one = recovery_path(None, "/folder", Some(state)).unwrap();
        let two = recovery_path(None, "/other", Some(state)).unwrap();
        assert!(
            one.starts_with("/s/gradmesh") && one != two,
            "{one:?} {two:?}"
        );
        assert!(one.to_string_lossy().ends_with(".json.recover"));
        assert_eq!(one, recovery_path(None, "/folder", Some(state)).unwrap());
    }
}
