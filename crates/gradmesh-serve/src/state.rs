//! The description of the picture the page draws its overlay and panels from.

use std::collections::BTreeSet;

use gradmesh::{ColourSpace, EdgeKind, GradientMesh};
use serde_json::{json, Value};

use crate::ops::Picture;

/// What the page needs besides the pixels.
pub struct Status<'a> {
    /// The picture.
    pub picture: &'a Picture,
    /// The file "save" writes, relative to the starting folder.
    pub file: Option<String>,
    /// Changed since saved.
    pub modified: bool,
    /// Whether undo and redo have a step.
    pub can_undo: bool,
    /// See `can_undo`.
    pub can_redo: bool,
    /// The folds of each layer (centre and area), or `None` while a gesture runs (finding
    /// them refines every changed layer to level 4).
    pub folds: Option<Vec<Vec<[f64; 3]>>>,
}

/// The folds found in each layer, kept with the layer they were found in, so that only changed
/// layers are searched again.
#[derive(Default)]
pub struct FoldCache {
    layers: Vec<Option<(GradientMesh, Vec<[f64; 3]>)>>,
}

impl FoldCache {
    /// The folds of each of `layers`: centre x, y and area.
    pub fn folds(&mut self, layers: &[GradientMesh]) -> Vec<Vec<[f64; 3]>> {
        self.layers.resize(layers.len(), None);
        (layers.iter().zip(&mut self.layers))
            .map(|(mesh, kept)| match kept {
                Some((seen, folds)) if seen == mesh => folds.clone(),
                _ => {
                    let folds = find_folds(mesh);
                    *kept = Some((mesh.clone(), folds.clone()));
                    folds
                }
            })
            .collect()
    }
}

fn find_folds(mesh: &GradientMesh) -> Vec<[f64; 3]> {
    if mesh.faces.is_empty() {
        return Vec::new();
    }
    gradmesh::render::find_folds(mesh)
        .map(|folds| {
            folds
                .iter()
                .map(|f| [f.position.x, f.position.y, f.area])
                .collect()
        })
        .unwrap_or_default()
}

impl Status<'_> {
    /// The state message.
    pub fn to_json(&self) -> Value {
        let layers: Vec<Value> = (self.picture.doc.layers.iter().zip(&self.picture.hidden))
            .enumerate()
            .map(|(i, (mesh, &hidden))| {
                let folds = self.folds.as_ref().and_then(|f| f.get(i));
                layer_json(mesh, hidden, folds.map(Vec::as_slice))
            })
            .collect();
        json!({
            "type": "state",
            "file": self.file,
            "modified": self.modified,
            "can_undo": self.can_undo,
            "can_redo": self.can_redo,
            "folds_checked": self.folds.is_some(),
            // The rectangle the document says it shows (a vectorised picture's), or null.
            "view": self.picture.doc.view.map(|r| [r.x0, r.y0, r.x1, r.y1]),
            "layers": layers,
        })
    }
}

fn layer_json(mesh: &GradientMesh, hidden: bool, folds: Option<&[[f64; 3]]>) -> Value {
    let space = mesh.colour_space;
    let points: Vec<[f64; 2]> = mesh
        .points
        .iter()
        .map(|p| [p.position.x, p.position.y])
        .collect();
    let colours: Vec<[f64; 3]> = mesh.points.iter().map(|p| p.colour).collect();
    let hex: Vec<String> = mesh
        .points
        .iter()
        .map(|p| srgb_hex(space, p.colour))
        .collect();
    let opacity: Vec<f64> = mesh.points.iter().map(|p| p.opacity).collect();
    let out_of_gamut: Vec<usize> = (mesh.points.iter().enumerate())
        .filter(|(_, p)| !space.in_srgb_gamut(p.colour))
        .map(|(i, _)| i)
        .collect();
    let mut edges = BTreeSet::new();
    let mut handles = Vec::new();
    for face in &mesh.faces {
        for i in 0..face.len() {
            let (a, b) = (face[i], face[(i + 1) % face.len()]);
            edges.insert((a.min(b), a.max(b)));
            for (from, to) in [(a, b), (b, a)] {
                let h = mesh.handle(from, to);
                handles.push(json!([from, to, h.x, h.y]));
            }
        }
    }
    let edges: Vec<Value> = edges
        .into_iter()
        .map(|(a, b)| {
            let tag = mesh.edge_tag(a, b);
            let kind = match tag.kind {
                EdgeKind::Smooth => "smooth",
                EdgeKind::Crease => "crease",
                EdgeKind::Discontinuous => "discontinuous",
            };
            json!([a, b, kind, tag.sharpness])
        })
        .collect();
    let folds = folds.unwrap_or_default();
    let edits: Vec<Value> = mesh
        .edits
        .iter()
        .map(|e| {
            json!([
                e.address.level,
                e.address.face,
                e.address.point,
                e.address.at,
                e.offset.map(|o| [o.x, o.y]),
            ])
        })
        .collect();
    let sides: Vec<Value> = mesh
        .wedges
        .iter()
        .map(|w| json!([w.point, w.face, srgb_hex(space, w.colour), w.opacity]))
        .collect();
    json!({
        "name": mesh.name,
        "sides": sides,
        "space": space.name(),
        "hidden": hidden,
        "points": points,
        "colours": colours,
        "hex": hex,
        "opacity": opacity,
        "faces": mesh.faces,
        "edges": edges,
        "handles": handles,
        "out_of_gamut": out_of_gamut,
        "folds": folds,
        "edits": edits,
    })
}

/// `colour` (in `space`) as `#rrggbb` in sRGB, clamped to the gamut.
pub fn srgb_hex(space: ColourSpace, colour: [f64; 3]) -> String {
    let linear = space.to_linear_srgb(colour);
    let byte = |c: f64| {
        let c = c.clamp(0.0, 1.0);
        let encoded = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (encoded * 255.0).round() as u8
    };
    let [r, g, b] = linear.map(byte);
    format!("#{r:02x}{g:02x}{b:02x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_of_known_colours() {
        assert_eq!(srgb_hex(ColourSpace::Lab, [100.0, 0.0, 0.0]), "#ffffff");
        assert_eq!(srgb_hex(ColourSpace::Lab, [0.0, 0.0, 0.0]), "#000000");
        let red = gradmesh::parse_css_colour("#ff0000", ColourSpace::Lab)
            .unwrap()
            .0;
        assert_eq!(srgb_hex(ColourSpace::Lab, red), "#ff0000");
    }

    /// The state carries the document's own view, which the page's first view fits, or null.
    #[test]
    fn the_state_carries_the_documents_view() {
        let mut doc = gradmesh::Document::new(vec![GradientMesh::new(ColourSpace::Lab)]);
        let state = |doc: &gradmesh::Document| {
            let picture = Picture::new(doc.clone());
            let status = Status {
                picture: &picture,
                file: None,
                modified: false,
                can_undo: false,
                can_redo: false,
                folds: None,
            };
            status.to_json()
        };
        assert_eq!(state(&doc)["view"], Value::Null);
        doc.view = Some(kurbo::Rect::new(-50.0, -20.0, 250.0, 130.0));
        assert_eq!(state(&doc)["view"], json!([-50.0, -20.0, 250.0, 130.0]));
    }
}
