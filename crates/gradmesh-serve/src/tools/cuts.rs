//! Tools that add points to a mesh: a point on an edge, the loop cut, a point inside a face.

use std::collections::HashMap;

use gradmesh::GradientMesh;
use kurbo::{ParamCurve, Point};

use super::{colours_at, drop_edits_on, edge_curve, edge_key, move_wedges, Selection, ToolResult};

/// Adds a point on the edge from `a` to `b` at `t` along its curve (0 at `a`, 1 at `b`), in every
/// face along the edge, coloured `colour` with `opacity`. The handles split so the curve stays
/// the same, and the edge's tag goes to both halves. Returns the new point.
pub fn insert_point_on_edge(
    mesh: &mut GradientMesh,
    a: u32,
    b: u32,
    t: f64,
    colour: [f64; 3],
    opacity: f64,
) -> u32 {
    let curve = edge_curve(mesh, a, b);
    let (first, second) = (curve.subsegment(0.0..t), curve.subsegment(t..1.0));
    let m = mesh.add_point(curve.eval(t), colour);
    mesh.points[m as usize].opacity = opacity;
    for face in &mut mesh.faces {
        let n = face.len();
        if let Some(i) = (0..n).find(|&i| {
            let (p, q) = (face[i], face[(i + 1) % n]);
            (p, q) == (a, b) || (p, q) == (b, a)
        }) {
            face.insert(i + 1, m);
        }
    }
    let tag = mesh.edge_tag(a, b);
    mesh.edges.remove(&edge_key(a, b));
    mesh.handles.remove(&(a, b));
    mesh.handles.remove(&(b, a));
    mesh.set_handle(a, m, first.p1 - first.p0);
    mesh.set_handle(m, a, first.p2 - first.p3);
    mesh.set_handle(m, b, second.p1 - second.p0);
    mesh.set_handle(b, m, second.p2 - second.p3);
    mesh.set_edge(a, m, tag.kind, tag.sharpness);
    mesh.set_edge(m, b, tag.kind, tag.sharpness);
    // A side's own handle along the edge now points to the new point.
    for w in &mut mesh.wedges {
        let other = if w.point == a { b } else { a };
        if (w.point == a || w.point == b) && w.handles.contains_key(&other) {
            let h = w.handles.remove(&other).expect("checked");
            w.handles.insert(m, h);
        }
    }
    m
}

/// Where a directed edge lies: its face and the index of its first corner there.
fn directed_edges(mesh: &GradientMesh) -> HashMap<(u32, u32), (u32, usize)> {
    let mut found = HashMap::new();
    for (f, corners) in mesh.faces.iter().enumerate() {
        let n = corners.len();
        for i in 0..n {
            found.insert((corners[i], corners[(i + 1) % n]), (f as u32, i));
        }
    }
    found
}

/// The edges a loop cut crosses (each with the place of its new point, `t` from its first end)
/// and the quads it splits (each with the index of the corner where the cut enters).
#[derive(Default)]
struct Strip {
    edges: Vec<(u32, u32, f64)>,
    quads: Vec<(u32, usize)>,
}

impl Strip {
    /// Adds the edge from `p` to `q` at `t`; false if the strip has it already (a closed loop).
    fn add_edge(&mut self, p: u32, q: u32, t: f64) -> bool {
        let key = edge_key(p, q);
        if self.edges.iter().any(|&(a, b, _)| edge_key(a, b) == key) {
            return false;
        }
        self.edges.push((p, q, t));
        true
    }

