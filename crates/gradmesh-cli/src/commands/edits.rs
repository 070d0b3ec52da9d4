//! `gradmesh edits`: the multi-resolution edits of each layer, with the vertex each names.

use std::fmt::Write as _;

use gradmesh::Refinement;
use gradmesh::{ColourEdit, Edit, Error, OpacityEdit};

use crate::args::EditsArgs;
use crate::output::out;

pub fn run(args: &EditsArgs, report: &mut super::WarningReport) -> Result<(), Error> {
    let doc = super::read(&args.input, &args.limits.limits(), 1, report)?;
    let mut out = String::new();
    for (i, mesh) in doc.layers.iter().enumerate() {
        let locate = |e: Error| e.in_layer(i).in_file(&args.input);
        let deepest = mesh.edits.iter().map(|e| e.address.level as usize).max();
        let name = mesh
            .name
            .as_deref()
            .map(|n| format!(" ({n})"))
            .unwrap_or_default();
        let Some(deepest) = deepest else {
            writeln!(out, "layer {i}{name}: no edits").unwrap();
            continue;
        };
        let (mut refinement, warnings) = Refinement::new(mesh, deepest).map_err(locate)?;
        report.add(Some(&args.input), super::in_layer(warnings, i));
        let data = refinement.evaluate();
        writeln!(
            out,
            "layer {i}{name}: {} edits, {}",
            mesh.edits.len(),
            mesh.fine_edits.name()
        )
        .unwrap();
        for (e, edit) in mesh.edits.iter().enumerate() {
            let a = edit.address;
            let vertex = refinement.edited_vertex(e);
            let place = match vertex {
                Some(v) => {
                    let d = data.levels[a.level as usize][v];
                    format!("vertex {v} at ({:.3}, {:.3})", d.position[0], d.position[1])
                }
                None => "no vertex".to_string(),
            };
            writeln!(
                out,
                "  edit {e}: {a}: {place}: {}",
                changes(edit, mesh.colour_space.name())
            )
            .unwrap();
        }
    }
    out!("{out}");
    Ok(())
}

/// What an edit changes, in words.
fn changes(edit: &Edit, space: &str) -> String {
    let mut parts = Vec::new();
    let three = |c: [f64; 3]| format!("[{}, {}, {}]", c[0], c[1], c[2]);
    match edit.colour {
        Some(ColourEdit::Set(c)) => parts.push(format!("colour {} ({space})", three(c))),
        Some(ColourEdit::Offset(d)) => parts.push(format!("colour + {} ({space})", three(d))),
        None => {}
    }
    match edit.opacity {
        Some(OpacityEdit::Set(o)) => parts.push(format!("opacity {o}")),
        Some(OpacityEdit::Offset(d)) => parts.push(format!("opacity + {d}")),
        None => {}
    }
    if let Some(o) = edit.offset {
        parts.push(format!("moved by {} i + {} j", o.x, o.y));
    }
    if parts.is_empty() {
        "nothing".into()
    } else {
        parts.join(", ")
    }
}
