//! The edits the editor makes to a document, as the page sends them.
//!
//! Each [`Op`] changes a [`Picture`] (the document and which layers are hidden); the
//! [`History`](crate::editor::History) checks the result with the library's validator and
//! refuses it whole if any layer is invalid.

use gradmesh::{
    parse_css_colour, ColourSpace, Document, EdgeKind, Edit, GradientMesh, VertexAddress,
    SHARPNESS_INFINITE,
};
use kurbo::{Point, Vec2};
use serde::Deserialize;
use std::sync::Arc;

use crate::backdrop::Backdrop;
use crate::tools::{self, remove_faces_and_points, Selection, ToolResult};

/// What the editor shows: the document, per layer whether it is hidden, and what the SVG or
/// PDF files it came from hold besides (their backdrops, part of the picture so that undoing
/// an import takes its backdrop away too).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Picture {
    /// The document.
    pub doc: Document,
    /// Per layer: hidden (not drawn, still saved).
    pub hidden: Vec<bool>,
    /// The backdrops, bottom first (shared between the steps of the history).
    pub backdrops: Arc<Vec<Backdrop>>,
}

impl Picture {
    /// A picture of `doc` with every layer shown, without backdrops.
    pub fn new(doc: Document) -> Picture {
        let hidden = vec![false; doc.layers.len()];
        Picture {
            doc,
            hidden,
            backdrops: Arc::default(),
        }
    }

    /// This picture with `backdrop`, if any, above its backdrops.
    pub fn with_backdrop(mut self, backdrop: Option<Backdrop>) -> Picture {
        if let Some(backdrop) = backdrop {
            Arc::make_mut(&mut self.backdrops).push(backdrop);
        }
        self
    }

    /// The document of the layers shown.
    pub fn visible(&self) -> Document {
        Document {
            layers: (self.doc.layers.iter().zip(&self.hidden))
                .filter(|(_, hidden)| !**hidden)
                .map(|(layer, _)| layer.clone())
                .collect(),
            view: self.doc.view,
        }
    }
}

/// The kind of an edge as the page names it.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum EdgeKindName {
    /// C1.
    Smooth,
    /// C0, with a sharpness (absent: infinitely sharp).
    Crease,
    /// C-1.
    Discontinuous,
}

