//! Tools that take points and edges out of a mesh and merge the faces around them.

use gradmesh::GradientMesh;

use super::{drop_edits_on, edge_key};

/// One face around a point: the face and the corners it holds besides the point, from the one
/// after the point around to the one before it.
struct Around {
    face: u32,
    path: Vec<u32>,
}

impl Around {
    fn first(&self) -> u32 {
        self.path[0]
    }
    fn last(&self) -> u32 {
        *self.path.last().expect("a face has 3 or more corners")
    }
}

/// The faces around `p`, each with its path.
fn faces_around(mesh: &GradientMesh, p: u32) -> Vec<Around> {
    (mesh.faces.iter().enumerate())
        .filter_map(|(f, corners)| {
            let n = corners.len();
            let i = corners.iter().position(|&c| c == p)?;
            Some(Around {
                face: f as u32,
                path: (1..n).map(|k| corners[(i + k) % n]).collect(),
            })
        })
        .collect()
}

/// The face the faces around `p` make without it: their paths joined where one ends and the
/// next begins (around the point, or across the boundary gap at a boundary point).
fn merged_around(p: u32, around: &[Around]) -> Result<Vec<u32>, String> {
    // At a boundary point the fan begins with the face whose first corner ends no other path.
    let start = (0..around.len())
        .find(|&k| !around.iter().any(|a| a.last() == around[k].first()))
        .unwrap_or(0);
    let mut used = vec![false; around.len()];
    used[start] = true;
    let mut merged = around[start].path.clone();
    let mut end = around[start].last();
    while let Some(k) = (0..around.len()).find(|&k| !used[k] && around[k].first() == end) {
        used[k] = true;
        merged.extend(&around[k].path[1..]);
        end = around[k].last();
    }
    if used.iter().any(|u| !u) {
        return Err(format!(
            "the faces around point {p} do not make one fan: it cannot be dissolved"
        ));
    }
    if merged.len() > 1 && merged.first() == merged.last() {
        merged.pop();
    }
    Ok(merged)
}

/// Refuses a merged face with fewer than three corners or one corner twice.
fn check_merged(merged: &[u32], what: &str) -> Result<(), String> {
    if merged.len() < 3 {
        return Err(format!(
            "{what} would leave a face of {} corners: delete the face instead",
            merged.len()
        ));
    }
    for (i, c) in merged.iter().enumerate() {
        if merged[i + 1..].contains(c) {
            return Err(format!(
                "{what} would make a face that meets itself at point {c}"
            ));
        }
    }
    Ok(())
}

/// Replaces `faces` (two or more) by the face `merged`, kept at the smallest of their numbers,
/// with the side overrides of the others moved to it, and removes `points`. Returns the face.
fn merge_faces(
    mesh: &mut GradientMesh,
    faces: &[u32],
    merged: Vec<u32>,
    points: &[u32],
) -> Result<u32, String> {
    let keep = *faces.iter().min().expect("faces to merge");
    for w in &mut mesh.wedges {
        if faces.contains(&w.face) && merged.contains(&w.point) {
            w.face = keep;
        }
    }
    mesh.faces[keep as usize] = merged;
    let others: Vec<u32> = faces.iter().copied().filter(|&f| f != keep).collect();
    remove_faces_and_points(mesh, &others, points)?;
    Ok(keep)
}

/// Removes point `p` and merges the faces around it into one (at a boundary point, the new face
/// closes across the corner the point made). A point of no face is just removed. Returns the
/// merged face, if any, and a note when multi-resolution edits on the merged faces went.
fn dissolve_point(
    mesh: &mut GradientMesh,
    p: u32,
) -> Result<(Option<u32>, Option<String>), String> {
    let count = mesh.points.len();
    if p as usize >= count {
        return Err(format!("there is no point {p} (the layer has {count})"));
    }
    let around = faces_around(mesh, p);
    if around.is_empty() {
        remove_faces_and_points(mesh, &[], &[p])?;
        return Ok((None, None));
    }
    let merged = merged_around(p, &around)?;
    check_merged(&merged, &format!("dissolving point {p}"))?;
    let faces: Vec<u32> = around.iter().map(|a| a.face).collect();
    let note = drop_edits_on(mesh, &faces);
    let face = merge_faces(mesh, &faces, merged, &[p])?;
    Ok((Some(face), note))
}

/// Removes `points` one after another, each merging the faces around it (see the page's
/// "dissolve"); returns the face made last and a note if edits went.
pub fn dissolve_points(
    mesh: &mut GradientMesh,
    points: &[u32],
) -> Result<(Option<u32>, Option<String>), String> {
    if points.is_empty() {
        return Err("select the points to dissolve".into());
    }
    let mut order = points.to_vec();
    // From the highest number down, so the numbers still to do stay the same.
    order.sort_unstable_by(|a, b| b.cmp(a));
    order.dedup();
    let (mut face, mut dropped) = (None, 0);
    for p in order {
        let before = mesh.edits.len();
        face = dissolve_point(mesh, p)?.0;
        dropped += before - mesh.edits.len();
    }
    let note = (dropped > 0).then(|| {
        format!(
            "{dropped} multi-resolution edit{} on the merged faces went with them",
            if dropped == 1 { "" } else { "s" }
        )
    });
    Ok((face, note))
}

