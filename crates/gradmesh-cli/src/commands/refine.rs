//! `gradmesh refine`: the refined control mesh, or its limit points, at a level.

use gradmesh::formats::{self, Format};
use gradmesh::{refine_level, Error, ErrorKind, LevelPoints, Limits};

use crate::args::RefineArgs;

pub fn run(args: &RefineArgs, report: &mut super::WarningReport) -> Result<(), Error> {
    let format = Format::from_path(&args.output)
        .filter(|f| matches!(f, Format::Obj | Format::Json))
        .ok_or_else(|| {
            Error::new(ErrorKind::UnsupportedFormat(format!(
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
    let mut doc = super::read(&args.input, &limits, 1, report)?;
    args.variant.apply(&mut doc);
    let points = if args.limit {
        LevelPoints::Limit
    } else {
        LevelPoints::Control
    };
    let mut layers = Vec::with_capacity(doc.layers.len());
    for (i, mesh) in doc.layers.iter().enumerate() {
        let (level, warnings) = refine_level(mesh, args.levels, points, &limits)
            .map_err(|e| e.in_layer(i).in_file(&args.input))?;
        report.add(Some(&args.input), super::in_layer(warnings, i));
        layers.push(level);
    }
    match format {
        Format::Obj => {
            let parts: Vec<_> = doc
                .layers
                .iter()
                .zip(&layers)
                .map(|(mesh, level)| (mesh.name.as_deref(), &level.topology, level.data.as_slice()))
                .collect();
            formats::write_atomic_streamed(&args.output, |w| {
                formats::obj::write_refined_obj_to(w, &parts)
            })
        }
        _ => {
            let parts: Vec<_> = doc
                .layers
                .iter()
                .zip(&layers)
                .map(|(mesh, level)| formats::json::RefinedLayer {
                    name: mesh.name.as_deref(),
                    colour_space: mesh.colour_space,
                    topology: &level.topology,
                    data: &level.data,
                })
                .collect();
            formats::write_atomic(
                &args.output,
                formats::json::write_refined(&parts).as_bytes(),
            )
        }
    }
}
