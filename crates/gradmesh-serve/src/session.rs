//! What the page asks for and what it gets back: commands in, state and frames out. The
//! WebSocket and the HTTP API both go through [`Session::handle`].

use std::sync::{Arc, Mutex, MutexGuard};

use gradmesh::render::View;
use serde::Deserialize;

use crate::backdrop;
use crate::clipboard;
use crate::editor::Editor;
use crate::files::{self, FileState, Refusal};
use crate::ops::Op;
use crate::security::Folder;
use crate::state::{FoldCache, Status};
use crate::tools::Selection;
use crate::viewer::{Viewer, Viewport};

/// The server's shared state: the document being edited and the folder it lives in.
#[derive(Debug)]
pub struct App {
    /// The document.
    pub editor: Mutex<Editor>,
    /// The starting folder.
    pub folder: Folder,
    /// What the session wrote and saved ([`files`]).
    pub files: Mutex<FileState>,
}

impl App {
    /// The app editing `editor`'s document in `folder`.
    pub fn new(editor: Editor, folder: Folder) -> App {
        App {
            editor: Mutex::new(editor),
            folder,
            files: Mutex::new(FileState::default()),
        }
    }

    /// What the session wrote and saved (locked after [`App::editor`] when both are held).
    pub fn files(&self) -> MutexGuard<'_, FileState> {
        self.files.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The editor, even if a thread panicked while holding it (its data is whole: every edit
    /// replaces the picture in one assignment).
    pub fn editor(&self) -> MutexGuard<'_, Editor> {
        self.editor.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// One request of the page.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Command {
    /// An edit, part of a gesture if `gesture` is given.
    Edit {
        /// The edit.
        op: Op,
        /// The gesture it belongs to.
        #[serde(default)]
        gesture: Option<u64>,
    },
    /// Asks for the state (and a frame), changing nothing.
    State,
    /// Ends the open gesture.
    EndGesture,
    /// Undoes one step.
    Undo,
    /// Redoes one step.
    Redo,
    /// Sets the canvas size (device pixels) and the rectangle of the plane it shows.
    View {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Left, top, right, bottom.
        view: [f64; 4],
    },
    /// Saves to the document's file.
    Save {
        /// Replace the file even if this session did not write it.
        #[serde(default)]
        overwrite: bool,
    },
    /// Saves to another JSON file in the starting folder.
    SaveAs {
        /// Its name relative to the folder.
        name: String,
        /// Replace the file even if this session did not write it.
        #[serde(default)]
        overwrite: bool,
    },
    /// Opens a document of the starting folder.
    Open {
        /// Its name relative to the folder.
        name: String,
    },
    /// Starts a new document.
    New,
    /// Restores (`restore: true`) or discards the recovery copy found at start.
    Recovery {
        /// Restore it; else discard it.
        restore: bool,
    },
    /// Adds the layers of a document of the starting folder above the others.
    ImportLayers {
        /// Its name relative to the folder.
        name: String,
    },
    /// Copies faces of a layer into a layer (the same or another), moved by `(dx, dy)`.
    Paste {
        /// The layer the faces are taken from.
        from_layer: usize,
        /// Its faces to copy.
        faces: Vec<u32>,
        /// The layer they are added to.
        layer: usize,
        /// Offset in x.
        dx: f64,
        /// Offset in y.
        dy: f64,
    },
}

impl Command {
    /// Whether the command changes or saves the document (refused while a recovery copy
    /// waits for the user's choice).
    fn changes_document(&self) -> bool {
        matches!(
            self,
            Command::Edit { .. }
                | Command::Undo
                | Command::Redo
                | Command::Save { .. }
                | Command::SaveAs { .. }
                | Command::ImportLayers { .. }
                | Command::Paste { .. }
        )
    }
}

/// A message for the page.
#[derive(Clone, Debug, PartialEq)]
pub enum Outgoing {
    /// JSON: the state.
    Text(String),
    /// JSON: an error message.
    Error(String),
    /// JSON: a note about an edit that was made (`{"type": "notice", "message": …}`).
    Notice(String),
    /// JSON: what a mesh tool leaves selected (`{"type": "select", "layer": L, "points": [...],
    /// "face": F or null}`).
    Select(String),
    /// A frame (see [`crate::viewer::encode_frame`]).
    Binary(Vec<u8>),
    /// The end of the answer to a batch of commands: the page may send the next batch.
    Done,
}

/// One page's session: its viewer and what it was last told.
pub struct Session {
    app: Arc<App>,
    viewer: Viewer,
    /// The history version the page last got the state of, whether a gesture was open, and
    /// the generation of the file state.
    told_version: Option<(u64, bool, u64)>,
    folds: FoldCache,
    /// Whether states leave the folds out, for [`Session::owed_folds`] to send once the page
    /// has its frame.
    defer_folds: bool,
    /// Whether the last state left out folds that are to come.
    folds_owed: bool,
    /// What the last edit's mesh tool left selected, not yet sent.
    selected: Option<Selection>,
}

impl Session {
    /// A session of `app`.
    pub fn new(app: Arc<App>) -> Session {
        Session {
            app,
            viewer: Viewer::new(),
            told_version: None,
            folds: FoldCache::default(),
            defer_folds: false,
            folds_owed: false,
            selected: None,
        }
    }

