//! SVG and PDF files in the editor. An SVG file's mesh-gradient fills become layers (the pieces
//! of one mesh that an export wrote as separate gradients joined again), and what is not a mesh
//! fill is a locked backdrop under the layers, drawn by resvg at the page's view
//! ([`gradmesh_svg_picture::render_backdrop`]), with a message saying what cannot be edited. A
//! PDF file's patch-mesh shadings become layers; what else its page holds is not drawn, and the
//! message says what was left out. The layers' colours are fitted to the file's own painting of
//! its meshes, as `gradmesh convert --fit` fits them, up to [`MAX_FITTED_PATCHES`] patches.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use gradmesh::formats::{self, pdf, svg, Format};
use gradmesh::render::{LayerSource, RenderOptions};
use gradmesh::{
    fit_joined_to_classic, ClassicFitOptions, ColourSpace, Document, JoinTolerance, Limits,
    WarningKind,
};
use serde_json::{json, Value};

use crate::viewer::Viewport;

/// The most memory one backdrop render may take, in bytes.
pub const MAX_BACKDROP_MEMORY: u64 = 1 << 30;

/// What an SVG or PDF file holds besides the layers read from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Backdrop {
    /// The file (its relative links are resolved against its folder).
    pub path: PathBuf,
    /// An SVG file's text, drawn as the backdrop; `None` for a PDF file, whose other content
    /// is not drawn.
    svg_text: Option<String>,
    /// What is not editable, counted by kind.
    pub message: String,
}

impl Backdrop {
    /// Whether the backdrop draws anything (an SVG file's other content).
    pub fn is_drawn(&self) -> bool {
        self.svg_text.is_some()
    }
}

/// A document read from a file, with the backdrop of an SVG or PDF file.
pub struct Read {
    /// The document.
    pub document: Document,
    /// What an SVG or PDF file holds besides the layers (`None` for other formats, and for a
    /// PDF file from which nothing was left out).
    pub backdrop: Option<Backdrop>,
}

/// Reads the document in `path`: an SVG file through [`read_svg`], a PDF or `.ai` file through
/// [`read_pdf`], any other as `formats::read_path` reads it.
pub fn read_document(path: &Path) -> Result<Read, String> {
    if Format::from_path(path) == Some(Format::Svg) {
        return read_svg(path);
    }
    if formats::is_pdf_path(path) {
        return read_pdf(path);
    }
    let document = formats::read_path(path).map_err(|e| e.to_string())?;
    Ok(Read {
        document,
        backdrop: None,
    })
}

/// Reads the SVG file `path`: its mesh fills as layers in Lab, those that meet along sides
/// joined into one layer ([`gradmesh::join_meshes`], see [`join_tolerance`]), and the rest of
/// it as a backdrop.
pub fn read_svg(path: &Path) -> Result<Read, String> {
    let limits = Limits::DEFAULT;
    let bytes = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.len() > limits.input_bytes {
        return Err(format!(
            "{}: {} bytes, over the limit of {}",
            path.display(),
            bytes.len(),
            limits.input_bytes
        ));
    }
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let read = svg::read_document_with_limits(&text, ColourSpace::Lab, &limits)
        .map_err(|e| e.in_file(path).to_string())?;
    let tolerance = join_tolerance(&read.document);
    let joined = gradmesh::join_meshes(&read.document.layers, tolerance);
    let fills: Vec<Vec<LayerSource>> = joined
        .iter()
        .map(|j| {
            j.sources
                .iter()
                .map(|&k| LayerSource::Classic(&read.fills[k]))
                .collect()
        })
        .collect();
    let mut layers: Vec<_> = joined.into_iter().map(|j| j.mesh).collect();
    let pixels_per_unit = read.pixel_size.0 / read.view.width().max(1e-12);
    let fit = fit_to_file(&mut layers, &fills, pixels_per_unit);
    let document = Document::new(layers);
    let kinds = read.warnings.iter().map(|w| w.kind);
    let backdrop = Backdrop {
        path: path.to_path_buf(),
        svg_text: Some(text),
        message: format!("{}. {fit}", not_editable(path, kinds)),
    };
    Ok(Read {
        document,
        backdrop: Some(backdrop),
    })
}

