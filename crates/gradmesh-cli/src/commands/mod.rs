//! The subcommands, each turning parsed flags into library calls.

mod convert;
mod edits;
mod info;
mod refine;
mod render;
mod serve;
mod vectorise;
mod warnings;

use std::path::Path;

use gradmesh::{Document, Error};

use crate::args::{Cli, Command};

pub use warnings::WarningReport;

/// Why a command failed.
pub enum Failure {
    /// An error still to be printed.
    Error(Error),
    /// Errors the command printed as it went (`info` reports every file it cannot read).
    Reported,
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure::Error(e)
    }
}

/// Runs the subcommand of `cli`. The warnings about its inputs are printed when it ends (before
/// its error, if it fails): every one with `--warnings` (and always by `info`), otherwise a
/// count per file.
pub fn run(cli: Cli) -> Result<(), Failure> {
    let mut report = WarningReport::new(cli.warnings);
    let result = match cli.command {
        Command::Info(a) => info::run(&a),
        Command::Convert(a) => Ok(convert::run(&a, &mut report)?),
        Command::Refine(a) => Ok(refine::run(&a, &mut report)?),
        Command::Render(a) => Ok(render::run(&a, &mut report)?),
        Command::Edits(a) => Ok(edits::run(&a, &mut report)?),
        Command::Serve(a) => Ok(serve::run(&a)?),
        Command::Vectorise(a) => Ok(vectorise::run(&a)?),
    };
    report.print();
    result
}

/// Reads a document within `limits` (page `page` of a PDF file), with errors located in the
/// file. An SVG or PDF file's warnings (what was left out) go to `report`.
fn read(
    path: &Path,
    limits: &gradmesh::Limits,
    page: usize,
    report: &mut WarningReport,
) -> Result<Document, Error> {
    let input = read_with_viewport(path, limits, page)?;
    report.add(Some(path), input.warnings);
    Ok(input.document)
}

/// The part of the plane a file shows and the picture's size in pixels, where the file says
/// (an SVG file's view box and size).
type Viewport = (gradmesh::render::View, (f64, f64));

/// What a layer read from an SVG or PDF file was converted from, and is drawn from classically.
#[derive(Clone, Debug)]
enum ClassicFill {
    /// An SVG mesh-gradient fill.
    Svg(gradmesh::formats::svg::MeshFill),
    /// A PDF patch-mesh shading.
    #[cfg_attr(not(feature = "pdf-read"), allow(dead_code))]
    Pdf(gradmesh::formats::pdf::ShadingFill),
}

/// A file read: its document, and for an SVG or PDF file its [`Viewport`] and the fills its
/// layers were converted from (one per layer).
struct Input {
    document: Document,
    viewport: Option<Viewport>,
    fills: Option<Vec<ClassicFill>>,
    /// What an SVG file held that was left out of `document`, for the caller to print.
    warnings: Vec<gradmesh::Warning>,
}

/// [`read`], with the file's [`Viewport`] and fills when it has them.
fn read_with_viewport(path: &Path, limits: &gradmesh::Limits, page: usize) -> Result<Input, Error> {
    use gradmesh::formats::{svg, Format};
    if gradmesh::formats::is_pdf_path(path) {
        return read_pdf(path, limits, page);
    }
    if Format::from_path(path) == Some(Format::Svg) {
        let read = svg::read_path_with_limits(path, limits)?;
        let viewport = Some((
            gradmesh::render::View::from_rect(read.view),
            read.pixel_size,
        ));
        return Ok(Input {
            document: read.document,
            viewport,
            fills: Some(read.fills.into_iter().map(ClassicFill::Svg).collect()),
            warnings: read.warnings,
        });
    }
    let document = gradmesh::formats::read_path_with_limits(path, limits)?;
    // A document's own view (a vectorised picture's rectangle), one pixel per unit.
    let viewport = document.view.map(|v| {
        (
            gradmesh::render::View::from_rect(v),
            (v.width(), v.height()),
        )
    });
    Ok(Input {
        document,
        viewport,
        fills: None,
        warnings: Vec::new(),
    })
}

/// Page `page` of a PDF (or `.ai`) file, with its page as the viewport and its shadings as the
/// fills.
#[cfg(feature = "pdf-read")]
fn read_pdf(path: &Path, limits: &gradmesh::Limits, page: usize) -> Result<Input, Error> {
    let read = gradmesh::formats::pdf::read_path_with_limits(path, page, limits)?;
    let view = read.picture.view_rect();
    Ok(Input {
        document: read.document,
        viewport: Some((
            gradmesh::render::View::from_rect(view),
            (view.width(), view.height()),
        )),
        fills: Some(
            read.picture
                .fills
                .into_iter()
                .map(ClassicFill::Pdf)
                .collect(),
        ),
        warnings: read.warnings,
    })
}

/// Without the `pdf-read` feature a PDF file is refused, as the library refuses it.
#[cfg(not(feature = "pdf-read"))]
fn read_pdf(path: &Path, limits: &gradmesh::Limits, _page: usize) -> Result<Input, Error> {
    let document = gradmesh::formats::read_path_with_limits(path, limits)?;
    Ok(Input {
        document,
        viewport: None,
        fills: None,
        warnings: Vec::new(),
    })
}

/// Refuses to write over an input unless `force` is given.
fn check_not_input(output: &Path, inputs: &[&Path], force: bool) -> Result<(), Error> {
    if force {
        return Ok(());
    }
    let canon = |p: &Path| std::fs::canonicalize(p).ok();
    let out = canon(output);
    for input in inputs {
        if out.is_some() && out == canon(input) {
            return Err(Error::new(gradmesh::ErrorKind::Io(format!(
                "{} is also the input; pass --force to write over it",
                output.display()
            ))));
        }
    }
    Ok(())
}

/// `warnings` of layer `layer`, marked with it.
fn in_layer(
    warnings: Vec<gradmesh::Warning>,
    layer: usize,
) -> impl Iterator<Item = gradmesh::Warning> {
    warnings.into_iter().map(move |w| gradmesh::Warning {
        layer: Some(layer),
        ..w
    })
}
