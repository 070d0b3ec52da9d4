//! The refined vertices of one control face at a level, with their addresses, for picking the
//! vertex of a multi-resolution edit on the page.

use gradmesh::{Edit, GradientMesh, Refinement, VertexAddress, MAX_EDIT_LEVEL};
use kurbo::Vec2;
use serde::Serialize;

/// The deepest level whose vertices the page can show (a sector then has 12 x 12 quads).
pub const MAX_PICK_LEVEL: u32 = 4;

/// One refined vertex: its address and its limit position.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RefinedVertex {
    /// The control point at the corner of its sector.
    pub point: u32,
    /// Its coordinates in the sector's grid.
    pub at: [u32; 2],
    /// Its position on the limit surface.
    pub position: [f64; 2],
}

/// Every vertex of the sectors of `face` at `level`, named through each sector (a vertex on a
/// sector's side appears once per sector that names it). Positions are those of the limit
/// surface with the layer's edits (a vertex moved by a position edit shows where it went).
pub fn face_vertices(
    mesh: &GradientMesh,
    face: u32,
    level: u32,
) -> Result<Vec<RefinedVertex>, String> {
    if !(1..=MAX_PICK_LEVEL.min(MAX_EDIT_LEVEL)).contains(&level) {
        return Err(format!("the level must be 1 to {MAX_PICK_LEVEL}"));
    }
    let corners = mesh
        .faces
        .get(face as usize)
        .ok_or_else(|| format!("there is no face {face}"))?
        .clone();
    let mut plain = mesh.clone();
    plain.edits.clear();
    let (mut refinement, _) = Refinement::new(&plain, level as usize).map_err(|e| e.to_string())?;
    let size = VertexAddress::sector_size(level);
    let mut found = Vec::new();
    for &point in &corners {
        for i in 0..=size {
            for j in 0..=size {
                let address = VertexAddress::new(level, face, point, [i, j]);
                refinement
                    .set_edits(&[Edit::new(address)], plain.fine_edits)
                    .map_err(|e| e.to_string())?;
                if let Some(v) = refinement.edited_vertex(0) {
                    found.push((point, [i, j], v));
                }
            }
        }
    }
    // The edits change no topology: a vertex has the same index with them.
    refinement
        .set_edits(&mesh.edits, mesh.fine_edits)
        .map_err(|e| e.to_string())?;
    let data = refinement.evaluate();
    let limit = refinement.limit(&data, level as usize);
    Ok(found
        .into_iter()
        .map(|(point, at, v)| RefinedVertex {
            point,
            at,
            position: limit[v].position,
        })
        .collect())
}

/// The position offset (in the vertex's frame, as `Edit::offset`) that moves the limit position
/// of the refined vertex at `address` by `shift` from where it is with the layer's edits.
///
/// The limit position is an affine function of the offset (the frame is made of the level's
/// edges before its edits, and subdivision is linear), so three evaluations give it exactly.
/// Fails with the validator's message when the layer refuses position edits
/// (`fine_edits: colour-only`), and when the frame is degenerate.
pub fn offset_for_move(
    mesh: &GradientMesh,
    address: VertexAddress,
    shift: Vec2,
) -> Result<Vec2, String> {
    let start = mesh
        .edit(&address)
        .and_then(|e| e.offset)
        .unwrap_or(Vec2::ZERO);
    let mut edits = mesh.edits.clone();
    let index = match edits.iter().position(|e| e.address == address) {
        Some(i) => i,
        None => {
            edits.push(Edit::new(address));
            edits.len() - 1
        }
    };
    let (mut refinement, _) =
        Refinement::new(mesh, address.level as usize).map_err(|e| e.to_string())?;
    let mut limit_with = |offset: Vec2| -> Result<Vec2, String> {
        edits[index].offset = Some(offset);
        refinement
            .set_edits(&edits, mesh.fine_edits)
            .map_err(|e| e.to_string())?;
        let v = (refinement.edited_vertex(index))
            .ok_or_else(|| format!("the address {address} names no vertex"))?;
        let data = refinement.evaluate();
        let limit = refinement.limit(&data, address.level as usize);
        Ok(Vec2::new(limit[v].position[0], limit[v].position[1]))
    };
    let here = limit_with(start)?;
    let along_u = limit_with(start + Vec2::new(1.0, 0.0))? - here;
    let along_v = limit_with(start + Vec2::new(0.0, 1.0))? - here;
    let det = along_u.cross(along_v);
    if det.abs() <= 1e-12 * along_u.hypot() * along_v.hypot() {
        return Err(format!(
            "the refined vertex {address} cannot be moved: its frame is degenerate"
        ));
    }
    let u = shift.cross(along_v) / det;
    let v = along_u.cross(shift) / det;
    Ok(start + Vec2::new(u, v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gradmesh::ColourSpace;
    use kurbo::Point;

    #[test]
    fn a_quad_at_level_2_has_four_sectors_of_16_names() {
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for (x, y) in [(0.0, 0.0), (90.0, 0.0), (90.0, 90.0), (0.0, 90.0)] {
            mesh.add_point(Point::new(x, y), [50.0, 0.0, 0.0]);
        }
        mesh.add_face(vec![0, 1, 2, 3]);
        let vertices = face_vertices(&mesh, 0, 2).unwrap();
        assert_eq!(vertices.len(), 4 * 16);
        // [3, 3] of every sector is the face's centre.
        for v in vertices.iter().filter(|v| v.at == [3, 3]) {
            assert!((v.position[0] - 45.0).abs() < 1e-9 && (v.position[1] - 45.0).abs() < 1e-9);
        }
        assert!(face_vertices(&mesh, 1, 2).is_err());
        assert!(face_vertices(&mesh, 0, 9).is_err());
    }
}
