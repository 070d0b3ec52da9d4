//! The special first refinement of the paper (sections 4.2-4.3): a linear ternary split whose
//! new points take their colour from the control point they surround and their position from
//! the handles.
//!
//! A face with `n` corners becomes a central `n`-gon of face points, `n` corner quads and `n`
//! edge quads. Level-1 vertices are numbered: one vertex point per base vertex, two edge points
//! per base edge (the one near `edge_vertices(e)[0]` first), one face point per base corner.

use kurbo::{Point, Vec2};

use crate::catmull_clark::Level;
use crate::topology::Topology;
use crate::validate::{BaseMesh, VertexData};

/// Index of the vertex point of base vertex `v`.
pub fn vertex_point(v: u32) -> u32 {
    v
}

/// Index of the edge point of base edge `e` near its end vertex `end` (0 or 1).
pub fn edge_point(base: &Topology, e: u32, end: usize) -> u32 {
    (base.vertex_count() + 2 * e as usize + end) as u32
}

/// Index of the face point at flat corner `corner` of the base topology.
pub fn face_point(base: &Topology, corner: usize) -> u32 {
    (base.vertex_count() + 2 * base.edge_count() + corner) as u32
}

/// Which end of edge `e` vertex `v` is.
fn end_of(base: &Topology, e: u32, v: u32) -> usize {
    usize::from(base.edge_vertices(e as usize)[0] != v)
}

/// Index of the first level-1 face made from base face `f`: its central face; the corner
/// quads follow, then the edge quads.
pub fn first_child_face(base: &Topology, f: usize) -> usize {
    f + 2 * base.face_offset(f)
}

/// The level-1 topology and sharpness of `base`.
pub fn ternary_level(base: &BaseMesh) -> Level {
    let t = &base.topology;
    let nv1 = t.vertex_count() + 2 * t.edge_count() + t.corner_count();
    let mut offsets = Vec::with_capacity(t.face_count() + 2 * t.corner_count() + 1);
    let mut verts = Vec::with_capacity(9 * t.corner_count());
    offsets.push(0u32);
    for f in 0..t.face_count() {
        let fv = t.face_vertices(f);
        let fe = t.face_edges(f);
        let o = t.face_offset(f);
        let n = fv.len();
        let ep = |i: usize, v: u32| edge_point(t, fe[i], end_of(t, fe[i], v));
        verts.extend((0..n).map(|i| face_point(t, o + i)));
        offsets.push(verts.len() as u32);
        for i in 0..n {
            let prev = (i + n - 1) % n;
            verts.extend_from_slice(&[
                vertex_point(fv[i]),
                ep(i, fv[i]),
                face_point(t, o + i),
                ep(prev, fv[i]),
            ]);
            offsets.push(verts.len() as u32);
        }
        for i in 0..n {
            let next = (i + 1) % n;
            verts.extend_from_slice(&[
                ep(i, fv[i]),
                ep(i, fv[next]),
                face_point(t, o + next),
                face_point(t, o + i),
            ]);
            offsets.push(verts.len() as u32);
        }
    }
    let topology =
        Topology::build(nv1, offsets, verts, |_, _| false).expect("the ternary split is manifold");

    // The three level-1 edges along a base edge inherit its sharpness.
    let mut edge_sharpness = vec![0.0; topology.edge_count()];
    for f in 0..t.face_count() {
        let fe = t.face_edges(f);
        let n = fe.len();
        let first = first_child_face(t, f);
        for i in 0..n {
            let s = base.edge_sharpness[fe[i] as usize];
            let corner_quad = topology.face_edges(first + 1 + i);
            let edge_quad = topology.face_edges(first + 1 + n + i);
            let next_corner_quad = topology.face_edges(first + 1 + (i + 1) % n);
            edge_sharpness[corner_quad[0] as usize] = s;
            edge_sharpness[edge_quad[0] as usize] = s;
            edge_sharpness[next_corner_quad[3] as usize] = s;
        }
    }
    let mut vertex_sharpness = vec![0.0; nv1];
    vertex_sharpness[..t.vertex_count()].copy_from_slice(&base.vertex_sharpness);
    Level::new(
        topology,
        edge_sharpness,
        vertex_sharpness,
        base.creasing,
        base.boundary,
    )
}

