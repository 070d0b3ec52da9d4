//! Finding where the limit surface folds over itself.
//!
//! A fold (for example from a handle longer than half its edge, the paper's Figure 9) turns part
//! of the surface over: there the map from the mesh to the plane reverses orientation, and the
//! refined quads, whose corners are limit points, run the other way round from the rest. The
//! renderer draws folded parts in face order (later faces on top), which is deterministic but
//! rarely what the artist meant, so `gradmesh info` warns about them.

use kurbo::{Point, Rect};

use crate::error::Error;
use crate::mesh::GradientMesh;
use crate::refine::{RefinedData, Refinement};
use crate::ternary_step::first_child_face;
use crate::topology::{Topology, INVALID};

/// The level [`find_folds`] inspects: quads of a ninth of a control face's side, halved twice.
pub const FOLD_LEVEL: usize = 4;

/// One connected region where the surface runs against the orientation of the rest.
#[derive(Clone, Debug, PartialEq)]
pub struct Fold {
    /// The control faces (of the layer's mesh) the region lies in, ascending.
    pub faces: Vec<usize>,
    /// The area-weighted centre of the reversed triangles.
    pub position: Point,
    /// The area of the reversed triangles, in plane units.
    pub area: f64,
    /// The bounding box of the reversed triangles.
    pub bounds: Rect,
}

/// The folds of a mesh's limit surface, looked for at level [`FOLD_LEVEL`]. Fails only if the
/// mesh is invalid.
pub fn find_folds(mesh: &GradientMesh) -> Result<Vec<Fold>, Error> {
    let (mut refinement, _) = Refinement::new(mesh, FOLD_LEVEL)?;
    let data = refinement.evaluate();
    Ok(find_folds_at(&mut refinement, &data, FOLD_LEVEL))
}

/// The face of `t` that holds flat corner `c`.
fn face_of_corner(t: &Topology, c: usize) -> usize {
    let (mut lo, mut hi) = (0, t.face_count());
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if t.face_offset(mid) <= c {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The control face that face `f` of level `k` comes from.
fn base_face(refinement: &Refinement, k: usize, f: usize) -> usize {
    let mut f = f;
    // Face c of level j + 1 is the quad at corner c of level j.
    for j in (1..k).rev() {
        f = face_of_corner(refinement.topology(j), f);
    }
    if k == 0 {
        return f;
    }
    // Level-1 faces of base face g start at first_child_face(g).
    let base = refinement.topology(0);
    let (mut lo, mut hi) = (0, base.face_count());
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if first_child_face(base, mid) <= f {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The folds of the limit surface seen at level `level` (at least 2) of a refinement whose data
/// is `data`: quads (split along their first diagonal) whose limit corners turn against the
/// orientation of most of the surface, grouped into regions joined by edges.
pub fn find_folds_at(refinement: &mut Refinement, data: &RefinedData, level: usize) -> Vec<Fold> {
    let k = level.max(2);
    refinement.extend_to(k);
    let lim = refinement.limit(data, k);
    let t = refinement.topology(k);
    let nf = t.face_count();
    let p = |v: u32| lim[v as usize].point();
    let signed = |a: Point, b: Point, c: Point| 0.5 * (b - a).cross(c - a);
    let mut areas = Vec::with_capacity(nf);
    let mut total = 0.0;
    for f in 0..nf {
        let fv = t.face_vertices(f);
        let tris: Vec<[Point; 3]> = (1..fv.len() - 1)
            .map(|i| [p(fv[0]), p(fv[i]), p(fv[i + 1])])
            .collect();
        let a: Vec<f64> = tris.iter().map(|t| signed(t[0], t[1], t[2])).collect();
        total += a.iter().sum::<f64>();
        areas.push((tris, a));
    }
    let orientation = if total < 0.0 { -1.0 } else { 1.0 };
    // Reversed triangles smaller than this are round-off on degenerate quads, not folds.
    let eps = 1e-12 * total.abs();
    let reversed: Vec<bool> = areas
        .iter()
        .map(|(_, a)| a.iter().any(|&x| x * orientation < -eps))
        .collect();

    // Connected regions of reversed quads (union-find over shared edges).
    let mut parent: Vec<usize> = (0..nf).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for e in 0..t.edge_count() {
        let [f0, f1] = t.edge_faces(e);
        if f1 == INVALID || !reversed[f0 as usize] || !reversed[f1 as usize] {
            continue;
        }
        let (a, b) = (
            find(&mut parent, f0 as usize),
            find(&mut parent, f1 as usize),
        );
        if a != b {
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut folds: Vec<(usize, Fold, Point)> = Vec::new();
    let mut index_of_root = std::collections::HashMap::new();
    for f in 0..nf {
        if !reversed[f] {
            continue;
        }
        let root = find(&mut parent, f);
        let i = *index_of_root.entry(root).or_insert_with(|| {
            folds.push((
                root,
                Fold {
                    faces: Vec::new(),
                    position: Point::ZERO,
                    area: 0.0,
                    bounds: Rect::new(
                        f64::INFINITY,
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                        f64::NEG_INFINITY,
                    ),
                },
                Point::ZERO,
            ));
            folds.len() - 1
        });
        let (_, fold, moment) = &mut folds[i];
        let bf = base_face(refinement, k, f);
        if !fold.faces.contains(&bf) {
            fold.faces.push(bf);
        }
        let (tris, a) = &areas[f];
        for (tri, &area) in tris.iter().zip(a) {
            if area * orientation >= -eps {
                continue;
            }
            let w = area.abs();
            let c = ((tri[0].to_vec2() + tri[1].to_vec2() + tri[2].to_vec2()) / 3.0).to_point();
            fold.area += w;
            *moment = (moment.to_vec2() + c.to_vec2() * w).to_point();
            for q in tri {
                fold.bounds = fold.bounds.union_pt(*q);
            }
        }
    }
    folds
        .into_iter()
        .map(|(_, mut fold, moment)| {
            fold.faces.sort_unstable();
            if fold.area > 0.0 {
                fold.position = (moment.to_vec2() / fold.area).to_point();
            }
            fold
        })
        .collect()
}
