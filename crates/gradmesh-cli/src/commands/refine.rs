//! `gradmesh refine`: the refined control mesh, or its limit points, at a level.

use gradmesh::catmull_clark::{self, Level};
use gradmesh::formats::{self, Format};
use gradmesh::refine::Refinement;
use gradmesh::validate::{BaseMesh, VertexData};
use gradmesh::{binary_step, ternary_step};
use gradmesh::{Error, ErrorKind, FirstStep, GradientMesh, Limits, Topology};

use crate::args::RefineArgs;

pub fn run(args: &RefineArgs) -> Result<(), Error> {
    let format = Format::from_path(&args.output)
        .filter(|f| matches!(f, Format::Obj | Format::Json))
        .ok_or_else(|| {
            Error::new(ErrorKind::Io(format!(
                "{}: refine writes .obj or .json",
                args.output.display()
            )))
        })?;
    super::check_not_input(&args.output, &[&args.input], args.force)?;
    let limits = Limits {
        refinement_level: args.max_level,
        refined_faces: args.max_refined_faces,
        ..args.limits.limits()
    };
    let mut doc = super::read(&args.input, &limits)?;
    args.variant.apply(&mut doc);
    let mut layers = Vec::with_capacity(doc.layers.len());
    for (i, mesh) in doc.layers.iter().enumerate() {
        let locate = |e: Error| e.in_layer(i).in_file(&args.input);
        // Edits apply between steps: such meshes take the full refinement.
        if !args.limit && !mesh.interpolate_positions && mesh.edits.is_empty() && args.levels >= 1 {
            // Only the last level is written: keep one level at a time.
            let (topology, points) =
                last_level(mesh, args.levels, &limits, &args.input).map_err(locate)?;
            layers.push((Refined::Last(Box::new(topology)), points));
            continue;
        }
        let (mut refinement, warnings) =
            Refinement::new_with_limits(mesh, args.levels, &limits).map_err(locate)?;
        if args.limit {
            // Limit points of levels 0 and 1 are computed from level 2.
            limits
                .check_refinement(refinement.base(), args.levels.max(2))
                .map_err(locate)?;
        }
        super::print_warnings(&args.input, &warnings);
        let deepest = refinement.base().edits.deepest_level();
        if deepest > args.levels && !args.limit {
            eprintln!(
                "gradmesh: warning: {}: layer {i}: edits down to level {deepest} lie below the \
                 level written ({}) and have no effect on it",
                args.input.display(),
                args.levels
            );
        }
        let mut data = refinement.evaluate();
        let points = if args.limit {
            refinement.limit(&data, args.levels)
        } else {
            std::mem::take(&mut data.levels[args.levels])
        };
        drop(data);
        layers.push((Refined::All(Box::new(refinement)), points));
    }
    match format {
        Format::Obj => {
            let parts: Vec<_> = doc
                .layers
                .iter()
                .zip(&layers)
                .map(|(mesh, (r, points))| {
                    (
                        mesh.name.as_deref(),
                        r.topology(args.levels),
                        points.as_slice(),
                    )
                })
                .collect();
            formats::write_atomic_with(&args.output, |w| {
                formats::obj::write_refined_obj_to(w, &parts)
            })
        }
        _ => {
            let parts: Vec<_> = doc
                .layers
                .iter()
                .zip(&layers)
                .map(|(mesh, (r, points))| formats::json::RefinedLayer {
                    name: mesh.name.as_deref(),
                    colour_space: mesh.colour_space,
                    topology: r.topology(args.levels),
                    data: points,
                })
                .collect();
            formats::write_atomic(
                &args.output,
                formats::json::write_refined(&parts).as_bytes(),
            )
        }
    }
}

/// The refined topology of one layer: every level, or only the last one.
enum Refined {
    All(Box<Refinement>),
    Last(Box<Topology>),
}

impl Refined {
    fn topology(&self, level: usize) -> &Topology {
        match self {
            Refined::All(r) => r.topology(level),
            Refined::Last(t) => t,
        }
    }
}

/// Level `levels >= 1` of `mesh` (topology and data), as [`Refinement::new_with_limits`] and
/// [`Refinement::evaluate`] compute it for a mesh without interpolated positions, but holding
/// at most two levels at a time and never the last step's stencils.
fn last_level(
    mesh: &GradientMesh,
    levels: usize,
    limits: &Limits,
    input: &std::path::Path,
) -> Result<(Topology, Vec<VertexData>), Error> {
    limits.check_mesh(mesh)?;
    let (base, warnings) = BaseMesh::new(mesh)?;
    limits.check_refinement(&base, levels)?;
    super::print_warnings(input, &warnings);
    let (mut level, mut data): (Level, _) = match base.first_step {
        FirstStep::Ternary => (
            ternary_step::ternary_level(&base),
            ternary_step::ternary_data(&base),
        ),
        FirstStep::Binary => (
            binary_step::binary_level(&base),
            binary_step::binary_data(&base),
        ),
    };
    drop(base);
    for _ in 2..levels {
        let (child, stencils) = catmull_clark::refine(&level);
        data = stencils.apply(&data);
        level = child;
    }
    if levels >= 2 {
        data = catmull_clark::refine_data(&level, &data);
        let topology = level.topology.subdivide();
        return Ok((topology, data));
    }
    Ok((level.topology, data))
}
