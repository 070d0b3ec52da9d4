//! Random valid meshes for property tests: shared by several test modules.

#![allow(dead_code)]

use gradmesh::{ColourSpace, EdgeKind, GradientMesh};
use kurbo::{Affine, Point};
use proptest::prelude::*;

/// A random mesh: a jittered grid whose quads are sometimes split into triangles and
/// sometimes merged with their right-hand neighbour into a hexagon, with random colours,
/// handles, creases and corners.
#[derive(Clone, Debug)]
pub struct MeshSpec {
    pub w: u32,
    pub h: u32,
    pub jitter: Vec<(f64, f64)>,
    pub cell_kind: Vec<u8>,
    pub colours: Vec<[f64; 3]>,
    pub opacity: Vec<f64>,
    pub handle_scale: Vec<(f64, f64)>,
    pub crease: Vec<u8>,
    pub corner: Vec<bool>,
}

pub fn mesh_spec() -> impl Strategy<Value = MeshSpec> {
    (2u32..=5, 2u32..=5).prop_flat_map(|(w, h)| {
        let nv = ((w + 1) * (h + 1)) as usize;
        let nc = (w * h) as usize;
        (
            Just(w),
            Just(h),
            prop::collection::vec((-0.2f64..0.2, -0.2f64..0.2), nv),
            prop::collection::vec(0u8..4, nc),
            prop::collection::vec(
                (0.0f64..100.0, -80.0f64..80.0, -80.0f64..80.0).prop_map(|(a, b, c)| [a, b, c]),
                nv,
            ),
            prop::collection::vec(0.2f64..1.0, nv),
            prop::collection::vec((0.0f64..0.49, -0.3f64..0.3), 4 * nv),
            prop::collection::vec(0u8..6, 4 * nv),
            prop::collection::vec(prop::bool::weighted(0.1), nv),
        )
            .prop_map(
                |(w, h, jitter, cell_kind, colours, opacity, handle_scale, crease, corner)| {
                    MeshSpec {
                        w,
                        h,
                        jitter,
                        cell_kind,
                        colours,
                        opacity,
                        handle_scale,
                        crease,
                        corner,
                    }
                },
            )
    })
}

pub fn build(spec: &MeshSpec) -> GradientMesh {
    let (w, h) = (spec.w, spec.h);
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=h {
        for i in 0..=w {
            let v = (j * (w + 1) + i) as usize;
            let (dx, dy) = spec.jitter[v];
            let p = mesh.add_point(
                Point::new(10.0 * (i as f64 + dx), 10.0 * (j as f64 + dy)),
                spec.colours[v],
            );
            mesh.points[p as usize].opacity = spec.opacity[v];
            mesh.points[p as usize].corner = spec.corner[v];
        }
    }
    let id = |i: u32, j: u32| j * (w + 1) + i;
    for j in 0..h {
        let mut i = 0;
        while i < w {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            match spec.cell_kind[(j * w + i) as usize] {
                // Two triangles.
                0 => {
                    mesh.add_face(vec![a, b, c]);
                    mesh.add_face(vec![a, c, d]);
                }
                // Merge with the next cell into a hexagon.
                1 if i + 1 < w => {
                    let (b2, c2) = (id(i + 2, j), id(i + 2, j + 1));
                    mesh.add_face(vec![a, b, b2, c2, c, d]);
                    i += 1;
                }
                _ => {
                    mesh.add_face(vec![a, b, c, d]);
                }
            }
            i += 1;
        }
    }
    // Handles: a random fraction of the edge, turned a little.
    let mut edges = Vec::new();
    for f in &mesh.faces {
        for k in 0..f.len() {
            edges.push((f[k], f[(k + 1) % f.len()]));
        }
    }
    for (k, &(a, b)) in edges.iter().enumerate() {
        let (s, turn) = spec.handle_scale[k % spec.handle_scale.len()];
        let d = mesh.points[b as usize].position - mesh.points[a as usize].position;
        let handle = Affine::rotate(turn) * Point::new(d.x * s, d.y * s);
        mesh.set_handle(a, b, handle.to_vec2());
        let kind = spec.crease[k % spec.crease.len()];
        if kind == 0 {
            mesh.set_edge(a, b, EdgeKind::Crease, None);
        } else if kind == 1 {
            mesh.set_edge(a, b, EdgeKind::Crease, Some(1.5));
        }
    }
    mesh
}