    /// A session whose answers leave out the search for folds (it refines every changed layer
    /// to level 4, longer than the frame takes after a drag): the state says
    /// `"folds_to_come": true`, and [`Session::owed_folds`] gives the state with them.
    pub fn deferring_folds(app: Arc<App>) -> Session {
        Session {
            defer_folds: true,
            ..Session::new(app)
        }
    }

    /// Whether a state left out folds that [`Session::owed_folds`] would find.
    pub fn owes_folds(&self) -> bool {
        self.folds_owed
    }

    /// The state with the folds the last state left out, if any (none while a gesture is open:
    /// its end owes them again).
    pub fn owed_folds(&mut self) -> Option<Outgoing> {
        if !std::mem::take(&mut self.folds_owed) || self.app.editor().history.gesture_open() {
            return None;
        }
        self.told_version = None;
        let defer = std::mem::replace(&mut self.defer_folds, false);
        let state = self.status_if_changed();
        self.defer_folds = defer;
        state.map(Outgoing::Text)
    }

    /// The viewer (its last frame).
    pub fn viewer(&self) -> &Viewer {
        &self.viewer
    }

    /// Handles a batch of JSON commands: all of them in order, then one frame and one state
    /// for the result. Messages that are not commands get an error message each.
    pub fn handle_texts(&mut self, texts: &[String]) -> Vec<Outgoing> {
        let mut out = Vec::new();
        let mut commands = Vec::with_capacity(texts.len());
        for text in texts {
            match serde_json::from_str::<Command>(text) {
                Ok(c) => commands.push(c),
                Err(e) => out.push(error_message(&format!("malformed command: {e}"))),
            }
        }
        out.extend(self.handle(&commands));
        out
    }

    /// Handles commands in order, then renders once; returns the errors, the state if it
    /// changed, and the frame if pixels changed.
    pub fn handle(&mut self, commands: &[Command]) -> Vec<Outgoing> {
        let mut out = Vec::new();
        for command in commands {
            match self.run(command) {
                Ok(Some(note)) => out.push(Outgoing::Notice(
                    serde_json::json!({"type": "notice", "message": note}).to_string(),
                )),
                Ok(None) => {}
                Err(refusal) => out.push(Outgoing::Error(refusal.to_json())),
            }
            if let Some(selection) = self.selected.take() {
                let mut message = serde_json::json!(selection);
                message["type"] = "select".into();
                out.push(Outgoing::Select(message.to_string()));
            }
        }
        if let Err(e) = self.keep_recovery() {
            out.push(error_message(&format!("the recovery copy: {e}")));
        }
        let (doc, draft) = {
            let editor = self.app.editor();
            (
                editor.history.current().visible(),
                editor.history.gesture_open(),
            )
        };
        match self.viewer.render(&doc, draft) {
            Ok(Some(frame)) => out.push(Outgoing::Binary(frame)),
            Ok(None) => {}
            Err(e) => out.push(error_message(&format!("cannot render: {e}"))),
        }
        if let Some(status) = self.status_if_changed() {
            out.push(Outgoing::Text(status));
        }
        out.push(Outgoing::Done);
        out
    }

