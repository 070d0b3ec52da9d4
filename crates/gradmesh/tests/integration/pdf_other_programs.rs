//! PDF files laid out by other programs: Ghostscript's `pdfwrite` (of Inkscape's PDFs, and
//! `ps2pdf` of a PostScript file that paints a type 6 and a type 7 shading with `shfill`),
//! MuPDF's `mutool clean`, and qpdf's compressed object streams and cross-reference streams.
//! Each is read by gradmesh and rendered against `pdftoppm` of the same file, ΔE00 over the
//! mesh pixels. A missing program fails the test, naming the package to install.

use std::path::{Path, PathBuf};
use std::process::Command;

use gradmesh::formats::pdf;
use gradmesh::Limits;

use super::export::{Raster, Tool};
use super::pdf_read::{
    figures, inkscape_pdf, keep, mesh_pixels, render_pdf, scratch, visible_in_poppler, Figures,
};

/// A program that writes a PDF file from another.
#[derive(Clone, Copy, Debug)]
enum Writer {
    /// `gs -sDEVICE=pdfwrite`: Ghostscript's own objects, functions and bit widths.
    Ghostscript,
    /// `ps2pdf` of a PostScript file.
    Ps2pdf,
    /// `mutool clean -z`: MuPDF's rewrite, streams deflated.
    MutoolClean,
    /// `mutool clean -l -a`: linearised, binary streams ASCIIHex-encoded.
    MutoolLinearisedHex,
    /// `qpdf --object-streams=generate`: objects in compressed object streams, the
    /// cross-reference data a stream.
    QpdfObjectStreams,
}

impl Writer {
    /// The program, its package, and its arguments for `input` to `output`.
    fn command(self, input: &Path, output: &Path) -> (&'static str, &'static str, Vec<String>) {
        let (i, o) = (input.display().to_string(), output.display().to_string());
        match self {
            Writer::Ghostscript => (
                "gs",
                "ghostscript",
                vec![
                    "-q".into(),
                    "-dSAFER".into(),
                    "-dBATCH".into(),
                    "-dNOPAUSE".into(),
                    "-sDEVICE=pdfwrite".into(),
                    format!("-sOutputFile={o}"),
                    i,
                ],
            ),
            Writer::Ps2pdf => ("ps2pdf", "ghostscript", vec![i, o]),
            Writer::MutoolClean => (
                "mutool",
                "mupdf-tools",
                vec!["clean".into(), "-z".into(), i, o],
            ),
            Writer::MutoolLinearisedHex => (
                "mutool",
                "mupdf-tools",
                vec!["clean".into(), "-l".into(), "-a".into(), i, o],
            ),
            Writer::QpdfObjectStreams => (
                "qpdf",
                "qpdf",
                vec!["--object-streams=generate".into(), i, o],
            ),
        }
    }

