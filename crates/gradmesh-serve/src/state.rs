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
    /// Whether to look for folds (a refinement of every layer to level 4): skipped while a
    /// gesture runs.
    pub with_folds: bool,
}

impl Status<'_> {
    /// The state message.
    pub fn to_json(&self) -> Value {
        let layers: Vec<Value> = (self.picture.doc.layers.iter().zip(&self.picture.hidden))
            .map(|(mesh, &hidden)| layer_json(mesh, hidden, self.with_folds))
            .collect();
        json!({
            "type": "state",
            "file": self.file,
            "modified": self.modified,
            "can_undo": self.can_undo,
            "can_redo": self.can_redo,
            "folds_checked": self.with_folds,
            "layers": layers,
        })
    }
}

fn layer_json(mesh: &GradientMesh, hidden: bool, with_folds: bool) -> Value {
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
    let folds: Vec<Value> = if with_folds && !mesh.faces.is_empty() {
        gradmesh::render::find_folds(mesh)
            .map(|folds| {
                folds
                    .iter()
                    .map(|f| json!([f.position.x, f.position.y, f.area]))
                    .collect()
            })
            .unwrap_or_default()
    } else {
        Vec::new()
    };
    let edits: Vec<Value> = mesh
        .edits
        .iter()
        .map(|e| {
            json!([
                e.address.level,
                e.address.face,
                e.address.point,
                e.address.at
            ])
        })
        .collect();
    let sides: Vec<Value> = mesh
        .wedges
        .iter()
        .map(|w| json!([w.point, w.face, srgb_hex(space, w.colour)]))
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
}
