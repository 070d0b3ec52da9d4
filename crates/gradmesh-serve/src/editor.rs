//! The document being edited, its undo history, and where it is saved.

use std::path::{Path, PathBuf};

use gradmesh::formats::{self, Format};
use gradmesh::{ColourSpace, Document, GradientMesh};

use crate::ops::{Applied, Op, Picture};

/// Undo and redo steps kept at most.
pub const MAX_HISTORY: usize = 500;

/// The picture, the pictures before it (undo) and after it (redo), and the open gesture.
///
/// A gesture (a drag, or a colour picked while the mouse moves) is a run of edits with the same
/// gesture number: each is applied to the picture as it was before the gesture began, and the
/// whole run is one step of the history. So only the last edit of a run matters, and edits the
/// server had no time to render can be dropped.
#[derive(Clone, Debug)]
pub struct History {
    current: Picture,
    undo: Vec<Picture>,
    redo: Vec<Picture>,
    gesture: Option<u64>,
    /// Changes since the last save or open.
    version: u64,
    saved_version: u64,
}

impl History {
    /// A history starting at `picture`.
    pub fn new(picture: Picture) -> History {
        History {
            current: picture,
            undo: Vec::new(),
            redo: Vec::new(),
            gesture: None,
            version: 0,
            saved_version: 0,
        }
    }

    /// The picture now.
    pub fn current(&self) -> &Picture {
        &self.current
    }

    /// Applies `op`, as part of `gesture` if given, and returns its note for the user (see
    /// [`Op::apply`]). The result must pass the validator (every layer); else the picture stays
    /// as it was and the validator's message is returned.
    pub fn apply(&mut self, op: &Op, gesture: Option<u64>) -> Result<Option<String>, String> {
        self.apply_selecting(op, gesture)
            .map(|applied| applied.note)
    }

    /// [`History::apply`], with what a mesh tool leaves selected.
    pub fn apply_selecting(&mut self, op: &Op, gesture: Option<u64>) -> Result<Applied, String> {
        let continuing = gesture.is_some() && gesture == self.gesture && !self.undo.is_empty();
        let mut next = if continuing {
            self.undo.last().expect("a gesture has its start").clone()
        } else {
            self.current.clone()
        };
        let applied = op.apply_selecting(&mut next)?;
        check_picture(&next, Some(&self.current))?;
        if !continuing {
            self.undo.push(std::mem::replace(&mut self.current, next));
            if self.undo.len() > MAX_HISTORY {
                self.undo.remove(0);
            }
        } else {
            self.current = next;
        }
        self.redo.clear();
        self.gesture = gesture;
        self.version += 1;
        Ok(applied)
    }

    /// Replaces the whole picture as one step (a recovery copy restored, layers imported),
    /// if every layer passes the validator.
    pub fn replace(&mut self, picture: Picture) -> Result<(), String> {
        check_picture(&picture, None)?;
        self.undo
            .push(std::mem::replace(&mut self.current, picture));
        if self.undo.len() > MAX_HISTORY {
            self.undo.remove(0);
        }
        self.redo.clear();
        self.gesture = None;
        self.version += 1;
        Ok(())
    }

    /// Ends the open gesture: the next edit starts a new step.
    pub fn end_gesture(&mut self) {
        self.gesture = None;
    }

    /// Goes back one step; false if there is none.
    pub fn undo(&mut self) -> bool {
        self.gesture = None;
        match self.undo.pop() {
            Some(previous) => {
                self.redo
                    .push(std::mem::replace(&mut self.current, previous));
                self.version += 1;
                true
            }
            None => false,
        }
    }

    /// Goes forward one step; false if there is none.
    pub fn redo(&mut self) -> bool {
        self.gesture = None;
        match self.redo.pop() {
            Some(next) => {
                self.undo.push(std::mem::replace(&mut self.current, next));
                self.version += 1;
                true
            }
            None => false,
        }
    }

    /// Whether there is a step to undo, and one to redo.
    pub fn can_undo_redo(&self) -> (bool, bool) {
        (!self.undo.is_empty(), !self.redo.is_empty())
    }

    /// A number that changes with every change of the picture.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Whether a gesture is open.
    pub fn gesture_open(&self) -> bool {
        self.gesture.is_some()
    }

    /// Whether the picture changed since it was last saved or opened.
    pub fn modified(&self) -> bool {
        self.version != self.saved_version
    }

    /// Marks the picture as saved.
    pub fn mark_saved(&mut self) {
        self.saved_version = self.version;
    }
}

/// Refuses a picture with an invalid layer, with the validator's message. Layers equal to the
/// same layer of `checked` (a picture already checked) are not checked again.
pub fn check_picture(picture: &Picture, checked: Option<&Picture>) -> Result<(), String> {
    for (i, mesh) in picture.doc.layers.iter().enumerate() {
        let unchanged = checked.and_then(|c| c.doc.layers.get(i)) == Some(mesh);
        if unchanged || (mesh.faces.is_empty() && mesh.points.is_empty()) {
            continue;
        }
        gradmesh::validate(mesh).map_err(|e| {
            let name = mesh.name.as_deref().unwrap_or("unnamed");
            format!("layer {i} ({name}): {e}")
        })?;
    }
    Ok(())
}

/// The document being edited and the file it is saved to.
#[derive(Debug)]
pub struct Editor {
    /// Its history.
    pub history: History,
    /// Where "save" writes: the file opened if it was JSON, else the same name with `.json`;
    /// `None` for a new document never saved.
    pub path: Option<PathBuf>,
}

impl Editor {
    /// A new document: one empty layer in Lab.
    pub fn new_document() -> Editor {
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        mesh.name = Some("Layer 1".into());
        Editor {
            history: History::new(Picture::new(Document::new(vec![mesh]))),
            path: None,
        }
    }

