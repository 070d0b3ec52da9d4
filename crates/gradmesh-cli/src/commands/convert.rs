//! `gradmesh convert`: any input to the native JSON format.

use gradmesh::formats::{self, Format};
use gradmesh::{Error, ErrorKind};

use crate::args::ConvertArgs;

pub fn run(args: &ConvertArgs, report: &mut super::WarningReport) -> Result<(), Error> {
    if Format::from_path(&args.output) != Some(Format::Json) {
        return Err(Error::new(ErrorKind::UnsupportedFormat(format!(
            "{}: convert writes the native format; give the output a .json extension",
            args.output.display()
        ))));
    }
    super::check_not_input(&args.output, &[&args.input], args.force)?;
    let mut doc = super::read(&args.input, &args.limits.limits(), args.page.page, report)?;
    args.variant.apply(&mut doc);
    for (i, mesh) in doc.layers.iter().enumerate() {
        let warnings = gradmesh::validate(mesh).map_err(|e| e.in_layer(i).in_file(&args.input))?;
        report.add(Some(&args.input), super::in_layer(warnings, i));
    }
    let text = formats::json::write_document(&doc);
    formats::write_atomic(&args.output, text.as_bytes())
}