/// One edit of the picture. Point and face indices are those of the layer's mesh.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum Op {
    /// Moves `points` by `(dx, dy)`.
    MovePoints {
        /// The layer.
        layer: usize,
        /// The points.
        points: Vec<u32>,
        /// Offset in x.
        dx: f64,
        /// Offset in y.
        dy: f64,
    },
    /// Sets the handle of point `from` towards `to` (relative to `from`).
    SetHandle {
        /// The layer.
        layer: usize,
        /// The point the handle belongs to.
        from: u32,
        /// The neighbour it points to.
        to: u32,
        /// The handle vector's x.
        x: f64,
        /// The handle vector's y.
        y: f64,
    },
    /// Sets the colour of `points`: coordinates in the layer's colour space, or a CSS colour.
    SetColour {
        /// The layer.
        layer: usize,
        /// The points.
        points: Vec<u32>,
        /// Coordinates in the layer's colour space.
        #[serde(default)]
        colour: Option<[f64; 3]>,
        /// A CSS colour (`#rrggbb`, `rgb(...)`, names).
        #[serde(default)]
        css: Option<String>,
    },
    /// Sets each of `points` to its own CSS colour (`css[i]` for `points[i]`), as the
    /// eyedropper does.
    SetColours {
        /// The layer.
        layer: usize,
        /// The points.
        points: Vec<u32>,
        /// Their colours.
        css: Vec<String>,
    },
    /// Sets the opacity of `points`.
    SetOpacity {
        /// The layer.
        layer: usize,
        /// The points.
        points: Vec<u32>,
        /// Opacity in 0..=1.
        opacity: f64,
    },
    /// Tags the edge between `a` and `b`.
    SetEdge {
        /// The layer.
        layer: usize,
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
        /// Smooth, crease or discontinuous.
        kind: EdgeKindName,
        /// A crease's sharpness (absent: infinite).
        #[serde(default)]
        sharpness: Option<f64>,
    },
    /// Adds a point in the middle of the edge between `a` and `b`, in every face along it.
    SplitEdge {
        /// The layer.
        layer: usize,
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// Splits a face in two along a new edge between two of its corners.
    SplitFace {
        /// The layer.
        layer: usize,
        /// The face.
        face: u32,
        /// One corner.
        a: u32,
        /// Another corner, not next to `a`.
        b: u32,
    },
    /// Adds a face with the given corners, in order.
    AddFace {
        /// The layer.
        layer: usize,
        /// The corners.
        points: Vec<u32>,
    },
    /// Adds a new rectangular patch of four points to a layer.
    AddRectangle {
        /// The layer.
        layer: usize,
        /// Left, top, right, bottom.
        rect: [f64; 4],
    },
    /// Deletes points and the faces that use them.
    DeletePoints {
        /// The layer.
        layer: usize,
        /// The points.
        points: Vec<u32>,
    },
    /// Deletes faces and the points no face uses any more.
    DeleteFaces {
        /// The layer.
        layer: usize,
        /// The faces.
        faces: Vec<u32>,
    },
    /// Adds an empty layer on top.
    AddLayer {
        /// Its name.
        #[serde(default)]
        name: Option<String>,
    },
    /// Moves a layer to another place in the stack.
    MoveLayer {
        /// The layer.
        layer: usize,
        /// Its new index.
        to: usize,
    },
    /// Hides or shows a layer.
    SetLayerHidden {
        /// The layer.
        layer: usize,
        /// Hidden or not.
        hidden: bool,
    },
    /// Renames a layer.
    RenameLayer {
        /// The layer.
        layer: usize,
        /// The new name (empty: none).
        name: String,
    },
    /// Deletes a layer.
    DeleteLayer {
        /// The layer.
        layer: usize,
    },
    /// Sets the colour of one side of a discontinuity: of `point` in the wedge of faces that
    /// holds `face`. Neither `colour` nor `css`: the side takes the point's colour again.
    SetSideColour {
        /// The layer.
        layer: usize,
        /// The point on the discontinuous edge.
        point: u32,
        /// A face around the point, on the side to colour.
        face: u32,
        /// Coordinates in the layer's colour space.
        #[serde(default)]
        colour: Option<[f64; 3]>,
        /// A CSS colour.
        #[serde(default)]
        css: Option<String>,
    },
    /// Sets the opacity of one side of a discontinuity: of `point` in the wedge of faces that
    /// holds `face`. A side without its own entry gets one with the point's colour (the format
    /// requires a side's colour). No `opacity`: the side takes the point's opacity again.
    SetSideOpacity {
        /// The layer.
        layer: usize,
        /// The point on the discontinuous edge.
        point: u32,
        /// A face around the point, on the side to change.
        face: u32,
        /// Opacity in 0..=1.
        #[serde(default)]
        opacity: Option<f64>,
    },
    /// Sets or removes the multi-resolution edit of a refined vertex: its colour and opacity
    /// are replaced, its position offset is replaced if given and kept if not. Neither colour,
    /// opacity nor offset: the edit is removed.
    SetRefinedEdit {
        /// The layer.
        layer: usize,
        /// Level of the refined vertex (1 or more).
        level: u32,
        /// The control face it lies in.
        face: u32,
        /// The corner of that face whose sector holds it.
        point: u32,
        /// Its place in the sector's grid.
        at: [u32; 2],
        /// New colour in the layer's space (absent: no colour edit).
        #[serde(default)]
        colour: Option<[f64; 3]>,
        /// New opacity (absent: no opacity edit).
        #[serde(default)]
        opacity: Option<f64>,
        /// New position offset `[u, v]` in the vertex's frame (absent: the edit's offset stays).
        #[serde(default)]
        offset: Option<[f64; 2]>,
    },
    /// Moves a refined vertex: sets its edit's position offset so that its limit position moves
    /// by `(dx, dy)` from where it is. Refused on a layer that allows colour edits only.
    MoveRefinedVertex {
        /// The layer.
        layer: usize,
        /// Level of the refined vertex (1 or more).
        level: u32,
        /// The control face it lies in.
        face: u32,
        /// The corner of that face whose sector holds it.
        point: u32,
        /// Its place in the sector's grid.
        at: [u32; 2],
        /// The move in x.
        dx: f64,
        /// The move in y.
        dy: f64,
    },
    /// Adds a grid of `columns` x `rows` quads over `rect` (1 to 64 each way).
    AddGrid {
        /// The layer.
        layer: usize,
        /// Two opposite corners: x0, y0, x1, y1.
        rect: [f64; 4],
        /// Quads across.
        columns: u32,
        /// Quads down.
        rows: u32,
    },
    /// Adds a mesh filling the ellipse inscribed in `rect`.
    AddEllipse {
        /// The layer.
        layer: usize,
        /// Two opposite corners of the ellipse's box: x0, y0, x1, y1.
        rect: [f64; 4],
    },
    /// Adds a mesh filling the polygon `outline`.
    AddOutline {
        /// The layer.
        layer: usize,
        /// The polygon's corners in order.
        outline: Vec<[f64; 2]>,
    },
    /// Cuts the strip of quads holding the edge from `a` to `b` with a line of new points, at
    /// `at` along the edge (0 at `a`, 1 at `b`; default the middle).
    LoopCut {
        /// The layer.
        layer: usize,
        /// One end of the edge clicked.
        a: u32,
        /// The other end.
        b: u32,
        /// Where along the edge, between 0 and 1.
        #[serde(default = "half")]
        at: f64,
    },
    /// Adds a point at `(x, y)` inside `face`, joined to each corner.
    AddPointInFace {
        /// The layer.
        layer: usize,
        /// The face.
        face: u32,
        /// The point's x.
        x: f64,
        /// The point's y.
        y: f64,
    },
    /// Removes `points`, each merging the faces around it into one.
    DissolvePoints {
        /// The layer.
        layer: usize,
        /// The points.
        points: Vec<u32>,
    },
    /// Removes the edge between `a` and `b`, merging its two faces into one.
    DissolveEdge {
        /// The layer.
        layer: usize,
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
}

fn half() -> f64 {
    0.5
}

/// What an edit did besides its change: a note for the user, and what a mesh tool leaves
/// selected.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Applied {
    /// A note for the user (the edit did more than asked).
    pub note: Option<String>,
    /// The points and face to select next.
    pub selection: Option<Selection>,
}

