//! `gradmesh info`: what a mesh is made of.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use gradmesh::BaseMesh;
use gradmesh::Topology;
use gradmesh::{EdgeKind, Error, GradientMesh};

use super::Failure;
use crate::args::InfoArgs;
use crate::output::{out, outln};

/// Describes every file, reporting each error as it comes; fails with the count of failures
/// (each already printed) if any file or layer could not be described.
pub fn run(args: &InfoArgs) -> Result<(), Failure> {
    let mut failed = 0usize;
    let limits = args.limits.limits();
    for path in &args.inputs {
        let mut read_warnings = super::WarningReport::new(true);
        let read = super::read(path, &limits, args.page.page, &mut read_warnings);
        read_warnings.print();
        match read {
            Ok(doc) => {
                outln!("{}", path.display());
                for (i, mesh) in doc.layers.iter().enumerate() {
                    match describe(mesh) {
                        Ok((text, warnings)) => {
                            out!("  layer {i}{text}");
                            for w in warnings {
                                outln!("    warning: {w}");
                            }
                        }
                        Err(e) => {
                            let e = e.in_layer(i).in_file(path);
                            eprintln!("gradmesh: error: {e}");
                            failed += 1;
                        }
                    }
                }
            }
            Err(e) => {
                eprintln!("gradmesh: error: {e}");
                failed += 1;
            }
        }
    }
    if failed > 0 {
        return Err(Failure::Reported);
    }
    Ok(())
}

fn histogram(values: impl Iterator<Item = usize>) -> String {
    let mut h = BTreeMap::new();
    for v in values {
        *h.entry(v).or_insert(0usize) += 1;
    }
    h.iter()
        .map(|(k, n)| format!("{k}: {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn describe(mesh: &GradientMesh) -> Result<(String, Vec<gradmesh::Warning>), Error> {
    let (base, mut warnings) = BaseMesh::new(mesh)?;
    for fold in gradmesh::render::find_folds(mesh)? {
        warnings.push(gradmesh::Warning::new(
            gradmesh::WarningKind::Fold,
            format!(
                "the surface folds over itself near ({:.1}, {:.1}), in faces {:?} (area {:.3}): \
                 make the mesh more convex there or shorten its handles",
                fold.position.x, fold.position.y, fold.faces, fold.area
            ),
        ));
    }
    let whole = Topology::from_faces(mesh.points.len(), &mesh.faces)?;
    let mut s = String::new();
    if let Some(name) = &mesh.name {
        write!(s, " \"{name}\"").unwrap();
    }
    writeln!(
        s,
        ": colour space {}, boundary {}, creasing {}",
        mesh.colour_space.name(),
        mesh.boundary.name(),
        mesh.creasing.name()
    )
    .unwrap();
    writeln!(
        s,
        "    points {}, faces {}, edges {}, corners {}",
        mesh.points.len(),
        mesh.faces.len(),
        whole.edge_count(),
        mesh.corner_count()
    )
    .unwrap();
    let boundary_edges = (0..whole.edge_count())
        .filter(|&e| whole.is_boundary_edge(e))
        .count();
    writeln!(
        s,
        "    boundary edges {boundary_edges}, Euler characteristic {}",
        whole.euler_characteristic()
    )
    .unwrap();
    writeln!(
        s,
        "    face sizes {{{}}}",
        histogram(mesh.faces.iter().map(Vec::len))
    )
    .unwrap();
    writeln!(
        s,
        "    valences {{{}}}",
        histogram(
            (0..whole.vertex_count())
                .filter(|&v| !whole.vertex_faces(v).is_empty())
                .map(|v| whole.vertex_edges(v).len())
        )
    )
    .unwrap();
    let count = |k: EdgeKind| mesh.edges.values().filter(|t| t.kind == k).count();
    writeln!(
        s,
        "    creases {}, discontinuous edges {}, corner points {}, split points {}",
        count(EdgeKind::Crease),
        count(EdgeKind::Discontinuous),
        mesh.points.iter().filter(|p| p.corner).count(),
        base.source_point.len() - mesh.points.len()
    )
    .unwrap();
    if !mesh.edits.is_empty() {
        writeln!(
            s,
            "    edits {}, down to level {}, {} (gradmesh edits lists them)",
            mesh.edits.len(),
            base.edits.deepest_level(),
            mesh.fine_edits.name()
        )
        .unwrap();
    }
    if let Some(b) = bounds(mesh) {
        writeln!(
            s,
            "    bounds x {} .. {}, y {} .. {}",
            b[0], b[2], b[1], b[3]
        )
        .unwrap();
    }
    Ok((s, warnings))
}

fn bounds(mesh: &GradientMesh) -> Option<[f64; 4]> {
    let mut it = mesh.points.iter().map(|p| p.position);
    let first = it.next()?;
    Some(it.fold([first.x, first.y, first.x, first.y], |b, p| {
        [b[0].min(p.x), b[1].min(p.y), b[2].max(p.x), b[3].max(p.y)]
    }))
}
