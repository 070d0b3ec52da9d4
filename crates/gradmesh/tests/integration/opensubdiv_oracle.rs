//! Catmull-Clark refinement and limit points against `opensubdiv-rs` (a port of OpenSubdiv).
//!
//! Plain Catmull-Clark (no ternary step) on random meshes with triangles, quads and hexagons,
//! infinitely sharp and semi-sharp creases, corners, and both boundary interpolations. The
//! oracle's weights are f32, so values are compared at 1e-5 relative; vertices are matched by
//! position since the two number them differently. Not compared: Chaikin creasing and interior
//! valence-2 vertices, where the port is known to differ from OpenSubdiv, and the limit points
//! of darts: OpenSubdiv gives a dart the smooth limit mask, which is not the limit (it changes
//! when computed one level deeper; `limit::tests::dart_mask_is_the_limit_of_refinement`), and
//! gradmesh uses the exact mask.

use crate::common::{build, mesh_spec};
use gradmesh::internals::catmull_clark::{self, Level};
use gradmesh::internals::limit::limit_stencils;
use gradmesh::internals::rules::VertexRule;
use gradmesh::SHARPNESS_INFINITE;
use gradmesh::{BaseMesh, VertexData};
use gradmesh::{BoundaryInterpolation, GradientMesh};
use opensubdiv_rs::far::{
    PrimvarRefiner, TopologyDescriptor, TopologyRefinerFactory, UniformOptions,
};
use opensubdiv_rs::sdc;
use proptest::prelude::*;

const DEPTH: usize = 3;

/// Ours: levels 0..=DEPTH and the limit of the last level, without its darts.
fn ours(mesh: &GradientMesh) -> (Vec<Vec<VertexData>>, Vec<VertexData>) {
    let (base, _) = BaseMesh::new(mesh).unwrap();
    let mut level = Level::from_base(&base);
    let mut data = vec![base.data.clone()];
    for _ in 0..DEPTH {
        let (child, stencils) = catmull_clark::refine(&level);
        data.push(stencils.apply(data.last().unwrap()));
        level = child;
    }
    let limit = limit_stencils(&level).unwrap().apply(data.last().unwrap());
    let not_darts = (0..limit.len())
        .filter(|&v| level.vertex_rule(v) != VertexRule::Dart)
        .map(|v| limit[v])
        .collect();
    (data, not_darts)
}

/// The oracle's levels 0..=DEPTH and the limit of the last level.
fn oracle(mesh: &GradientMesh) -> (Vec<Vec<VertexData>>, Vec<VertexData>) {
    let sizes: Vec<usize> = mesh.faces.iter().map(Vec::len).collect();
    let verts: Vec<u32> = mesh.faces.iter().flatten().copied().collect();
    let mut pairs = Vec::new();
    let mut weights = Vec::new();
    for (&(a, b), tag) in &mesh.edges {
        pairs.push([a, b]);
        weights.push(tag.effective_sharpness() as f32);
    }
    let corners: Vec<u32> = (0..mesh.points.len() as u32)
        .filter(|&v| mesh.points[v as usize].corner)
        .collect();
    let corner_weights = vec![SHARPNESS_INFINITE as f32; corners.len()];
    let descriptor = TopologyDescriptor::new(mesh.points.len(), &sizes, &verts)
        .with_creases(&pairs, &weights)
        .with_corners(&corners, &corner_weights);
    let boundary = match mesh.boundary {
        BoundaryInterpolation::EdgeAndCorner => sdc::VtxBoundaryInterpolation::EdgeAndCorner,
        BoundaryInterpolation::EdgeOnly => sdc::VtxBoundaryInterpolation::EdgeOnly,
    };
    let mut refiner = TopologyRefinerFactory::create(
        descriptor,
        sdc::SchemeType::Catmark,
        sdc::Options::default().with_vtx_boundary_interpolation(boundary),
    )
    .expect("valid topology");
    refiner.refine_uniform(UniformOptions::new(DEPTH));
    let primvars = PrimvarRefiner::new(&refiner);
    let base: Vec<[f64; 6]> = mesh
        .points
        .iter()
        .map(|p| {
            [
                p.position.x,
                p.position.y,
                p.colour[0],
                p.colour[1],
                p.colour[2],
                p.opacity,
            ]
        })
        .collect();
    let mut data = vec![base];
    for level in 1..=DEPTH {
        let mut next = vec![[0.0; 6]; refiner.level(level).num_vertices()];
        primvars.interpolate(level, data.last().unwrap(), &mut next);
        data.push(next);
    }
    let mut limit = vec![[0.0; 6]; data[DEPTH].len()];
    primvars.limit(&data[DEPTH], &mut limit);
    let structs = |l: Vec<[f64; 6]>| l.into_iter().map(VertexData::from_array).collect();
    (data.into_iter().map(structs).collect(), structs(limit))
}

/// Checks that every vertex of `a` has a vertex of `b` at the same position with the same
/// data, at 1e-5 relative to the size of the values.
fn same_points(a: &[VertexData], b: &[VertexData], what: &str) -> Result<(), TestCaseError> {
    prop_assert!(a.len() <= b.len(), "{}: vertex count", what);
    let mut order: Vec<usize> = (0..b.len()).collect();
    order.sort_by(|&i, &j| b[i].position[0].total_cmp(&b[j].position[0]));
    let xs: Vec<f64> = order.iter().map(|&i| b[i].position[0]).collect();
    let tol = |x: f64| 1e-5 * x.abs().max(100.0);
    for p in a {
        let start = xs.partition_point(|&x| x < p.position[0] - tol(p.position[0]));
        let found = order[start..]
            .iter()
            .take_while(|&&i| b[i].position[0] <= p.position[0] + tol(p.position[0]))
            .any(|&i| {
                let (q, p) = (b[i].to_array(), p.to_array());
                (0..6).all(|c| (q[c] - p[c]).abs() <= tol(p[c]))
            });
        prop_assert!(found, "{}: no match for {:?}", what, p);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, .. ProptestConfig::default() })]

    #[test]
    fn catmull_clark_matches_opensubdiv(spec in mesh_spec(), edge_only in any::<bool>()) {
        let mut mesh = build(&spec);
        if edge_only {
            mesh.boundary = BoundaryInterpolation::EdgeOnly;
        }
        // Add semi-sharp creases of several sharpness values.
        let keys: Vec<(u32, u32)> = mesh.edges.keys().copied().collect();
        for (k, key) in keys.iter().enumerate() {
            if let Some(tag) = mesh.edges.get_mut(key) {
                tag.sharpness = match k % 4 {
                    0 => None,
                    1 => Some(0.5),
                    2 => Some(1.5),
                    _ => Some(2.25),
                };
            }
        }
        let (a, la) = ours(&mesh);
        let (b, lb) = oracle(&mesh);
        for k in 1..=DEPTH {
            prop_assert_eq!(a[k].len(), b[k].len());
            same_points(&a[k], &b[k], &format!("level {k}"))?;
        }
        same_points(&la, &lb, "limit")?;
    }
}