impl Op {
    /// Applies the edit to `picture`; returns a note for the user when the edit did more than
    /// asked (a deletion that dropped multi-resolution edits). Fails with a message for the
    /// user when the edit names nothing that exists or makes no sense; the validity of the
    /// result is checked apart.
    pub fn apply(&self, picture: &mut Picture) -> Result<Option<String>, String> {
        self.apply_selecting(picture).map(|applied| applied.note)
    }

    /// [`Op::apply`], with what a mesh tool leaves selected.
    pub fn apply_selecting(&self, picture: &mut Picture) -> Result<Applied, String> {
        if let Some(result) = self.apply_tool(picture) {
            return result;
        }
        let note = self.apply_edit(picture)?;
        Ok(Applied {
            note,
            selection: None,
        })
    }

    /// Applies an edit that is not a mesh tool; returns its note.
    fn apply_edit(&self, picture: &mut Picture) -> Result<Option<String>, String> {
        match self {
            Op::AddLayer { name } => {
                let mut mesh = GradientMesh::new(ColourSpace::Lab);
                mesh.name = name.clone();
                picture.doc.layers.push(mesh);
                picture.hidden.push(false);
                Ok(None)
            }
            Op::MoveLayer { layer, to } => {
                check_layer(picture, *layer)?;
                check_layer(picture, *to)?;
                let mesh = picture.doc.layers.remove(*layer);
                let hidden = picture.hidden.remove(*layer);
                picture.doc.layers.insert(*to, mesh);
                picture.hidden.insert(*to, hidden);
                Ok(None)
            }
            Op::SetLayerHidden { layer, hidden } => {
                check_layer(picture, *layer)?;
                picture.hidden[*layer] = *hidden;
                Ok(None)
            }
            Op::RenameLayer { layer, name } => {
                check_layer(picture, *layer)?;
                picture.doc.layers[*layer].name = (!name.is_empty()).then(|| name.clone());
                Ok(None)
            }
            Op::DeleteLayer { layer } => {
                check_layer(picture, *layer)?;
                picture.doc.layers.remove(*layer);
                picture.hidden.remove(*layer);
                Ok(None)
            }
            Op::DeletePoints { layer, .. } | Op::DeleteFaces { layer, .. } => {
                check_layer(picture, *layer)?;
                let mesh = &mut picture.doc.layers[*layer];
                let edits = mesh.edits.len();
                self.apply_to_mesh(mesh)?;
                let dropped = edits - mesh.edits.len();
                Ok((dropped > 0).then(|| {
                    format!(
                        "{dropped} multi-resolution edit{} on the deleted faces went with them",
                        if dropped == 1 { "" } else { "s" }
                    )
                }))
            }
            _ => {
                let layer = self.layer();
                check_layer(picture, layer)?;
                self.apply_to_mesh(&mut picture.doc.layers[layer])?;
                Ok(None)
            }
        }
    }

