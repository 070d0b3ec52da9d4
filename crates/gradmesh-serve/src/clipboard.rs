//! Copy, paste and duplicate: faces of a layer, with their points, handles, edge kinds and
//! side colours, added to a layer as new points and faces.

use std::collections::{BTreeMap, HashMap};

use gradmesh::GradientMesh;
use kurbo::Vec2;

use crate::editor::History;

/// Pastes the faces `faces` of layer `from_layer` into layer `layer`, moved by `offset`, as one
/// step of the history.
pub fn paste_faces(
    history: &mut History,
    from_layer: usize,
    faces: &[u32],
    layer: usize,
    offset: Vec2,
) -> Result<(), String> {
    let picture = history.current();
    let source = (picture.doc.layers.get(from_layer))
        .ok_or_else(|| format!("there is no layer {from_layer}"))?;
    let part = extract(source, faces)?;
    let mut next = picture.clone();
    let target =
        (next.doc.layers.get_mut(layer)).ok_or_else(|| format!("there is no layer {layer}"))?;
    paste(target, &part, offset);
    history.replace(next)
}

/// The faces `faces` of `mesh` as a mesh of their own: the points they use (numbered in order
/// of first use), their handles, edge tags and sides. Refined-vertex edits are not taken.
pub fn extract(mesh: &GradientMesh, faces: &[u32]) -> Result<GradientMesh, String> {
    if faces.is_empty() {
        return Err("no faces to copy: select a face, or the points of whole faces".into());
    }
    let mut number: HashMap<u32, u32> = HashMap::new();
    let mut face_number: HashMap<u32, u32> = HashMap::new();
    let mut part = GradientMesh {
        name: mesh.name.clone(),
        colour_space: mesh.colour_space,
        boundary: mesh.boundary,
        creasing: mesh.creasing,
        interpolate_positions: mesh.interpolate_positions,
        first_step: mesh.first_step,
        fine_edits: mesh.fine_edits,
        ..GradientMesh::default()
    };
    for &f in faces {
        let corners = mesh
            .faces
            .get(f as usize)
            .ok_or_else(|| format!("there is no face {f}"))?;
        if face_number.contains_key(&f) {
            continue;
        }
        face_number.insert(f, part.faces.len() as u32);
        let face = corners
            .iter()
            .map(|&p| {
                *number.entry(p).or_insert_with(|| {
                    part.points.push(mesh.points[p as usize].clone());
                    part.points.len() as u32 - 1
                })
            })
            .collect();
        part.faces.push(face);
    }
    let both = |a: u32, b: u32| Some((*number.get(&a)?, *number.get(&b)?));
    for (&(a, b), handle) in &mesh.handles {
        if let Some(key) = both(a, b) {
            part.handles.insert(key, *handle);
        }
    }
    for (&(a, b), tag) in &mesh.edges {
        if let Some((a, b)) = both(a, b) {
            part.edges.insert((a.min(b), a.max(b)), *tag);
        }
    }
    for wedge in &mesh.wedges {
        if let (Some(&point), Some(&face)) =
            (number.get(&wedge.point), face_number.get(&wedge.face))
        {
            let mut side = wedge.clone();
            side.point = point;
            side.face = face;
            side.handles = (wedge.handles.iter())
                .filter_map(|(to, h)| Some((*number.get(to)?, *h)))
                .collect::<BTreeMap<_, _>>();
            part.wedges.push(side);
        }
    }
    Ok(part)
}

/// Adds `part` to `target` moved by `offset`, as new points and faces after those of
/// `target`; colours are converted to `target`'s colour space. Returns the new points' range.
pub fn paste(target: &mut GradientMesh, part: &GradientMesh, offset: Vec2) -> std::ops::Range<u32> {
    let first = target.points.len() as u32;
    let convert = |c: [f64; 3]| part.colour_space.convert(target.colour_space, c);
    let points: Vec<_> = part
        .points
        .iter()
        .map(|p| {
            let mut point = p.clone();
            point.position += offset;
            point.colour = convert(p.colour);
            point
        })
        .collect();
    target.points.extend(points);
    let first_face = target.faces.len() as u32;
    target.faces.extend(
        part.faces
            .iter()
            .map(|f| f.iter().map(|p| p + first).collect()),
    );
    for (&(a, b), handle) in &part.handles {
        target.handles.insert((a + first, b + first), *handle);
    }
    for (&(a, b), tag) in &part.edges {
        target.edges.insert((a + first, b + first), *tag);
    }
    for wedge in &part.wedges {
        let mut side = wedge.clone();
        side.point += first;
        side.face += first_face;
        side.colour = convert(wedge.colour);
        side.handles = (wedge.handles.iter())
            .map(|(to, h)| (to + first, *h))
            .collect();
        target.wedges.push(side);
    }
    first..target.points.len() as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use gradmesh::{ColourSpace, ControlPoint};
    use kurbo::Point;

    fn two_quads() -> GradientMesh {
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for (x, y) in [(0., 0.), (1., 0.), (2., 0.), (0., 1.), (1., 1.), (2., 1.)] {
            mesh.points
                .push(ControlPoint::new(Point::new(x, y), [50.0, 10.0 * x, 0.0]));
        }
        mesh.faces = vec![vec![0, 1, 4, 3], vec![1, 2, 5, 4]];
        mesh.handles.insert((2, 5), Vec2::new(0.1, 0.3));
        mesh
    }

    #[test]
    fn a_face_copied_and_pasted_is_a_valid_island_of_new_points() {
        let mut mesh = two_quads();
        let part = extract(&mesh, &[1]).unwrap();
        assert_eq!((part.points.len(), part.faces.len()), (4, 1));
        assert_eq!(part.handles.get(&(1, 2)), Some(&Vec2::new(0.1, 0.3)));
        let new = paste(&mut mesh, &part, Vec2::new(5.0, 0.0));
        assert_eq!(new, 6..10);
        assert_eq!(mesh.faces[2], vec![6, 7, 8, 9]);
        assert_eq!(mesh.points[6].position, Point::new(6.0, 0.0));
        assert_eq!(mesh.handles.get(&(7, 8)), Some(&Vec2::new(0.1, 0.3)));
        gradmesh::validate(&mesh).unwrap();
        assert!(extract(&mesh, &[]).is_err());
        assert!(extract(&mesh, &[9]).is_err());
    }
}