/// The position of the face point at corner `V0` of a face (the bilinear rule of section 4.3,
/// with the weights as corrected in the paper notes):
/// `F = V0 + (1 - d2) D1 + (1 - d1) D2 + d1 d2 (C - V0)`, with `d = 2 |D| / |edge|`.
///
/// `D1` is the handle along the edge to the next corner `V1`, `D2` along the edge to the
/// previous corner `V2`, and `C` the centroid of the face.
pub fn face_point_position(v0: Point, v1: Point, v2: Point, d1: Vec2, d2: Vec2, c: Point) -> Point {
    let w1 = 2.0 * d1.hypot() / (v1 - v0).hypot();
    let w2 = 2.0 * d2.hypot() / (v2 - v0).hypot();
    v0 + d1 * (1.0 - w2) + d2 * (1.0 - w1) + (c - v0) * (w1 * w2)
}

/// The level-1 data of `base`: positions from the handles, colours copied from the control
/// point each new point surrounds.
pub fn ternary_data(base: &BaseMesh) -> Vec<VertexData> {
    let t = &base.topology;
    let mut out = vec![[0.0; 6]; t.vertex_count() + 2 * t.edge_count() + t.corner_count()];
    let pos = |v: u32| {
        let d = &base.data[v as usize];
        Point::new(d[0], d[1])
    };
    let with_position = |v: u32, p: Point| {
        let mut d = base.data[v as usize];
        d[0] = p.x;
        d[1] = p.y;
        d
    };
    out[..t.vertex_count()].copy_from_slice(&base.data);
    for e in 0..t.edge_count() {
        let ends = t.edge_vertices(e);
        for (end, &v) in ends.iter().enumerate() {
            let h = base.edge_handles[e][end];
            out[edge_point(t, e as u32, end) as usize] = with_position(v, pos(v) + h);
        }
    }
    let handle = |e: u32, v: u32| base.edge_handles[e as usize][end_of(t, e, v)];
    for f in 0..t.face_count() {
        let fv = t.face_vertices(f);
        let fe = t.face_edges(f);
        let n = fv.len();
        let centroid = fv.iter().fold(Vec2::ZERO, |acc, &v| acc + pos(v).to_vec2()) / n as f64;
        let c = centroid.to_point();
        for i in 0..n {
            let (next, prev) = ((i + 1) % n, (i + n - 1) % n);
            let p = face_point_position(
                pos(fv[i]),
                pos(fv[next]),
                pos(fv[prev]),
                handle(fe[i], fv[i]),
                handle(fe[prev], fv[i]),
                c,
            );
            out[face_point(t, t.face_offset(f) + i) as usize] = with_position(fv[i], p);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallelogram_face_point_is_the_tensor_corner() {
        let v0 = Point::new(1.0, 2.0);
        let (e1, e2) = (Vec2::new(3.0, 0.5), Vec2::new(0.7, 2.0));
        let c = v0 + (e1 + e2) * 0.5;
        for (a, b) in [(0.1, 0.3), (0.33, 0.25), (0.5, 0.05), (0.0, 0.2)] {
            let (d1, d2) = (e1 * a, e2 * b);
            let f = face_point_position(v0, v0 + e1, v0 + e2, d1, d2, c);
            let expect = v0 + d1 + d2;
            assert!((f - expect).hypot() < 1e-12, "{f:?} vs {expect:?}");
        }
    }

    #[test]
    fn default_handles_split_a_square_in_thirds() {
        let v0 = Point::ZERO;
        let f = face_point_position(
            v0,
            Point::new(3.0, 0.0),
            Point::new(0.0, 3.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 1.0),
            Point::new(1.5, 1.5),
        );
        assert!((f - Point::new(1.0, 1.0)).hypot() < 1e-12);
    }

    #[test]
    fn zero_handles_give_no_nan() {
        let f = face_point_position(
            Point::ZERO,
            Point::new(1.0, 0.0),
            Point::new(0.0, 1.0),
            Vec2::ZERO,
            Vec2::ZERO,
            Point::new(0.3, 0.3),
        );
        assert_eq!(f, Point::ZERO);
    }
}