    /// Applies a mesh tool; `None` for the other edits.
    fn apply_tool(&self, picture: &mut Picture) -> Option<Result<Applied, String>> {
        let layer = self.layer();
        let mut run = |tool: &dyn Fn(&mut GradientMesh) -> Result<ToolResult, String>| {
            check_layer(picture, layer)?;
            let result = tool(&mut picture.doc.layers[layer])?;
            let mut selection = result.selection;
            selection.layer = layer;
            Ok(Applied {
                note: result.note,
                selection: Some(selection),
            })
        };
        let merged = |(face, note): (Option<u32>, Option<String>)| ToolResult {
            selection: Selection {
                layer,
                points: Vec::new(),
                face,
            },
            note,
        };
        Some(match self {
            Op::AddGrid {
                rect,
                columns,
                rows,
                ..
            } => run(&|mesh| tools::add_grid(mesh, *rect, *columns, *rows)),
            Op::AddEllipse { rect, .. } => run(&|mesh| tools::add_ellipse(mesh, *rect)),
            Op::AddOutline { outline, .. } => run(&|mesh| tools::add_outline(mesh, outline)),
            Op::LoopCut { a, b, at, .. } => run(&|mesh| tools::loop_cut(mesh, *a, *b, *at)),
            Op::AddPointInFace { face, x, y, .. } => {
                run(&|mesh| tools::add_point_in_face(mesh, *face, Point::new(*x, *y)))
            }
            Op::DissolvePoints { points, .. } => {
                run(&|mesh| tools::dissolve_points(mesh, points).map(merged))
            }
            Op::DissolveEdge { a, b, .. } => run(&|mesh| {
                tools::dissolve_edge(mesh, *a, *b).map(|(face, note)| merged((Some(face), note)))
            }),
            _ => return None,
        })
    }

    /// The layer an edit of one mesh changes.
    fn layer(&self) -> usize {
        match self {
            Op::MovePoints { layer, .. }
            | Op::SetHandle { layer, .. }
            | Op::SetColour { layer, .. }
            | Op::SetColours { layer, .. }
            | Op::SetOpacity { layer, .. }
            | Op::SetEdge { layer, .. }
            | Op::SplitEdge { layer, .. }
            | Op::SplitFace { layer, .. }
            | Op::AddFace { layer, .. }
            | Op::AddRectangle { layer, .. }
            | Op::DeletePoints { layer, .. }
            | Op::DeleteFaces { layer, .. }
            | Op::MoveLayer { layer, .. }
            | Op::SetLayerHidden { layer, .. }
            | Op::RenameLayer { layer, .. }
            | Op::DeleteLayer { layer }
            | Op::SetSideColour { layer, .. }
            | Op::SetSideOpacity { layer, .. }
            | Op::SetRefinedEdit { layer, .. }
            | Op::MoveRefinedVertex { layer, .. }
            | Op::AddGrid { layer, .. }
            | Op::AddEllipse { layer, .. }
            | Op::AddOutline { layer, .. }
            | Op::LoopCut { layer, .. }
            | Op::AddPointInFace { layer, .. }
            | Op::DissolvePoints { layer, .. }
            | Op::DissolveEdge { layer, .. } => *layer,
            Op::AddLayer { .. } => 0,
        }
    }

