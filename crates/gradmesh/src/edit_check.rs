//! Checking multi-resolution edits against a base level: each names an existing vertex of a
//! sector, no two name the same vertex, and their numbers are within range.

use std::collections::HashMap;

use crate::colour::ColourSpace;
use crate::error::{Error, ErrorKind};
use crate::multires::{ColourEdit, Edit, FineEdits, OpacityEdit, VertexAddress, MAX_EDIT_LEVEL};
use crate::scheme::{FirstStep, MAX_MAGNITUDE};
use crate::topology::{Topology, INVALID};

/// An edit checked against the base level.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedEdit {
    /// Index of the edit in the mesh's list (for messages).
    pub index: usize,
    /// The edit.
    pub edit: Edit,
    /// The position of the sector's corner in its face.
    pub corner: usize,
}

/// The edits of a base level, checked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EditSet {
    /// The edits, in the mesh's order.
    pub edits: Vec<CheckedEdit>,
    /// The colour space the edits' colours are written in (the mesh's).
    pub space: ColourSpace,
    /// The colour space of the data they apply to (another when a renderer interpolates in
    /// another space).
    pub working: ColourSpace,
}

impl EditSet {
    /// The deepest level any edit names (0 when there is none).
    pub fn deepest_level(&self) -> usize {
        self.edits
            .iter()
            .map(|e| e.edit.address.level as usize)
            .max()
            .unwrap_or(0)
    }

    /// Whether there are no edits.
    pub fn is_empty(&self) -> bool {
        self.edits.is_empty()
    }
}

fn invalid_edit(index: usize, message: impl Into<String>) -> Error {
    ErrorKind::Invalid {
        what: format!("edit {index}"),
        message: message.into(),
    }
    .into()
}

/// Checks `edits` against a base level of topology `t`, whose faces are those of the mesh
/// (`source_point` maps split vertices back to control points), refined with `first_step`.
pub fn check_edits(
    t: &Topology,
    source_point: &[u32],
    first_step: FirstStep,
    edits: &[Edit],
    fine: FineEdits,
    space: ColourSpace,
) -> Result<EditSet, Error> {
    let mut seen: HashMap<(usize, usize, [u32; 2]), (usize, VertexAddress)> =
        HashMap::with_capacity(edits.len());
    let mut checked = Vec::with_capacity(edits.len());
    for (index, edit) in edits.iter().enumerate() {
        let a = edit.address;
        if first_step != FirstStep::Ternary {
            return Err(invalid_edit(
                index,
                "edits need the ternary first step (the mesh uses the binary one)",
            ));
        }
        if a.level == 0 || a.level > MAX_EDIT_LEVEL {
            return Err(invalid_edit(
                index,
                format!(
                    "expected a level in 1..={MAX_EDIT_LEVEL}, found {} (level 0 is the control \
                     mesh: change the point itself)",
                    a.level
                ),
            ));
        }
        if a.face as usize >= t.face_count() {
            return Err(invalid_edit(
                index,
                format!(
                    "face {} does not exist (there are {} faces)",
                    a.face,
                    t.face_count()
                ),
            ));
        }
        let corners: Vec<u32> = t
            .face_vertices(a.face as usize)
            .iter()
            .map(|&v| source_point[v as usize])
            .collect();
        let Some(corner) = corners.iter().position(|&p| p == a.point) else {
            return Err(invalid_edit(
                index,
                format!(
                    "point {} is not a corner of face {} {corners:?}",
                    a.point, a.face
                ),
            ));
        };
        let m = VertexAddress::sector_size(a.level);
        if a.at[0] > m || a.at[1] > m {
            return Err(invalid_edit(
                index,
                format!(
                    "coordinates [{}, {}] are outside the sector, whose grid at level {} runs \
                     from 0 to {m}",
                    a.at[0], a.at[1], a.level
                ),
            ));
        }
        let key = canonical(t, a.face as usize, corner, a.level, a.at);
        if let Some(&(other, named)) = seen.get(&key) {
            let same = if named == a {
                format!("({a})")
            } else {
                format!("({named} and {a} are one vertex)")
            };
            return Err(invalid_edit(
                index,
                format!("names the same vertex as edit {other} {same}"),
            ));
        }
        seen.insert(key, (index, a));
        let finite = |what: &str, v: &[f64]| -> Result<(), Error> {
            match v.iter().find(|x| !x.is_finite() || x.abs() > MAX_MAGNITUDE) {
                Some(x) => Err(invalid_edit(
                    index,
                    format!("{what} must be finite and at most {MAX_MAGNITUDE:e} in magnitude, found {x}"),
                )),
                None => Ok(()),
            }
        };
        match edit.colour {
            Some(ColourEdit::Offset(c)) => finite("colour offset", &c)?,
            Some(ColourEdit::Set(c)) => finite("colour", &c)?,
            None => {}
        }
        match edit.opacity {
            Some(OpacityEdit::Offset(o)) => finite("opacity offset", &[o])?,
            Some(OpacityEdit::Set(o)) if !(0.0..=1.0).contains(&o) => {
                return Err(invalid_edit(
                    index,
                    format!("opacity: expected a number in 0..1, found {o}"),
                ))
            }
            _ => {}
        }
        if let Some(d) = edit.offset {
            finite("position offset", &[d.x, d.y])?;
            if fine == FineEdits::ColourOnly {
                return Err(invalid_edit(
                    index,
                    "moves a refined vertex, but the mesh allows colour edits only below level 0 \
                     (\"fine_edits\": \"colour-only\")",
                ));
            }
        }
        checked.push(CheckedEdit {
            index,
            edit: edit.clone(),
            corner,
        });
    }
    Ok(EditSet {
        edits: checked,
        space,
        working: space,
    })
}