/// Removes the edge between `a` and `b` and merges its two faces into one. Returns the merged
/// face and a note when multi-resolution edits on the two faces went.
pub fn dissolve_edge(
    mesh: &mut GradientMesh,
    a: u32,
    b: u32,
) -> Result<(u32, Option<String>), String> {
    let find = |p: u32, q: u32| {
        (mesh.faces.iter().enumerate()).find_map(|(f, c)| {
            let n = c.len();
            (0..n)
                .find(|&i| c[i] == p && c[(i + 1) % n] == q)
                .map(|i| (f as u32, i))
        })
    };
    let (f, g) = match (find(a, b), find(b, a)) {
        (Some(f), Some(g)) if f.0 != g.0 => (f, g),
        (Some(_), Some(_)) => {
            return Err(format!(
                "both sides of the edge {a}–{b} are the same face: it cannot be dissolved"
            ))
        }
        (None, None) => return Err(format!("points {a} and {b} are not joined by an edge")),
        _ => {
            return Err(format!(
                "the edge {a}–{b} is on the boundary: there is no second face to merge (dissolve a point, or delete the face)"
            ))
        }
    };
    // Face f holds a then b; g holds b then a. Around f from b to a, then around g from a to b
    // without its ends.
    let (cf, cg) = (&mesh.faces[f.0 as usize], &mesh.faces[g.0 as usize]);
    let (nf, ng) = (cf.len(), cg.len());
    let mut merged: Vec<u32> = (1..=nf).map(|k| cf[(f.1 + k) % nf]).collect();
    merged.extend((2..ng).map(|k| cg[(g.1 + k) % ng]));
    check_merged(&merged, &format!("dissolving the edge {a}–{b}"))?;
    let note = drop_edits_on(mesh, &[f.0, g.0]);
    mesh.edges.remove(&edge_key(a, b));
    mesh.handles.remove(&(a, b));
    mesh.handles.remove(&(b, a));
    for w in &mut mesh.wedges {
        if w.point == a || w.point == b {
            w.handles.remove(if w.point == a { &b } else { &a });
        }
    }
    let face = merge_faces(mesh, &[f.0, g.0], merged, &[])?;
    Ok((face, note))
}

/// Removes `faces`, the points in `points`, and every point no face uses any more; numbers the
/// rest in order and carries handles, edge tags, sides and multi-resolution edits over to the
/// new numbers. Sides and edits on removed faces are dropped.
pub fn remove_faces_and_points(
    mesh: &mut GradientMesh,
    faces: &[u32],
    points: &[u32],
) -> Result<(), String> {
    let kept_faces: Vec<Vec<u32>> = (mesh.faces.iter().enumerate())
        .filter(|(f, _)| !faces.contains(&(*f as u32)))
        .map(|(_, corners)| corners.clone())
        .collect();
    let mut used = vec![false; mesh.points.len()];
    for corner in kept_faces.iter().flatten() {
        used[*corner as usize] = true;
    }
    for &p in points {
        used[p as usize] = false;
    }
    let mut new_index = vec![u32::MAX; mesh.points.len()];
    let mut next = 0u32;
    for (p, &keep) in used.iter().enumerate() {
        if keep {
            new_index[p] = next;
            next += 1;
        }
    }
    let old_faces: Vec<usize> = (0..mesh.faces.len())
        .filter(|f| !faces.contains(&(*f as u32)))
        .collect();
    let renumber = |p: u32| new_index[p as usize];
    mesh.points = (mesh.points.iter().zip(&used))
        .filter(|(_, &keep)| keep)
        .map(|(p, _)| p.clone())
        .collect();
    mesh.faces = kept_faces
        .into_iter()
        .map(|corners| corners.into_iter().map(renumber).collect())
        .collect();
    let alive = |&(a, b): &(u32, u32)| used[a as usize] && used[b as usize];
    mesh.handles = std::mem::take(&mut mesh.handles)
        .into_iter()
        .filter(|(key, _)| alive(key))
        .map(|((a, b), h)| ((renumber(a), renumber(b)), h))
        .collect();
    mesh.edges = std::mem::take(&mut mesh.edges)
        .into_iter()
        .filter(|(key, _)| alive(key))
        .map(|((a, b), t)| (edge_key(renumber(a), renumber(b)), t))
        .collect();
    mesh.wedges = std::mem::take(&mut mesh.wedges)
        .into_iter()
        .filter_map(|mut w| {
            let face = old_faces.iter().position(|&f| f == w.face as usize)?;
            if !used[w.point as usize] || w.handles.keys().any(|&n| !used[n as usize]) {
                return None;
            }
            w.point = renumber(w.point);
            w.face = face as u32;
            w.handles = w
                .handles
                .into_iter()
                .map(|(n, h)| (renumber(n), h))
                .collect();
            Some(w)
        })
        .collect();
    // An edit names a vertex by a face, one of its corners and a place in that corner's
    // sector: a kept face keeps its corners in order, so only the numbers change.
    mesh.edits = std::mem::take(&mut mesh.edits)
        .into_iter()
        .filter_map(|mut e| {
            let face = old_faces
                .iter()
                .position(|&f| f == e.address.face as usize)?;
            e.address.face = face as u32;
            e.address.point = renumber(e.address.point);
            Some(e)
        })
        .collect();
    Ok(())
}