    fn apply_to_mesh(&self, mesh: &mut GradientMesh) -> Result<(), String> {
        match self {
            Op::MovePoints { points, dx, dy, .. } => {
                for &p in points {
                    point_mut(mesh, p)?.position += Vec2::new(*dx, *dy);
                }
                Ok(())
            }
            Op::SetHandle { from, to, x, y, .. } => {
                check_edge(mesh, *from, *to)?;
                mesh.set_handle(*from, *to, Vec2::new(*x, *y));
                Ok(())
            }
            Op::SetColour {
                points,
                colour,
                css,
                ..
            } => set_colour(mesh, points, *colour, css.as_deref()),
            Op::SetColours { points, css, .. } => {
                if points.len() != css.len() {
                    return Err(format!(
                        "{} points but {} colours: give one colour per point",
                        points.len(),
                        css.len()
                    ));
                }
                for (&p, text) in points.iter().zip(css) {
                    set_colour(mesh, &[p], None, Some(text))?;
                }
                Ok(())
            }
            Op::SetOpacity {
                points, opacity, ..
            } => {
                for &p in points {
                    point_mut(mesh, p)?.opacity = *opacity;
                }
                Ok(())
            }
            Op::SetEdge {
                a,
                b,
                kind,
                sharpness,
                ..
            } => set_edge(mesh, *a, *b, *kind, *sharpness),
            Op::SplitEdge { a, b, .. } => split_edge(mesh, *a, *b),
            Op::SetSideColour {
                point,
                face,
                colour,
                css,
                ..
            } => set_side_colour(mesh, *point, *face, *colour, css.as_deref()),
            Op::SetSideOpacity {
                point,
                face,
                opacity,
                ..
            } => set_side_opacity(mesh, *point, *face, *opacity),
            Op::SplitFace { face, a, b, .. } => split_face(mesh, *face, *a, *b),
            Op::AddFace { points, .. } => {
                for &p in points {
                    point_mut(mesh, p)?;
                }
                mesh.add_face(points.clone());
                Ok(())
            }
            Op::AddRectangle { rect, .. } => {
                add_rectangle(mesh, *rect);
                Ok(())
            }
            Op::DeletePoints { points, .. } => delete_points(mesh, points),
            Op::DeleteFaces { faces, .. } => delete_faces(mesh, faces),
            Op::SetRefinedEdit {
                level,
                face,
                point,
                at,
                colour,
                opacity,
                offset,
                ..
            } => {
                let address = VertexAddress::new(*level, *face, *point, *at);
                let offset = offset.map(|[u, v]| Vec2::new(u, v));
                set_refined_edit(mesh, address, *colour, *opacity, offset)
            }
            Op::MoveRefinedVertex {
                level,
                face,
                point,
                at,
                dx,
                dy,
                ..
            } => {
                let address = VertexAddress::new(*level, *face, *point, *at);
                move_refined_vertex(mesh, address, Vec2::new(*dx, *dy))
            }
            Op::AddLayer { .. }
            | Op::MoveLayer { .. }
            | Op::SetLayerHidden { .. }
            | Op::RenameLayer { .. }
            | Op::DeleteLayer { .. }
            | Op::AddGrid { .. }
            | Op::AddEllipse { .. }
            | Op::AddOutline { .. }
            | Op::LoopCut { .. }
            | Op::AddPointInFace { .. }
            | Op::DissolvePoints { .. }
            | Op::DissolveEdge { .. } => {
                unreachable!("layer edits and mesh tools are applied to the picture")
            }
        }
    }
}

fn check_layer(picture: &Picture, layer: usize) -> Result<(), String> {
    if layer < picture.doc.layers.len() {
        Ok(())
    } else {
        Err(format!(
            "there is no layer {layer} (the document has {})",
            picture.doc.layers.len()
        ))
    }
}

fn point_mut(mesh: &mut GradientMesh, p: u32) -> Result<&mut gradmesh::ControlPoint, String> {
    let count = mesh.points.len();
    mesh.points
        .get_mut(p as usize)
        .ok_or_else(|| format!("there is no point {p} (the layer has {count})"))
}

/// Whether `a` and `b` are joined by an edge of some face.
fn is_edge(mesh: &GradientMesh, a: u32, b: u32) -> bool {
    mesh.faces.iter().any(|face| {
        (0..face.len()).any(|i| {
            let (p, q) = (face[i], face[(i + 1) % face.len()]);
            (p, q) == (a, b) || (p, q) == (b, a)
        })
    })
}

fn check_edge(mesh: &GradientMesh, a: u32, b: u32) -> Result<(), String> {
    if is_edge(mesh, a, b) {
        Ok(())
    } else {
        Err(format!("points {a} and {b} are not joined by an edge"))
    }
}

/// A colour given as coordinates or as CSS text, in `space`, with the text to keep.
fn colour_value(
    space: ColourSpace,
    colour: Option<[f64; 3]>,
    css: Option<&str>,
) -> Result<([f64; 3], Option<String>), String> {
    let (colour, text) = match (colour, css) {
        (Some(c), None) => (c, None),
        (None, Some(text)) => {
            let (c, _alpha) = parse_css_colour(text, space)
                .map_err(|e| format!("{text:?} is not a colour: {e}"))?;
            (c, Some(text.to_string()))
        }
        _ => return Err("give either a colour's coordinates or a CSS colour".into()),
    };
    if colour.iter().any(|c| !c.is_finite()) {
        return Err("colour coordinates must be finite numbers".into());
    }
    Ok((colour, text))
}