    /// Writes `input` as `output` with this program.
    fn write(self, input: &Path, output: &Path) {
        let (program, package, args) = self.command(input, output);
        let out = Command::new(program)
            .args(&args)
            .output()
            .unwrap_or_else(|e| {
                panic!("{program} could not be run ({e}): install it (apt-get install {package})")
            });
        assert!(
            out.status.success() && output.exists(),
            "{program} {args:?} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// The PostScript file of the test data that paints two Coons patches (the second sharing a
/// side by edge flag 2) and a tensor-product patch coloured through a function.
fn two_meshes_ps() -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/pdf/two-meshes.ps");
    assert!(
        path.exists(),
        "the test data file {} is missing",
        path.display()
    );
    path
}

/// Whether `bytes` hold `needle`.
fn holds(bytes: &[u8], needle: &str) -> bool {
    bytes.windows(needle.len()).any(|w| w == needle.as_bytes())
}

/// One file to compare: its path, the shading types expected in page order, and the mask of
/// pixels where poppler shows a shading (none: every pixel gradmesh covers is a mesh pixel).
struct Case {
    name: String,
    path: PathBuf,
    types: Vec<u8>,
    visible: Option<Vec<bool>>,
}

/// Reads and renders `case` against pdftoppm (and MuPDF for scale): the figures against
/// poppler and MuPDF's against poppler.
fn compare(case: &Case) -> (Figures, Figures) {
    let bytes = std::fs::read(&case.path).unwrap();
    let picture =
        pdf::read_pdf(&bytes, 1, &Limits::DEFAULT).unwrap_or_else(|e| panic!("{}: {e}", case.name));
    let types: Vec<u8> = picture.fills.iter().map(|f| f.shading_type).collect();
    assert_eq!(types, case.types, "{}: the shading types read", case.name);
    let poppler = Tool::Pdftoppm.rasterise(&case.path);
    let mupdf = Tool::Mutool.rasterise(&case.path);
    let (w, h) = (poppler.width, poppler.height);
    let ours = render_pdf(&picture, w, h, true);
    let alpha = render_pdf(&picture, w, h, false);
    keep(&ours, &case.path.with_extension("gradmesh.png"));
    let mut inside = mesh_pixels(&alpha);
    if let Some(visible) = &case.visible {
        for (a, b) in inside.iter_mut().zip(visible) {
            *a &= *b;
        }
    }
    let ours = Raster::from_image(&ours);
    (
        figures(&ours, &poppler, &inside, &case.name),
        figures(&mupdf, &poppler, &inside, &case.name),
    )
}

/// The Inkscape PDFs rewritten by Ghostscript, MuPDF and qpdf; the mask of visible mesh
/// pixels is taken from the Inkscape PDF, whose page the rewrites keep.
fn inkscape_rewrites(dir: &Path) -> Vec<Case> {
    let mut cases = Vec::new();
    for name in [
        "wpt/meshgradient-basic-001.svg",
        "zectorio-mesh-gradient-js/sample3.svg",
        "zectorio-mesh-gradient-js/sample5.svg",
    ] {
        let original = inkscape_pdf(name, dir);
        let bytes = std::fs::read(&original).unwrap();
        let picture = pdf::read_pdf(&bytes, 1, &Limits::DEFAULT).unwrap();
        let types: Vec<u8> = picture.fills.iter().map(|f| f.shading_type).collect();
        let visible = visible_in_poppler(&original, &Tool::Pdftoppm.rasterise(&original));
        for writer in [
            Writer::Ghostscript,
            Writer::MutoolClean,
            Writer::QpdfObjectStreams,
        ] {
            let path = original.with_extension(format!("{writer:?}.pdf"));
            writer.write(&original, &path);
            cases.push(Case {
                name: format!("{name} by {writer:?}"),
                path,
                types: types.clone(),
                visible: Some(visible.clone()),
            });
        }
    }
    cases
}

/// `ps2pdf` of the PostScript file, and that PDF rewritten by qpdf and MuPDF.
fn postscript_cases(dir: &Path) -> Vec<Case> {
    let made = dir.join("two-meshes.pdf");
    Writer::Ps2pdf.write(&two_meshes_ps(), &made);
    let mut cases = vec![Case {
        name: "two-meshes.ps by ps2pdf".into(),
        path: made.clone(),
        types: vec![6, 7],
        visible: None,
    }];
    for writer in [Writer::QpdfObjectStreams, Writer::MutoolLinearisedHex] {
        let path = made.with_extension(format!("{writer:?}.pdf"));
        writer.write(&made, &path);
        cases.push(Case {
            name: format!("two-meshes.ps by ps2pdf, then {writer:?}"),
            path,
            types: vec![6, 7],
            visible: None,
        });
    }
    cases
}

/// PDF files written by Ghostscript, MuPDF and qpdf read as poppler paints them: mean at
/// most 1 ΔE00 and 99th percentile at most 4 against pdftoppm, or no farther from poppler
/// than MuPDF is on both. qpdf's files hold their objects in object streams and their
/// cross-reference data in a stream (checked), so lopdf's reading of those is exercised.
#[test]
fn other_programs_pdfs_match_pdftoppm() {
    let dir = scratch("other-programs");
    let mut cases = inkscape_rewrites(&dir);
    cases.extend(postscript_cases(&dir));
    let mut failures = Vec::new();
    for case in &cases {
        if case.name.contains("QpdfObjectStreams") {
            let bytes = std::fs::read(&case.path).unwrap();
            assert!(
                holds(&bytes, "/ObjStm") && holds(&bytes, "/XRef"),
                "{}: qpdf wrote no object or cross-reference stream",
                case.name
            );
        }
        let (f, spread) = compare(case);
        eprintln!(
            "{}: {} pixels; against pdftoppm mean {:.2}, 99th {:.2}; mutool against pdftoppm mean {:.2}, 99th {:.2}",
            case.name, f.pixels, f.mean, f.p99, spread.mean, spread.p99
        );
        let within_bar = f.mean <= 1.0 && f.p99 <= 4.0;
        let as_close_as_mupdf = f.mean <= spread.mean && f.p99 <= spread.p99;
        if !(within_bar || as_close_as_mupdf) {
            failures.push(format!(
                "{}: {f:?}; MuPDF against poppler {spread:?}",
                case.name
            ));
        }
    }
    if std::env::var_os("GRADMESH_KEEP_EXPORTS").is_none() {
        std::fs::remove_dir_all(&dir).ok();
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A file of the PDF test data (`tests/data/pdf`), failing the test when it is missing.
fn test_data(name: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/pdf")
        .join(name);
    assert!(
        path.exists(),
        "the test data file {} is missing",
        path.display()
    );
    path
}

/// Two files of pdf.js's test corpus written by Ghostscript 9.14 (`tests/data/pdf/README.md`):
/// every edge flag, colour through a function, one Coons and one tensor-product shading. Read,
/// converted into valid layers of the scheme, and rendered within the bar of pdftoppm (the
/// page holds nothing else, so every pixel gradmesh covers is a mesh pixel).
#[test]
fn pdfjs_all_flags_files_match_pdftoppm() {
    let dir = scratch("pdfjs");
    for (name, shading_type) in [
        ("coons-allflags-withfunction.pdf", 6),
        ("tensor-allflags-withfunction.pdf", 7),
    ] {
        let source = test_data(name);
        let path = dir.join(name);
        std::fs::copy(&source, &path).unwrap();
        let read = pdf::read_path_with_limits(&path, 1, &Limits::DEFAULT)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        for mesh in &read.document.layers {
            gradmesh::validate(mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let case = Case {
            name: name.into(),
            path,
            types: vec![shading_type],
            visible: None,
        };
        let (f, spread) = compare(&case);
        eprintln!(
            "{name}: {} patches, {} pixels; against pdftoppm mean {:.2}, 99th {:.2}; mutool against pdftoppm mean {:.2}, 99th {:.2}",
            read.picture.fills[0].patches.len(), f.pixels, f.mean, f.p99, spread.mean, spread.p99
        );
        assert!(f.mean <= 1.0 && f.p99 <= 4.0, "{name}: {f:?}");
    }
    if std::env::var_os("GRADMESH_KEEP_EXPORTS").is_none() {
        std::fs::remove_dir_all(&dir).ok();
    }
}
