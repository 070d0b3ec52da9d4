//! The limit curves of a layer's boundary: its loops of boundary edges and the cubic
//! B-spline segments along them.
//!
//! From level 1 on, boundary edges are infinitely sharp, so the boundary of level `k` is a
//! uniform cubic B-spline of its boundary vertices, broken at corners (a corner's curve ends
//! there with the phantom point `2 C - P`, which reproduces the subdivision rules that keep the
//! corner fixed and put edge points at midpoints). Its limit points are the crease and corner
//! limit stencils, so the curve runs exactly through the limit positions of the boundary.
//! The renderer flattens these segments for coverage (`render::tessellate::outline`); the export
//! writes them as Bézier curves.

use std::collections::HashMap;

use crate::level::Level;
use crate::rules::VertexRule;
use crate::topology::Topology;

/// The boundary loops of `t`: vertex sequences such that each `v[i] -> v[i + 1]` (cyclically)
/// is a boundary edge run in the direction of its face. Deterministic order.
pub(crate) fn boundary_loops(t: &Topology) -> Vec<Vec<u32>> {
    let mut outgoing: HashMap<u32, u32> = HashMap::new();
    let mut starts = Vec::new();
    for e in 0..t.edge_count() {
        if t.is_boundary_edge(e) {
            let [a, b] = t.edge_vertices(e);
            outgoing.insert(a, b);
            starts.push(a);
        }
    }
    let mut loops = Vec::new();
    for &s in &starts {
        if !outgoing.contains_key(&s) {
            continue;
        }
        let mut lp = vec![s];
        let mut v = outgoing.remove(&s).expect("checked");
        while v != s {
            lp.push(v);
            match outgoing.remove(&v) {
                Some(n) => v = n,
                None => break,
            }
        }
        loops.push(lp);
    }
    loops
}

/// Calls `segment(q)` with the four B-spline control points of each cubic segment of the
/// boundary loop `lp` of `level` (whose control positions are `pos(i)` for loop index `i`, taken
/// modulo the loop's length), in order along the loop. Closed loops are periodic B-splines;
/// loops with corners are open spans from corner to corner with phantom points at both ends.
pub(crate) fn for_each_boundary_segment(
    level: &Level,
    lp: &[u32],
    pos: impl Fn(usize) -> [f64; 2],
    mut segment: impl FnMut([[f64; 2]; 4]),
) {
    let m = lp.len();
    if m < 2 {
        return;
    }
    let corners: Vec<usize> = (0..m)
        .filter(|&i| level.vertex_rule(lp[i] as usize) == VertexRule::Corner)
        .collect();
    if corners.is_empty() {
        // A closed periodic B-spline.
        for i in 0..m {
            segment([pos(i + m - 1), pos(i), pos(i + 1), pos(i + 2)]);
        }
        return;
    }
    // Open spans from corner to corner, with phantom points at both ends.
    for (c, &start) in corners.iter().enumerate() {
        let end = if c + 1 < corners.len() {
            corners[c + 1]
        } else {
            corners[0] + m
        };
        let span: Vec<[f64; 2]> = (start..=end).map(&pos).collect();
        let n = span.len() - 1;
        let phantom = |a: [f64; 2], b: [f64; 2]| [2.0 * a[0] - b[0], 2.0 * a[1] - b[1]];
        let at = |i: isize| -> [f64; 2] {
            if i < 0 {
                phantom(span[0], span[1])
            } else if i as usize > n {
                phantom(span[n], span[n - 1])
            } else {
                span[i as usize]
            }
        };
        for i in 0..n as isize {
            segment([at(i - 1), at(i), at(i + 1), at(i + 2)]);
        }
    }
}