fn set_colour(
    mesh: &mut GradientMesh,
    points: &[u32],
    colour: Option<[f64; 3]>,
    css: Option<&str>,
) -> Result<(), String> {
    let (colour, text) = colour_value(mesh.colour_space, colour, css)?;
    for &p in points {
        let point = point_mut(mesh, p)?;
        point.colour = colour;
        point.colour_text = text.clone();
    }
    Ok(())
}

/// The index in `mesh.wedges` of the entry of the side of `point` that holds `face`, if it has
/// one (the entry may name any face of that side); fails if the point or face does not exist or
/// the face does not hold the point.
fn side_entry(mesh: &mut GradientMesh, point: u32, face: u32) -> Result<Option<usize>, String> {
    point_mut(mesh, point)?;
    let corners = mesh
        .faces
        .get(face as usize)
        .ok_or_else(|| format!("there is no face {face}"))?;
    if !corners.contains(&point) {
        return Err(format!("point {point} is not a corner of face {face}"));
    }
    let side = wedge_faces(mesh, point, face);
    Ok((mesh.wedges.iter()).position(|w| w.point == point && side.contains(&w.face)))
}

/// The faces around `point` on the same side of its discontinuous edges as `face` (its wedge):
/// those reached from `face` across edges at `point` that are not discontinuous.
fn wedge_faces(mesh: &GradientMesh, point: u32, face: u32) -> Vec<u32> {
    // The neighbours of `point` along the edges of face `f`.
    let neighbours = |f: u32| {
        let corners = &mesh.faces[f as usize];
        let n = corners.len();
        let i = corners.iter().position(|&c| c == point);
        i.map(|i| [corners[(i + 1) % n], corners[(i + n - 1) % n]])
    };
    let mut side = vec![face];
    let mut next = 0;
    while next < side.len() {
        let f = side[next];
        next += 1;
        for q in neighbours(f).into_iter().flatten() {
            if mesh.edge_tag(point, q).kind == EdgeKind::Discontinuous {
                continue;
            }
            for g in 0..mesh.faces.len() as u32 {
                if !side.contains(&g) && neighbours(g).is_some_and(|ns| ns.contains(&q)) {
                    side.push(g);
                }
            }
        }
    }
    side
}

fn set_side_opacity(
    mesh: &mut GradientMesh,
    point: u32,
    face: u32,
    opacity: Option<f64>,
) -> Result<(), String> {
    let existing = side_entry(mesh, point, face)?;
    match (existing, opacity) {
        (Some(i), _) => mesh.wedges[i].opacity = opacity,
        (None, None) => {}
        (None, Some(_)) => {
            let p = &mesh.points[point as usize];
            mesh.wedges.push(gradmesh::WedgeOverride {
                point,
                face,
                colour: p.colour,
                colour_text: p.colour_text.clone(),
                opacity,
                handles: Default::default(),
            });
        }
    }
    Ok(())
}

fn set_side_colour(
    mesh: &mut GradientMesh,
    point: u32,
    face: u32,
    colour: Option<[f64; 3]>,
    css: Option<&str>,
) -> Result<(), String> {
    let existing = side_entry(mesh, point, face)?;
    if colour.is_none() && css.is_none() {
        if let Some(i) = existing {
            mesh.wedges.remove(i);
        }
        return Ok(());
    }
    let (colour, text) = colour_value(mesh.colour_space, colour, css)?;
    match existing {
        Some(i) => {
            mesh.wedges[i].colour = colour;
            mesh.wedges[i].colour_text = text;
        }
        None => mesh.wedges.push(gradmesh::WedgeOverride {
            point,
            face,
            colour,
            colour_text: text,
            opacity: None,
            handles: Default::default(),
        }),
    }
    Ok(())
}