/// Reads the first page of the PDF (or `.ai`) file `path`: one layer in Lab per patch-mesh
/// shading painted, and a backdrop that draws nothing but says what the page holds besides,
/// when something was left out or read differently.
pub fn read_pdf(path: &Path) -> Result<Read, String> {
    let mut read =
        pdf::read_path_with_limits(path, 1, &Limits::DEFAULT).map_err(|e| e.to_string())?;
    let fills: Vec<Vec<LayerSource>> = read
        .picture
        .fills
        .iter()
        .map(|fill| vec![LayerSource::Patches(fill)])
        .collect();
    let fit = fit_to_file(&mut read.document.layers, &fills, 1.0);
    if fit != ColourFit::Fitted {
        read.warnings.push(gradmesh::Warning::new(
            WarningKind::PdfLeftOut,
            fit.to_string(),
        ));
    }
    let messages: Vec<&str> = read.warnings.iter().map(|w| w.message.as_str()).collect();
    let backdrop = (!messages.is_empty()).then(|| Backdrop {
        path: path.to_path_buf(),
        svg_text: None,
        message: left_out_of_pdf(path, &messages),
    });
    Ok(Read {
        document: read.document,
        backdrop,
    })
}

/// The most patches a file's meshes may hold for the editor to fit their colours when it opens
/// the file. The fit paints each fill and solves for every control colour and refined-level
/// edit: the meshgradient test files (up to a few dozen patches) take 0.3-6 s each on a busy
/// 2-core machine, and an SVG exported from a mesh (thousands of one-patch gradients) minutes.
pub const MAX_FITTED_PATCHES: usize = 256;

/// What became of a file's colours when it was opened: what the File panel's message says.
#[derive(Clone, Debug, PartialEq)]
enum ColourFit {
    /// Fitted to the file's own painting.
    Fitted,
    /// Left as converted: the layers hold this many patches, over [`MAX_FITTED_PATCHES`].
    TooManyPatches(usize),
    /// Left as converted: the fit failed, for this reason.
    Failed(String),
}

impl std::fmt::Display for ColourFit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ColourFit::Fitted => {
                write!(f, "Colours fitted to the file's own painting of its meshes")
            }
            ColourFit::TooManyPatches(patches) => write!(
                f,
                "Colours as converted, not fitted to the file's painting ({patches} patches, over \
                 {MAX_FITTED_PATCHES}; `gradmesh convert --fit` fits them)"
            ),
            ColourFit::Failed(why) => write!(
                f,
                "Colours as converted: the fit to the file's painting failed ({why})"
            ),
        }
    }
}

/// Fits the colours of `layers` (and colour edits at a refined level where the control colours
/// cannot follow) to the file's own painting of the fills each holds, `fills[i]` for layer `i`,
/// as `gradmesh convert --fit` does: the scheme's surface then looks as the file does, not as
/// the plain conversion of its patches. `pixels_per_unit` is the file's scale (its fills are
/// painted at that scale or finer). Layers of more than [`MAX_FITTED_PATCHES`] patches in all,
/// or that the fit cannot take, are left as converted.
fn fit_to_file(
    layers: &mut [gradmesh::GradientMesh],
    fills: &[Vec<LayerSource>],
    pixels_per_unit: f64,
) -> ColourFit {
    let patches: usize = layers.iter().map(|l| l.faces.len()).sum();
    if patches > MAX_FITTED_PATCHES {
        return ColourFit::TooManyPatches(patches);
    }
    let fills: Vec<&[LayerSource]> = fills.iter().map(Vec::as_slice).collect();
    let options = ClassicFitOptions {
        pixels_per_unit,
        ..ClassicFitOptions::default()
    };
    let mut fitted = layers.to_vec();
    match fit_joined_to_classic(&mut fitted, &fills, &options) {
        Ok(_) => {
            layers.clone_from_slice(&fitted);
            ColourFit::Fitted
        }
        Err(e) => ColourFit::Failed(e.to_string()),
    }
}

/// "NAME: only its patch-mesh shadings are read; left out or read differently: text is not
/// drawn; …"
/// for the warnings `messages` of a PDF file.
fn left_out_of_pdf(path: &Path, messages: &[&str]) -> String {
    format!(
        "{}: only its patch-mesh shadings are read; left out or read differently: {}",
        file_name(path),
        messages.join("; ")
    )
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default()
}

/// How near sides must be to be joined: gradmesh's SVG export writes coordinates to a
/// thousandth of a unit, and each mesh gradient places its corners by adding up its sides'
/// rounded steps, so the same corner read from two gradients lies a few thousandths apart; a
/// hundred-thousandth of the document's extent where that is more. Stop colours are 8-bit
/// sRGB: a Lab unit covers a step of one.
pub fn join_tolerance(doc: &Document) -> JoinTolerance {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in doc.layers.iter().flat_map(|l| &l.points) {
        lo = [lo[0].min(p.position.x), lo[1].min(p.position.y)];
        hi = [hi[0].max(p.position.x), hi[1].max(p.position.y)];
    }
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let extent = if extent.is_finite() { extent } else { 0.0 };
    JoinTolerance {
        position: (1e-5 * extent).max(0.02),
        colour: 1.0,
        opacity: 0.01,
    }
}