    /// Follows the strip from face `f`, entered through its edge at corner `i` with the new point
    /// `s` along it, across each quad to the opposite edge, until a face that is not a quad, the
    /// boundary, or the start again.
    fn walk(
        &mut self,
        mesh: &GradientMesh,
        edges: &HashMap<(u32, u32), (u32, usize)>,
        start: (u32, usize),
        s: f64,
    ) {
        let (mut f, mut i) = start;
        loop {
            let c = &mesh.faces[f as usize];
            if c.len() != 4 || self.quads.iter().any(|&(g, _)| g == f) {
                return;
            }
            self.quads.push((f, i));
            // The opposite edge runs against the entry: its point is at 1 - s from its first
            // end, at s from the other.
            let (p, q) = (c[(i + 2) % 4], c[(i + 3) % 4]);
            if !self.add_edge(p, q, 1.0 - s) {
                return;
            }
            match edges.get(&(q, p)) {
                Some(&next) => (f, i) = next,
                None => return,
            }
        }
    }
}

/// Inserts a line of points across the strip of quads that holds the edge from `a` to `b`, at
/// `t` along the edge (0 at `a`, 1 at `b`) and at the same place along each edge the strip
/// crosses, and splits each quad of the strip in two. The strip ends at the boundary, at a
/// face that is not a quad (which gets the new point on its side), or where it closes on itself.
/// New points take the surface's colour where they are. Selects the new points in order.
pub fn loop_cut(mesh: &mut GradientMesh, a: u32, b: u32, t: f64) -> Result<ToolResult, String> {
    if !(t.is_finite() && t > 0.0 && t < 1.0) {
        return Err(format!(
            "the cut's place along the edge must be between 0 and 1 (not {t})"
        ));
    }
    let edges = directed_edges(mesh);
    let (forward, backward) = (edges.get(&(a, b)).copied(), edges.get(&(b, a)).copied());
    if forward.is_none() && backward.is_none() {
        return Err(format!("points {a} and {b} are not joined by an edge"));
    }
    let mut strip = Strip::default();
    strip.add_edge(a, b, t);
    if let Some(start) = forward {
        strip.walk(mesh, &edges, start, t);
    }
    if let Some(start) = backward {
        strip.walk(mesh, &edges, start, 1.0 - t);
    }
    let positions: Vec<Point> = (strip.edges.iter())
        .map(|&(p, q, s)| edge_curve(mesh, p, q).eval(s))
        .collect();
    let colours = colours_at(mesh, &positions, |k| {
        let (p, q, s) = strip.edges[k];
        let (cp, cq) = (&mesh.points[p as usize], &mesh.points[q as usize]);
        let colour = [0, 1, 2].map(|i| cp.colour[i] + (cq.colour[i] - cp.colour[i]) * s);
        (colour, cp.opacity + (cq.opacity - cp.opacity) * s)
    });
    let mut changed: Vec<u32> = Vec::new();
    for (f, corners) in mesh.faces.iter().enumerate() {
        let n = corners.len();
        let touched = (0..n).any(|i| {
            let key = edge_key(corners[i], corners[(i + 1) % n]);
            strip.edges.iter().any(|&(p, q, _)| edge_key(p, q) == key)
        });
        if touched {
            changed.push(f as u32);
        }
    }
    let note = drop_edits_on(mesh, &changed);
    let quads: Vec<(u32, [u32; 4])> = (strip.quads.iter())
        .map(|&(f, i)| {
            let c = &mesh.faces[f as usize];
            (f, [0, 1, 2, 3].map(|k| c[(i + k) % 4]))
        })
        .collect();
    let mut new_points = HashMap::new();
    for (&(p, q, s), &(colour, opacity)) in strip.edges.iter().zip(&colours) {
        new_points.insert(
            edge_key(p, q),
            insert_point_on_edge(mesh, p, q, s, colour, opacity),
        );
    }
    for (f, corners) in quads {
        split_cut_quad(mesh, f, corners, &new_points);
    }
    let points = (strip.edges.iter())
        .map(|&(p, q, _)| new_points[&edge_key(p, q)])
        .collect();
    Ok(ToolResult {
        selection: Selection {
            layer: 0,
            points,
            face: None,
        },
        note,
    })
}