fn set_edge(
    mesh: &mut GradientMesh,
    a: u32,
    b: u32,
    kind: EdgeKindName,
    sharpness: Option<f64>,
) -> Result<(), String> {
    check_edge(mesh, a, b)?;
    let (kind, sharpness) = match kind {
        EdgeKindName::Smooth => (EdgeKind::Smooth, None),
        EdgeKindName::Crease => match sharpness {
            Some(s) if s >= SHARPNESS_INFINITE => (EdgeKind::Crease, None),
            s => (EdgeKind::Crease, s),
        },
        EdgeKindName::Discontinuous => (EdgeKind::Discontinuous, None),
    };
    mesh.set_edge(a, b, kind, sharpness);
    Ok(())
}

fn split_edge(mesh: &mut GradientMesh, a: u32, b: u32) -> Result<(), String> {
    check_edge(mesh, a, b)?;
    let (ca, cb) = (&mesh.points[a as usize], &mesh.points[b as usize]);
    let colour = [0, 1, 2].map(|i| (ca.colour[i] + cb.colour[i]) / 2.0);
    let opacity = (ca.opacity + cb.opacity) / 2.0;
    tools::insert_point_on_edge(mesh, a, b, 0.5, colour, opacity);
    Ok(())
}

fn split_face(mesh: &mut GradientMesh, face: u32, a: u32, b: u32) -> Result<(), String> {
    let corners = mesh
        .faces
        .get(face as usize)
        .ok_or_else(|| format!("there is no face {face}"))?
        .clone();
    let n = corners.len();
    let find = |p: u32| {
        corners
            .iter()
            .position(|&c| c == p)
            .ok_or_else(|| format!("point {p} is not a corner of face {face}"))
    };
    let (i, j) = (find(a)?, find(b)?);
    let gap = (j + n - i) % n;
    if gap < 2 || gap > n - 2 {
        return Err(format!(
            "points {a} and {b} are next to each other (or the same): the face cannot be split between them"
        ));
    }
    let first: Vec<u32> = (0..=gap).map(|k| corners[(i + k) % n]).collect();
    let second: Vec<u32> = (gap..=n).map(|k| corners[(i + k) % n]).collect();
    mesh.faces[face as usize] = first;
    mesh.faces.push(second);
    Ok(())
}

fn add_rectangle(mesh: &mut GradientMesh, [x0, y0, x1, y1]: [f64; 4]) {
    let palette = tools::palette(mesh.colour_space);
    let corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)];
    let ids: Vec<u32> = corners
        .iter()
        .zip(palette)
        .map(|(&(x, y), c)| mesh.add_point(Point::new(x, y), c))
        .collect();
    mesh.add_face(ids);
}

fn delete_points(mesh: &mut GradientMesh, points: &[u32]) -> Result<(), String> {
    for &p in points {
        point_mut(mesh, p)?;
    }
    let faces: Vec<u32> = (0..mesh.faces.len() as u32)
        .filter(|&f| mesh.faces[f as usize].iter().any(|c| points.contains(c)))
        .collect();
    remove_faces_and_points(mesh, &faces, points)
}

fn delete_faces(mesh: &mut GradientMesh, faces: &[u32]) -> Result<(), String> {
    if let Some(f) = faces.iter().find(|&&f| f as usize >= mesh.faces.len()) {
        return Err(format!("there is no face {f}"));
    }
    remove_faces_and_points(mesh, faces, &[])
}

fn set_refined_edit(
    mesh: &mut GradientMesh,
    address: VertexAddress,
    colour: Option<[f64; 3]>,
    opacity: Option<f64>,
    offset: Option<Vec2>,
) -> Result<(), String> {
    if colour.is_none() && opacity.is_none() && offset.is_none() {
        mesh.remove_edit(&address);
        return Ok(());
    }
    let mut edit = (mesh.edit(&address).cloned()).unwrap_or_else(|| Edit::new(address));
    edit.colour = colour.map(gradmesh::ColourEdit::Set);
    edit.opacity = opacity.map(gradmesh::OpacityEdit::Set);
    if offset.is_some() {
        edit.offset = offset;
    }
    mesh.set_edit(edit);
    Ok(())
}

fn move_refined_vertex(
    mesh: &mut GradientMesh,
    address: VertexAddress,
    shift: Vec2,
) -> Result<(), String> {
    if !(shift.x.is_finite() && shift.y.is_finite()) {
        return Err("a move must be finite numbers".into());
    }
    let offset = crate::refined::offset_for_move(mesh, address, shift)?;
    let mut edit = (mesh.edit(&address).cloned()).unwrap_or_else(|| Edit::new(address));
    edit.offset = Some(offset);
    mesh.set_edit(edit);
    Ok(())
}