    /// The state message, if the picture changed since the page was last told. Folds are
    /// looked for only when no gesture is open, and only in the layers that changed.
    fn status_if_changed(&mut self) -> Option<String> {
        let app = Arc::clone(&self.app);
        let editor = app.editor();
        let h = &editor.history;
        let files = app.files();
        let key = (h.version(), h.gesture_open(), files.generation());
        // While a gesture runs the page moves what it drags itself: the state goes with the
        // gesture's first frame and with its end, not with every move.
        let told_this_gesture = self
            .told_version
            .is_some_and(|told| told.1 && key.1 && told.2 == key.2);
        if self.told_version == Some(key) || told_this_gesture {
            return None;
        }
        let want_folds = !key.1;
        self.folds_owed = want_folds && self.defer_folds;
        let folds =
            (want_folds && !self.defer_folds).then(|| self.folds.folds(&h.current().doc.layers));
        let (can_undo, can_redo) = h.can_undo_redo();
        let status = Status {
            picture: h.current(),
            file: editor.path.as_deref().map(|p| app.folder.name_of(p)),
            modified: h.modified(),
            can_undo,
            can_redo,
            folds,
        };
        self.told_version = Some(key);
        let mut state = status.to_json();
        state["folds_to_come"] = self.folds_owed.into();
        files::describe(&files, &mut state);
        state["backdrops"] = backdrop::describe(&h.current().backdrops, |p| app.folder.name_of(p));
        Some(state.to_string())
    }

    /// Writes the recovery copy of the edits made so far (see [`crate::recovery`]).
    fn keep_recovery(&self) -> Result<(), String> {
        let editor = self.app.editor();
        let mut files = self.app.files();
        files.recovery.keep(&editor.history)
    }

