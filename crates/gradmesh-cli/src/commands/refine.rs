//! `gradmesh refine`: the refined control mesh, or its limit points, at a level.

use gradmesh::formats::{self, Format};
use gradmesh::refine::Refinement;
use gradmesh::{Error, ErrorKind};

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
    let mut limits = args.limits.limits();
    if let Some(level) = args.max_level {
        limits.refinement_level = level;
    }
    if let Some(faces) = args.max_refined_faces {
        limits.refined_faces = faces;
    }
    let mut doc = super::read(&args.input, &limits)?;
    args.variant.apply(&mut doc);
    let mut layers = Vec::with_capacity(doc.layers.len());
    for (i, mesh) in doc.layers.iter().enumerate() {
        let locate = |e: Error| e.in_layer(i).in_file(&args.input);
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
        layers.push((refinement, points));
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
