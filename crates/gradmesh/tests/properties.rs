//! Property tests of the paper's conditions on random valid meshes of mixed face sizes.

use gradmesh::refine::{RefinedMesh, Refinement};
use gradmesh::{ColourSpace, EdgeKind, GradientMesh};
use kurbo::{Affine, Point, Vec2};
use proptest::prelude::*;

/// A random mesh: a jittered grid whose quads are sometimes split into triangles and
/// sometimes merged with their right-hand neighbour into a hexagon, with random colours,
/// handles, creases and corners.
#[derive(Clone, Debug)]
struct MeshSpec {
    w: u32,
    h: u32,
    jitter: Vec<(f64, f64)>,
    cell_kind: Vec<u8>,
    colours: Vec<[f64; 3]>,
    opacity: Vec<f64>,
    handle_scale: Vec<(f64, f64)>,
    crease: Vec<u8>,
    corner: Vec<bool>,
}

fn mesh_spec() -> impl Strategy<Value = MeshSpec> {
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

fn build(spec: &MeshSpec) -> GradientMesh {
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

/// Index of control point `p`'s vertex at every level `0..=depth`.
fn vertex_chain(r: &Refinement, p: u32, depth: usize) -> Vec<usize> {
    let mut out = vec![p as usize, p as usize];
    for k in 1..depth {
        let t = r.topology(k);
        let next = t.face_count() + t.edge_count() + out[k];
        out.push(next);
    }
    out
}

fn colour_bounds(mesh: &GradientMesh) -> ([f64; 4], [f64; 4]) {
    let mut lo = [f64::INFINITY; 4];
    let mut hi = [f64::NEG_INFINITY; 4];
    for p in &mesh.points {
        for c in 0..3 {
            lo[c] = lo[c].min(p.colour[c]);
            hi[c] = hi[c].max(p.colour[c]);
        }
        lo[3] = lo[3].min(p.opacity);
        hi[3] = hi[3].max(p.opacity);
    }
    (lo, hi)
}

fn refine(mesh: &GradientMesh, depth: usize) -> (Refinement, RefinedMesh) {
    let (r, _) = Refinement::new(mesh, depth).expect("a valid mesh");
    let data = r.evaluate();
    (r, data)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, .. ProptestConfig::default() })]

    /// Condition 1: the colour of every control point is the colour of its vertex at every
    /// level and in the limit.
    #[test]
    fn condition_1_colours_are_interpolated(spec in mesh_spec()) {
        let mesh = build(&spec);
        let depth = 3;
        let (mut r, data) = refine(&mesh, depth);
        let limit = r.limit(&data, depth);
        for (p, point) in mesh.points.iter().enumerate() {
            let chain = vertex_chain(&r, p as u32, depth);
            for (k, &v) in chain.iter().enumerate() {
                for c in 0..3 {
                    let got = data.levels[k][v][2 + c];
                    prop_assert!((got - point.colour[c]).abs() < 1e-9,
                        "point {p} level {k} channel {c}: {got} vs {}", point.colour[c]);
                }
            }
            let v = chain[depth];
            for c in 0..3 {
                prop_assert!((limit[v][2 + c] - point.colour[c]).abs() < 1e-9);
            }
            prop_assert!((limit[v][5] - point.opacity).abs() < 1e-9);
        }
    }

    /// Condition 2: every refined and limit colour lies within the per-channel bounds of the
    /// control colours (Catmull-Clark weights are a convex combination).
    #[test]
    fn condition_2_colours_stay_in_the_hull(spec in mesh_spec()) {
        let mesh = build(&spec);
        let (lo, hi) = colour_bounds(&mesh);
        let (mut r, data) = refine(&mesh, 3);
        let limit = r.limit(&data, 3);
        for (k, level) in data.levels.iter().chain(std::iter::once(&limit)).enumerate() {
            for d in level {
                for c in 0..4 {
                    let x = d[2 + c];
                    prop_assert!(x >= lo[c] - 1e-9 && x <= hi[c] + 1e-9,
                        "level {k} channel {c}: {x} outside {}..{}", lo[c], hi[c]);
                }
            }
        }
    }

    /// Positions commute with similarity transforms of the whole mesh (handles included), and
    /// with any affine map when the handles lie along their edges.
    #[test]
    fn positions_are_affine_invariant(
        spec in mesh_spec(),
        angle in -3.0f64..3.0,
        scale in 0.1f64..10.0,
        shear in -0.8f64..0.8,
        tx in -100.0f64..100.0,
    ) {
        let mesh = build(&spec);
        let check = |mesh: &GradientMesh, a: Affine| -> Result<(), TestCaseError> {
            let mut moved = mesh.clone();
            for p in &mut moved.points {
                p.position = a * p.position;
            }
            let linear = Affine::new({
                let c = a.as_coeffs();
                [c[0], c[1], c[2], c[3], 0.0, 0.0]
            });
            for h in moved.handles.values_mut() {
                *h = (linear * h.to_point()).to_vec2();
            }
            let (_, d0) = refine(mesh, 3);
            let (_, d1) = refine(&moved, 3);
            for k in 0..=3 {
                for (p, q) in d0.levels[k].iter().zip(&d1.levels[k]) {
                    let expect = a * Point::new(p[0], p[1]);
                    let err = (expect - Point::new(q[0], q[1])).hypot();
                    prop_assert!(err < 1e-7 * (1.0 + expect.to_vec2().hypot()),
                        "level {k}: {expect:?} vs {q:?}");
                }
            }
            Ok(())
        };
        check(&mesh, Affine::translate(Vec2::new(tx, -tx)) * Affine::rotate(angle) * Affine::scale(scale))?;
        let mut along = mesh.clone();
        along.handles.clear();
        check(&along, Affine::new([scale, shear, 0.3, 1.0, tx, 2.0]))?;
    }
}