    /// Runs one command; returns the edit's note for the user, if any.
    fn run(&mut self, command: &Command) -> Result<Option<String>, Refusal> {
        let app = Arc::clone(&self.app);
        let mut editor = app.editor();
        if command.changes_document() && app.files().recovery_pending() {
            return Err(files::recovery_pending_refusal());
        }
        let mut note = None;
        let done = match command {
            Command::Edit { op, gesture } => {
                (editor.history.apply_selecting(op, *gesture)).map(|applied| {
                    note = applied.note;
                    self.selected = applied.selection;
                })
            }
            Command::State => Ok(()),
            Command::EndGesture => {
                editor.history.end_gesture();
                Ok(())
            }
            Command::Undo => {
                editor.history.undo();
                Ok(())
            }
            Command::Redo => {
                editor.history.redo();
                Ok(())
            }
            Command::View {
                width,
                height,
                view,
            } => {
                let [x0, y0, x1, y1] = *view;
                self.viewer.set_viewport(Viewport {
                    width: *width,
                    height: *height,
                    view: View::new(x0, y0, x1, y1),
                })
            }
            Command::Save { overwrite } => {
                let Some(path) = editor.path.clone() else {
                    return Err("this document has no file yet: use Save as"
                        .to_string()
                        .into());
                };
                let mut files = app.files();
                return files::save(&app.folder, &mut files, &mut editor, &path, *overwrite)
                    .map(|()| None);
            }
            Command::SaveAs { name, overwrite } => {
                let path = app.folder.resolve(name)?;
                let mut files = app.files();
                return files::save(&app.folder, &mut files, &mut editor, &path, *overwrite)
                    .map(|()| None);
            }
            Command::Open { name } => {
                let path = app.folder.resolve(name)?;
                *editor = Editor::open(&path)?;
                let key = app.folder.root().join(name).display().to_string();
                note = app.files().opened(Some(&path), &editor, &key);
                self.told_version = None;
                Ok(())
            }
            Command::New => {
                *editor = Editor::new_document();
                let key = app.folder.root().display().to_string();
                note = app.files().opened(None, &editor, &key);
                self.told_version = None;
                Ok(())
            }
            Command::Recovery { restore } => app.files().choose_recovery(&mut editor, *restore),
            Command::ImportLayers { name } => files::import_layers(&app.folder, &mut editor, name),
            Command::Paste {
                from_layer,
                faces,
                layer,
                dx,
                dy,
            } => clipboard::paste_faces(
                &mut editor.history,
                *from_layer,
                faces,
                *layer,
                kurbo::Vec2::new(*dx, *dy),
            ),
        };
        done.map(|()| note).map_err(Refusal::from)
    }
}

/// An error message for the page.
pub fn error_message(message: &str) -> Outgoing {
    Outgoing::Error(serde_json::json!({"type": "error", "message": message}).to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::editor::History;
    use crate::ops::Picture;
    use gradmesh::render::RenderOptions;

    /// A session of `picture`, not yet saved, in the temporary folder.
    fn session_of(picture: Picture) -> Session {
        let editor = Editor {
            history: History::new(picture),
            path: None,
        };
        let app = App::new(editor, Folder::new(&std::env::temp_dir()).unwrap());
        Session::new(Arc::new(app))
    }

    fn square_session() -> Session {
        let mut picture = Picture::default();
        Op::AddLayer { name: None }.apply(&mut picture).unwrap();
        Op::AddRectangle {
            layer: 0,
            rect: [0.0, 0.0, 100.0, 100.0],
        }
        .apply(&mut picture)
        .unwrap();
        session_of(picture)
    }

    fn count(out: &[Outgoing]) -> (usize, usize, usize, usize) {
        let mut n = (0, 0, 0, 0);
        for message in out {
            match message {
                Outgoing::Binary(_) => n.0 += 1,
                Outgoing::Text(_) | Outgoing::Notice(_) | Outgoing::Select(_) => n.1 += 1,
                Outgoing::Error(_) => n.2 += 1,
                Outgoing::Done => n.3 += 1,
            }
        }
        n
    }

    #[test]
    fn a_batch_of_drag_moves_gives_one_frame_of_the_last() {
        let mut session = square_session();
        let view = r#"{"type":"view","width":200,"height":200,"view":[-10,-10,110,110]}"#;
        assert_eq!(
            count(&session.handle_texts(&[view.to_string()])),
            (1, 1, 0, 1)
        );
        let moves: Vec<String> = (1..=20)
            .map(|dx| {
                format!(
                    r#"{{"type":"edit","gesture":3,"op":{{"op":"move_points","layer":0,"points":[0],"dx":{dx},"dy":0}}}}"#
                )
            })
            .collect();
        assert_eq!(count(&session.handle_texts(&moves)), (1, 1, 0, 1));
        // Later moves of the gesture: a frame, no state (the page moves the points itself);
        // its end: the state.
        let later = r#"{"type":"edit","gesture":3,"op":{"op":"move_points","layer":0,"points":[0],"dx":20,"dy":5}}"#;
        assert_eq!(
            count(&session.handle_texts(&[later.to_string()])),
            (1, 0, 0, 1)
        );
        let end = r#"{"type":"end_gesture"}"#.to_string();
        assert_eq!(count(&session.handle_texts(&[end])).1, 1);
        let editor = session.app.editor();
        assert_eq!(
            editor.history.current().doc.layers[0].points[0].position.x,
            20.0
        );
        drop(editor);
        // One undo step takes the whole drag back.
        session.handle_texts(&[r#"{"type":"undo"}"#.to_string()]);
        let editor = session.app.editor();
        assert_eq!(
            editor.history.current().doc.layers[0].points[0].position.x,
            0.0
        );
        assert!(!editor.history.can_undo_redo().0);
    }

    /// A session of a 4 x 4 grid of 100 units whose 25 points have colours of all hues.
    fn colourful_grid_session() -> Session {
        let mut picture = Picture::default();
        Op::AddLayer { name: None }.apply(&mut picture).unwrap();
        Op::AddGrid {
            layer: 0,
            rect: [0.0, 0.0, 100.0, 100.0],
            columns: 4,
            rows: 4,
        }
        .apply(&mut picture)
        .unwrap();
        Op::SetColours {
            layer: 0,
            points: (0..25).collect(),
            css: (0..25)
                .map(|i| format!("hsl({}, 90%, {}%)", i * 137 % 360, 30 + i * 7 % 50))
                .collect(),
        }
        .apply(&mut picture)
        .unwrap();
        session_of(picture)
    }

    /// The session's document rendered from scratch as its viewer renders it, exactly.
    fn exact_render(session: &Session) -> Vec<u8> {
        let vp = session.viewer.viewport().unwrap();
        let doc = session.app.editor().history.current().visible();
        let opts = RenderOptions::new(vp.width, vp.height, vp.view);
        let mut pixels = vec![0u8; 4 * (vp.width * vp.height) as usize];
        gradmesh::render::render_document_into(&doc, &opts, &mut pixels).unwrap();
        pixels
    }

    #[test]
    fn a_drag_is_drawn_as_a_draft_and_exactly_once_it_ends() {
        let mut session = colourful_grid_session();
        let view = r#"{"type":"view","width":256,"height":256,"view":[-10,-10,110,110]}"#;
        session.handle_texts(&[view.to_string()]);
        assert_eq!(session.viewer.shown().unwrap().2, exact_render(&session));
        for dx in 1..=5 {
            let step = format!(
                r#"{{"type":"edit","gesture":7,"op":{{"op":"move_points","layer":0,"points":[12],"dx":{dx},"dy":{}}}}}"#,
                -dx
            );
            session.handle_texts(&[step]);
        }
        let (drafted, exact) = (
            session.viewer.shown().unwrap().2.to_vec(),
            exact_render(&session),
        );
        assert!(drafted != exact, "the drag was drawn exactly");
        // Looser tolerances, a few 8-bit levels at most (dithered either side), and rarely.
        let differences: Vec<u8> = drafted
            .iter()
            .zip(&exact)
            .map(|(a, b)| a.abs_diff(*b))
            .collect();
        let worst = differences.iter().max().copied().unwrap_or(0);
        let mean = differences.iter().map(|&d| d as f64).sum::<f64>() / differences.len() as f64;
        assert!(
            worst <= 6 && mean < 0.5,
            "a draft {worst} levels from the exact picture, {mean} on average"
        );
        session.handle_texts(&[r#"{"type":"end_gesture"}"#.to_string()]);
        assert_eq!(session.viewer.shown().unwrap().2, exact_render(&session));
    }

    /// The state messages among `out`, parsed.
    fn states(out: &[Outgoing]) -> Vec<serde_json::Value> {
        out.iter()
            .filter_map(|m| match m {
                Outgoing::Text(t) => serde_json::from_str::<serde_json::Value>(t).ok(),
                _ => None,
            })
            .filter(|v| v["type"] == "state")
            .collect()
    }

    #[test]
    fn a_deferring_session_sends_the_folds_after_the_frame() {
        let app = Arc::clone(&colourful_grid_session().app);
        let mut session = Session::deferring_folds(app);
        let view = r#"{"type":"view","width":64,"height":64,"view":[-10,-10,110,110]}"#;
        let first = states(&session.handle_texts(&[view.to_string()]));
        assert_eq!(first[0]["folds_checked"], false);
        assert_eq!(first[0]["folds_to_come"], true);
        let Some(Outgoing::Text(owed)) = session.owed_folds() else {
            panic!("no state with the folds")
        };
        let owed: serde_json::Value = serde_json::from_str(&owed).unwrap();
        assert_eq!(
            (&owed["folds_checked"], &owed["folds_to_come"]),
            (&true.into(), &false.into())
        );
        assert!(session.owed_folds().is_none(), "the folds sent twice");

        // Folded: point 12 dragged across its neighbours. While the gesture is open nothing is
        // owed; its end owes the folds, which then show the fold.
        let step = r#"{"type":"edit","gesture":4,"op":{"op":"move_points","layer":0,"points":[12],"dx":60,"dy":0}}"#;
        let during = states(&session.handle_texts(&[step.to_string()]));
        assert_eq!(during[0]["folds_to_come"], false);
        assert!(!session.owes_folds());
        let end = states(&session.handle_texts(&[r#"{"type":"end_gesture"}"#.to_string()]));
        assert_eq!(end[0]["folds_to_come"], true);
        let Some(Outgoing::Text(owed)) = session.owed_folds() else {
            panic!("no state with the folds")
        };
        let owed: serde_json::Value = serde_json::from_str(&owed).unwrap();
        let folds = owed["layers"][0]["folds"].as_array().unwrap();
        assert!(!folds.is_empty(), "the fold is not reported");

        // A session that does not defer (the HTTP API's) gives the folds at once.
        let app = Arc::clone(&session.app);
        let mut plain = Session::new(app);
        let now = states(&plain.handle_texts(&[r#"{"type":"state"}"#.to_string()]));
        assert_eq!(now[0]["folds_checked"], true);
        assert!(!now[0]["layers"][0]["folds"].as_array().unwrap().is_empty());
        assert!(plain.owed_folds().is_none());
    }

    #[test]
    fn nothing_changed_gives_no_frame_and_bad_commands_an_error_each() {
        let mut session = square_session();
        let view = r#"{"type":"view","width":64,"height":64,"view":[0,0,100,100]}"#;
        session.handle_texts(&[view.to_string()]);
        assert_eq!(
            count(&session.handle_texts(&[r#"{"type":"state"}"#.to_string()])),
            (0, 0, 0, 1)
        );
        let bad = [
            "{".to_string(),
            r#"{"type":"view","width":0,"height":1,"view":[0,0,1,1]}"#.to_string(),
        ];
        assert_eq!(count(&session.handle_texts(&bad)), (0, 0, 2, 1));
    }
}