/// Splits quad `f`, whose corners before the cut were `corners` (starting where the cut
/// entered), between the new points of its first and third sides.
fn split_cut_quad(
    mesh: &mut GradientMesh,
    f: u32,
    corners: [u32; 4],
    new_points: &HashMap<(u32, u32), u32>,
) {
    let [c0, c1, c2, c3] = corners;
    let (m01, m23) = (new_points[&edge_key(c0, c1)], new_points[&edge_key(c2, c3)]);
    let now = &mesh.faces[f as usize];
    let n = now.len();
    let start = now.iter().position(|&c| c == c0).expect("a corner stays");
    let ring: Vec<u32> = (0..n).map(|k| now[(start + k) % n]).collect();
    let at = |m: u32| ring.iter().position(|&x| x == m).expect("on the face");
    let (i01, i23) = (at(m01), at(m23));
    let first: Vec<u32> = (0..=i01).chain(i23..n).map(|k| ring[k]).collect();
    let second: Vec<u32> = (i01..=i23).map(|k| ring[k]).collect();
    mesh.faces[f as usize] = first;
    let g = mesh.add_face(second);
    move_wedges(mesh, f, &[g]);
}

/// Adds a point at `(x, y)` inside face `face` and joins it to every corner: the face becomes as
/// many triangles as it had sides (the first keeps the face's number). The point takes the
/// surface's colour there. Selects the new point.
pub fn add_point_in_face(
    mesh: &mut GradientMesh,
    face: u32,
    at: Point,
) -> Result<ToolResult, String> {
    let corners = mesh
        .faces
        .get(face as usize)
        .ok_or_else(|| format!("there is no face {face}"))?
        .clone();
    if !(at.x.is_finite() && at.y.is_finite()) {
        return Err("the point's position must be finite numbers".into());
    }
    if !inside_face(mesh, &corners, at) {
        return Err(format!(
            "({:.2}, {:.2}) is not inside face {face}: click inside the face",
            at.x, at.y
        ));
    }
    let n = corners.len() as f64;
    let [(colour, opacity)] = colours_at(mesh, &[at], |_| {
        let mean = |f: &dyn Fn(&gradmesh::ControlPoint) -> f64| {
            corners
                .iter()
                .map(|&c| f(&mesh.points[c as usize]))
                .sum::<f64>()
                / n
        };
        (
            [0, 1, 2].map(|i| mean(&|p| p.colour[i])),
            mean(&|p| p.opacity),
        )
    })
    .try_into()
    .expect("one position");
    let note = drop_edits_on(mesh, &[face]);
    let m = mesh.add_point(at, colour);
    mesh.points[m as usize].opacity = opacity;
    let k = corners.len();
    let mut triangles = Vec::with_capacity(k);
    for i in 0..k {
        let triangle = vec![corners[i], corners[(i + 1) % k], m];
        if i == 0 {
            mesh.faces[face as usize] = triangle;
            triangles.push(face);
        } else {
            triangles.push(mesh.add_face(triangle));
        }
    }
    move_wedges(mesh, face, &triangles);
    Ok(ToolResult {
        selection: Selection {
            layer: 0,
            points: vec![m],
            face: None,
        },
        note,
    })
}

/// Whether `at` lies inside the face's outline (its edge curves, flattened).
fn inside_face(mesh: &GradientMesh, corners: &[u32], at: Point) -> bool {
    let n = corners.len();
    let mut outline = Vec::with_capacity(8 * n);
    for i in 0..n {
        let curve = edge_curve(mesh, corners[i], corners[(i + 1) % n]);
        outline.extend((0..8).map(|k| curve.eval(f64::from(k) / 8.0)));
    }
    let mut inside = false;
    let m = outline.len();
    for i in 0..m {
        let (p, q) = (outline[i], outline[(i + m - 1) % m]);
        if (p.y > at.y) != (q.y > at.y) && at.x < (q.x - p.x) * (at.y - p.y) / (q.y - p.y) + p.x {
            inside = !inside;
        }
    }
    inside
}