/// "NAME: not editable, drawn as a locked backdrop: 3 parts that are not mesh gradients left
/// out, …" for the warnings of `kinds`.
fn not_editable(path: &Path, kinds: impl Iterator<Item = WarningKind>) -> String {
    let mut counts: BTreeMap<String, (WarningKind, usize)> = BTreeMap::new();
    for kind in kinds {
        counts.entry(format!("{kind:?}")).or_insert((kind, 0)).1 += 1;
    }
    let name = file_name(path);
    if counts.is_empty() {
        return format!("{name}: every part is a mesh gradient");
    }
    let parts: Vec<String> = counts
        .into_values()
        .map(|(kind, count)| kind.counted(count))
        .collect();
    format!(
        "{name}: not editable, drawn as a locked backdrop: {}",
        parts.join(", ")
    )
}

/// The backdrops as the state message lists them.
pub fn describe(backdrops: &[Backdrop], folder_name: impl Fn(&Path) -> String) -> Value {
    backdrops
        .iter()
        .map(|b| json!({"file": folder_name(&b.path), "message": b.message, "drawn": b.is_drawn()}))
        .collect()
}

/// The backdrops drawn one over the other at `viewport`: RGBA8 with straight alpha, or `None`
/// when none draws anything.
pub fn render(backdrops: &[Backdrop], viewport: &Viewport) -> Result<Option<Vec<u8>>, String> {
    let opts = RenderOptions::new(viewport.width, viewport.height, viewport.view);
    let mut picture: Option<Vec<u8>> = None;
    for backdrop in backdrops {
        let Some(text) = &backdrop.svg_text else {
            continue;
        };
        let drawn = gradmesh_svg_picture::render_backdrop(
            (&backdrop.path, text),
            &opts,
            MAX_BACKDROP_MEMORY,
        )
        .map_err(|e| e.to_string())?
        .map_err(|message| format!("{}: {message}", backdrop.path.display()))?;
        match (&mut picture, drawn) {
            (_, None) => {}
            (None, Some(rgba)) => picture = Some(rgba),
            (Some(below), Some(above)) => over(below, &above),
        }
    }
    Ok(picture)
}