    /// The document in the file at `path`, with an SVG or PDF file's backdrop
    /// ([`crate::backdrop::read_document`]).
    pub fn open(path: &Path) -> Result<Editor, String> {
        let read = crate::backdrop::read_document(path)?;
        let picture = Picture::new(read.document).with_backdrop(read.backdrop);
        Ok(Editor {
            history: History::new(picture),
            path: Some(save_path_for(path)),
        })
    }

    /// Writes the document as JSON to `path` (atomically) and makes it the file "save" writes.
    pub fn save_to(&mut self, path: &Path) -> Result<(), String> {
        if Format::from_path(path) != Some(Format::Json) {
            return Err(format!(
                "refused: {} must end in .json (documents are saved in the native JSON format)",
                path.display()
            ));
        }
        let text = formats::json::write_document(&self.history.current().doc);
        formats::write_atomic(path, text.as_bytes()).map_err(|e| e.to_string())?;
        self.path = Some(path.to_path_buf());
        self.history.mark_saved();
        Ok(())
    }
}

/// The JSON file a document read from `path` is saved to.
pub fn save_path_for(path: &Path) -> PathBuf {
    if Format::from_path(path) == Some(Format::Json) {
        path.to_path_buf()
    } else {
        path.with_extension("json")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Picture {
        let mut picture = Picture::new(Document::default());
        Op::AddLayer { name: None }.apply(&mut picture).unwrap();
        Op::AddRectangle {
            layer: 0,
            rect: [0.0, 0.0, 100.0, 100.0],
        }
        .apply(&mut picture)
        .unwrap();
        picture
    }

    fn move_point(dx: f64) -> Op {
        Op::MovePoints {
            layer: 0,
            points: vec![0],
            dx,
            dy: 0.0,
        }
    }

    fn x0(h: &History) -> f64 {
        h.current().doc.layers[0].points[0].position.x
    }

    #[test]
    fn a_gesture_is_one_step_applied_to_its_start() {
        let mut h = History::new(square());
        h.apply(&move_point(5.0), Some(1)).unwrap();
        h.apply(&move_point(7.0), Some(1)).unwrap();
        assert_eq!(x0(&h), 7.0);
        h.end_gesture();
        h.apply(&move_point(1.0), Some(2)).unwrap();
        assert_eq!(x0(&h), 8.0);
        assert!(h.undo());
        assert_eq!(x0(&h), 7.0);
        assert!(h.undo());
        assert_eq!(x0(&h), 0.0);
        assert!(!h.undo());
        assert!(h.redo());
        assert_eq!(x0(&h), 7.0);
    }

    #[test]
    fn invalid_results_are_refused_whole() {
        let mut h = History::new(square());
        let err = h
            .apply(
                &Op::AddFace {
                    layer: 0,
                    points: vec![0, 1],
                },
                None,
            )
            .unwrap_err();
        assert!(err.contains("layer 0"), "{err}");
        assert_eq!(h.current(), &square());
        assert!(!h.can_undo_redo().0);
    }

    #[test]
    fn the_sides_of_a_discontinuity_take_their_own_colours() {
        let mut h = History::new(square());
        let edge = |kind| Op::SetEdge {
            layer: 0,
            a: 4,
            b: 5,
            kind,
            sharpness: None,
        };
        h.apply(
            &Op::SplitEdge {
                layer: 0,
                a: 0,
                b: 1,
            },
            None,
        )
        .unwrap();
        h.apply(
            &Op::SplitEdge {
                layer: 0,
                a: 2,
                b: 3,
            },
            None,
        )
        .unwrap();
        let split = Op::SplitFace {
            layer: 0,
            face: 0,
            a: 4,
            b: 5,
        };
        h.apply(&split, None).unwrap();
        h.apply(&edge(crate::ops::EdgeKindName::Discontinuous), None)
            .unwrap();
        let side = |face| Op::SetSideColour {
            layer: 0,
            point: 4,
            face,
            colour: None,
            css: Some("#00ff00".into()),
        };
        h.apply(&side(1), None).unwrap();
        let mesh = &h.current().doc.layers[0];
        assert_eq!((mesh.wedges.len(), mesh.wedges[0].face), (1, 1));
        // Not a corner of the face: refused.
        let wrong = Op::SetSideColour {
            layer: 0,
            point: 1,
            face: 1,
            colour: None,
            css: Some("red".into()),
        };
        assert!(h.apply(&wrong, None).is_err());
    }

    #[test]
    fn split_edge_split_face_and_delete_stay_valid() {
        let mut h = History::new(square());
        h.apply(
            &Op::SplitEdge {
                layer: 0,
                a: 0,
                b: 1,
            },
            None,
        )
        .unwrap();
        h.apply(
            &Op::SplitEdge {
                layer: 0,
                a: 2,
                b: 3,
            },
            None,
        )
        .unwrap();
        let mesh = &h.current().doc.layers[0];
        assert_eq!(mesh.points.len(), 6);
        assert_eq!(mesh.faces[0].len(), 6);
        h.apply(
            &Op::SplitFace {
                layer: 0,
                face: 0,
                a: 4,
                b: 5,
            },
            None,
        )
        .unwrap();
        assert_eq!(h.current().doc.layers[0].faces.len(), 2);
        h.apply(
            &Op::DeleteFaces {
                layer: 0,
                faces: vec![1],
            },
            None,
        )
        .unwrap();
        let mesh = &h.current().doc.layers[0];
        assert_eq!((mesh.faces.len(), mesh.points.len()), (1, 4));
        h.apply(
            &Op::DeletePoints {
                layer: 0,
                points: vec![0],
            },
            None,
        )
        .unwrap();
        assert!(h.current().doc.layers[0].points.is_empty());
    }
}
