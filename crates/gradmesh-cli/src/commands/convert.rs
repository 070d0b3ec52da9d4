//! `gradmesh convert`: any input to the native JSON format, with `--fit` the colours of an SVG
//! or PDF file's meshes fitted to their classic painting.

use std::path::Path;

use gradmesh::formats::{self, Format};
use gradmesh::render::LayerSource;
use gradmesh::{fit_to_classic, ClassicFitOptions, Document, Error, ErrorKind};

use super::{ClassicFill, Input};
use crate::args::ConvertArgs;

pub fn run(args: &ConvertArgs, report: &mut super::WarningReport) -> Result<(), Error> {
    if Format::from_path(&args.output) != Some(Format::Json) {
        return Err(Error::new(ErrorKind::UnsupportedFormat(format!(
            "{}: convert writes the native format; give the output a .json extension",
            args.output.display()
        ))));
    }
    super::check_not_input(&args.output, &[&args.input], args.force)?;
    let limits = args.limits.limits();
    let mut input = super::read_with_viewport(&args.input, &limits, args.page.page)?;
    report.add(Some(&args.input), std::mem::take(&mut input.warnings));
    args.variant.apply(&mut input.document);
    if args.fit {
        fit(&mut input, &args.input)?;
    }
    let doc = input.document;
    for (i, mesh) in doc.layers.iter().enumerate() {
        let warnings = gradmesh::validate(mesh).map_err(|e| e.in_layer(i).in_file(&args.input))?;
        report.add(Some(&args.input), super::in_layer(warnings, i));
    }
    write(&doc, &args.output)
}

fn write(doc: &Document, output: &Path) -> Result<(), Error> {
    let text = formats::json::write_document(doc);
    formats::write_atomic(output, text.as_bytes())
}

/// Fits the colours of `input`'s layers to the classic painting of the fills they came from,
/// at the file's own scale or finer.
fn fit(input: &mut Input, path: &Path) -> Result<(), Error> {
    let Some(fills) = &input.fills else {
        return Err(Error::new(ErrorKind::UnsupportedFormat(format!(
            "{}: --fit needs an SVG or PDF input (it fits the layers to the file's own meshes)",
            path.display()
        ))));
    };
    let sources: Vec<LayerSource> = fills
        .iter()
        .map(|fill| match fill {
            ClassicFill::Svg(f) => LayerSource::Classic(f),
            ClassicFill::Pdf(f) => LayerSource::Patches(f),
        })
        .collect();
    let pixels_per_unit = input
        .viewport
        .map_or(1.0, |(view, (w, _))| w / view.width().max(1e-12));
    let options = ClassicFitOptions {
        pixels_per_unit,
        ..ClassicFitOptions::default()
    };
    fit_to_classic(&mut input.document.layers, &sources, &options).map_err(|e| e.in_file(path))?;
    Ok(())
}