/// `above` composited over `below`, both straight-alpha RGBA8.
fn over(below: &mut [u8], above: &[u8]) {
    for (b, a) in below.chunks_exact_mut(4).zip(above.chunks_exact(4)) {
        let (aa, ba) = (f32::from(a[3]) / 255.0, f32::from(b[3]) / 255.0);
        let alpha = aa + ba * (1.0 - aa);
        if alpha <= 0.0 {
            continue;
        }
        for c in 0..3 {
            let value = (f32::from(a[c]) * aa + f32::from(b[c]) * ba * (1.0 - aa)) / alpha;
            b[c] = value.round().clamp(0.0, 255.0) as u8;
        }
        b[3] = (alpha * 255.0).round() as u8;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_counts_what_is_left_out_by_kind() {
        let kinds = [
            WarningKind::SvgNotMeshFill,
            WarningKind::SvgNotMeshFill,
            WarningKind::SvgReadDifferently,
        ];
        let message = not_editable(Path::new("/a/art.svg"), kinds.into_iter());
        assert_eq!(
            message,
            "art.svg: not editable, drawn as a locked backdrop: 2 parts that are not mesh \
             gradients left out, 1 SVG attribute ignored or read differently"
        );
    }

    /// The examples `names` as the layers of one document, exported as SVG by the page's
    /// export and read back by [`read_svg`]: the layers exported, the gradients written, and
    /// the document read.
    fn exported_and_read(names: &[&str]) -> (usize, usize, Document) {
        let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
        let mut doc = Document::default();
        for name in names {
            let read = formats::read_path(&examples.join(name))
                .unwrap_or_else(|e| panic!("the example {name}: {e}"));
            doc.layers.extend(read.layers);
        }
        let svg = crate::exports::export_document(&doc, crate::exports::ExportFormat::Svg, 600)
            .expect("the SVG export");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("exported.svg");
        std::fs::write(&path, svg).unwrap();
        let fills = formats::read_path(&path).unwrap().layers.len();
        (doc.layers.len(), fills, read_svg(&path).unwrap().document)
    }

    #[test]
    fn an_exported_svg_reads_back_as_one_large_layer_per_layer() {
        let (exported, fills, doc) = exported_and_read(&["non-rectangular.json", "annulus.json"]);
        assert!(fills > 500, "the export writes many gradients: {fills}");
        for mesh in &doc.layers {
            gradmesh::validate(mesh).unwrap();
        }
        // Each layer exported is one mesh but for the finer rings the export writes around its
        // irregular points, which meet their surroundings at T-junctions and stay apart.
        let faces: usize = doc.layers.iter().map(|l| l.faces.len()).sum();
        let large: Vec<usize> = (doc.layers.iter().map(|l| l.faces.len()))
            .filter(|&n| n > 100)
            .collect();
        assert_eq!(
            large.len(),
            exported,
            "{fills} gradients joined into {large:?}"
        );
        assert!(large.iter().sum::<usize>() * 100 > 95 * faces);
        assert!(doc.layers.len() * 50 < fills, "{} layers", doc.layers.len());
    }

    /// A meshgradient test file of the shared data (the test fails naming it when missing).
    fn shared_svg(name: &str) -> PathBuf {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/realdata/meshgradient")
            .join(name);
        assert!(path.is_file(), "the test needs {}", path.display());
        path
    }

    /// The mean difference, in 8-bit levels over the colour channels, between `layers` drawn
    /// as the scheme and `fills` painted classically, over the pixels both cover opaquely, in a
    /// 256-pixel-wide picture of `view`.
    fn mean_difference(
        layers: &[gradmesh::GradientMesh],
        fills: &[svg::MeshFill],
        view: kurbo::Rect,
    ) -> f64 {
        use gradmesh::render::{render_picture_into, PictureLayer, View};
        let (w, h) = (256, (256.0 * view.height() / view.width()).ceil() as u32);
        let opts = RenderOptions::new(w, h, View::from_rect(view));
        let paint = |sources: Vec<LayerSource>| {
            let layers: Vec<PictureLayer> = (sources.into_iter())
                .map(|source| PictureLayer { source, clip: None })
                .collect();
            let mut out = vec![0f32; 4 * (w * h) as usize];
            render_picture_into(&layers, &opts, &mut out).unwrap();
            out
        };
        let scheme = paint(layers.iter().map(LayerSource::Scheme).collect());
        let classic = paint(fills.iter().map(LayerSource::Classic).collect());
        let (mut sum, mut count) = (0.0, 0usize);
        for (a, b) in scheme.chunks_exact(4).zip(classic.chunks_exact(4)) {
            if a[3] >= 1.0 && b[3] >= 1.0 {
                sum += (0..3).map(|c| f64::from((a[c] - b[c]).abs())).sum::<f64>() / 3.0;
                count += 1;
            }
        }
        assert!(count > 1000, "{count} pixels covered by both");
        255.0 * sum / count as f64
    }

    /// An SVG file opens with its layers' colours fitted to the file's own painting of its
    /// meshes: the scheme's surface is drawn within a level of it, where the plain conversion
    /// of the patches is several levels off.
    #[test]
    fn an_svg_opens_with_colours_fitted_to_its_painting() {
        for name in [
            "wpt/meshgradient-basic-003.svg",
            "zectorio-mesh-gradient-js/sample4.svg",
        ] {
            let path = shared_svg(name);
            let text = std::fs::read_to_string(&path).unwrap();
            let plain =
                svg::read_document_with_limits(&text, ColourSpace::Lab, &Limits::DEFAULT).unwrap();
            let fitted = read_svg(&path).unwrap().document;
            let faces = |layers: &[gradmesh::GradientMesh]| -> usize {
                layers.iter().map(|l| l.faces.len()).sum()
            };
            assert_eq!(
                faces(&fitted.layers),
                faces(&plain.document.layers),
                "{name}"
            );
            let before = mean_difference(&plain.document.layers, &plain.fills, plain.view);
            let after = mean_difference(&fitted.layers, &plain.fills, plain.view);
            assert!(
                after < 1.0 && after < before / 3.0,
                "{name}: {before} -> {after}"
            );
        }
    }

    #[test]
    fn over_keeps_what_is_below_a_clear_pixel() {
        let mut below = vec![10, 20, 30, 255, 0, 0, 0, 0];
        over(&mut below, &[200, 0, 0, 0, 0, 0, 255, 255]);
        assert_eq!(below, vec![10, 20, 30, 255, 0, 0, 255, 255]);
    }
}