/// The smallest `(face, corner, at)` among the names of the vertex `at` of the sector of `face` at
/// `corner` (its position in the face), at `level`: two names of one vertex give the same key.
///
/// A vertex on the line `i = m` of a sector is on the line `j = m` of the next corner's sector
/// (`[m, j]` there is `[j, m]`), and one on a face edge (`j = 0` or `i = 0`) is on the other
/// face's edge, with the axes swapped (the edge runs the other way there). Discontinuous edges
/// are boundaries of the split base level: their two sides are different vertices.
fn canonical(
    t: &Topology,
    face: usize,
    corner: usize,
    level: u32,
    at: [u32; 2],
) -> (usize, usize, [u32; 2]) {
    let m = VertexAddress::sector_size(level);
    let start = (face, corner, at);
    let mut best = start;
    let mut stack = vec![start];
    let mut seen = vec![start];
    while let Some((f, c, [i, j])) = stack.pop() {
        best = best.min((f, c, [i, j]));
        let n = t.face_vertices(f).len();
        let mut next = Vec::new();
        if level >= 2 {
            if i == m {
                next.push((f, (c + 1) % n, [j, m]));
            }
            if j == m {
                next.push((f, (c + n - 1) % n, [m, i]));
            }
        }
        let v = t.face_vertices(f)[c];
        let across = |e: u32| -> Option<(usize, usize)> {
            let g = t
                .edge_faces(e as usize)
                .into_iter()
                .find(|&g| g != INVALID && g as usize != f)?;
            let cg = t.face_vertices(g as usize).iter().position(|&w| w == v)?;
            Some((g as usize, cg))
        };
        if j == 0 {
            if let Some((g, cg)) = across(t.face_edges(f)[c]) {
                next.push((g, cg, [0, i]));
            }
        }
        if i == 0 {
            if let Some((g, cg)) = across(t.face_edges(f)[(c + n - 1) % n]) {
                next.push((g, cg, [j, 0]));
            }
        }
        for x in next {
            if !seen.contains(&x) {
                seen.push(x);
                stack.push(x);
            }
        }
    }
    best
}
