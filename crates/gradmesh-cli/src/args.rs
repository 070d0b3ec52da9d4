//! Command-line flags.

use std::path::PathBuf;

use clap::builder::TypedValueParser as _;
use clap::{Args, Parser, Subcommand, ValueEnum};
use gradmesh::render::GamutMapping;
use gradmesh::Limits;

/// Gradient meshes of arbitrary topology (Lieng, Kosinka, Shen & Dodgson 2017).
#[derive(Debug, Parser)]
#[command(name = "gradmesh", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// List every warning about the inputs, rather than a count per file (`info` always
    /// lists them).
    #[arg(long, global = true)]
    pub warnings: bool,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print counts, face sizes, valences, bounds, colour space and warnings of meshes.
    Info(InfoArgs),
    /// Convert a mesh (.json, .off, .obj, .svg, .pdf, .ai) to the native JSON format.
    Convert(ConvertArgs),
    /// Write the refined control mesh (or its limit points) at a given level.
    Refine(RefineArgs),
    /// Render the limit surface of meshes, drawn in order as layers, to a PNG.
    Render(RenderArgs),
    /// List the multi-resolution edits of a mesh: the vertex each names, and what it changes.
    Edits(EditsArgs),
    /// Fit a gradient mesh of free topology to a PNG or JPEG picture.
    Vectorise(VectoriseArgs),
    /// Start the local web editor and print its URL (listens on 127.0.0.1 only).
    Serve(ServeArgs),
}

/// Flags of `gradmesh serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// The documents to open (.json, .off, .obj, .svg, .pdf, .ai), their layers in order, the first at
    /// the bottom; without any, a new document. Saving writes JSON beside the one file (the
    /// same file if it is JSON); several files are saved with "Save as".
    #[arg(value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// The port on 127.0.0.1 (0: any free port).
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// The folder documents are opened from and saved to (default: FILE's folder, else the
    /// current folder). The editor reads and writes nothing outside it.
    #[arg(long, value_name = "DIR")]
    pub folder: Option<PathBuf>,
}

/// The paper's options (section 4.5), applied to every layer; without them each layer keeps
/// what its file says.
#[derive(Debug, Args)]
#[command(next_help_heading = "Scheme options")]
pub struct VariantArgs {
    /// Make the limit surface pass through the control points.
    #[arg(long)]
    pub interpolate_positions: bool,
    /// The first refinement: ternary (the paper's) or binary (two binary splits).
    #[arg(long, value_name = "STEP")]
    pub first_step: Option<FirstStepArg>,
}

/// `--first-step`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FirstStepArg {
    /// The paper's ternary step.
    Ternary,
    /// Two binary splits.
    Binary,
}

impl From<FirstStepArg> for gradmesh::FirstStep {
    fn from(step: FirstStepArg) -> Self {
        match step {
            FirstStepArg::Ternary => gradmesh::FirstStep::Ternary,
            FirstStepArg::Binary => gradmesh::FirstStep::Binary,
        }
    }
}

impl VariantArgs {
    /// Applies the options to every layer of `doc`.
    pub fn apply(&self, doc: &mut gradmesh::Document) {
        for mesh in &mut doc.layers {
            if self.interpolate_positions {
                mesh.interpolate_positions = true;
            }
            if let Some(step) = self.first_step {
                mesh.first_step = step.into();
            }
        }
    }
}

/// The page of a PDF input.
#[derive(Debug, Args)]
pub struct PageArg {
    /// The page of a PDF (or .ai) input to read, from 1.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub page: usize,
}

/// Limits on the input (`gradmesh::Limits`), raised for trusted input.
#[derive(Debug, Args)]
#[command(next_help_heading = "Limits")]
pub struct LimitArgs {
    /// Largest input file, in bytes.
    #[arg(long, value_name = "BYTES", default_value_t = Limits::DEFAULT.input_bytes)]
    pub max_input_bytes: u64,
    /// Most control points in one mesh.
    #[arg(long, value_name = "N", default_value_t = Limits::DEFAULT.points)]
    pub max_points: u64,
    /// Most faces in one mesh.
    #[arg(long, value_name = "N", default_value_t = Limits::DEFAULT.faces)]
    pub max_faces: u64,
    /// Most face corners in one mesh.
    #[arg(long, value_name = "N", default_value_t = Limits::DEFAULT.corners)]
    pub max_corners: u64,
}

impl LimitArgs {
    /// The default limits, with the flags given.
    pub fn limits(&self) -> Limits {
        Limits {
            input_bytes: self.max_input_bytes,
            points: self.max_points,
            faces: self.max_faces,
            corners: self.max_corners,
            ..Limits::DEFAULT
        }
    }
}

/// `--colour-space`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ColourSpaceArg {
    /// CIE Lab (D65).
    Lab,
    /// Oklab.
    Oklab,
    /// Linear-light sRGB.
    SrgbLinear,
    /// sRGB.
    Srgb,
}

impl From<ColourSpaceArg> for gradmesh::ColourSpace {
    fn from(space: ColourSpaceArg) -> Self {
        match space {
            ColourSpaceArg::Lab => gradmesh::ColourSpace::Lab,
            ColourSpaceArg::Oklab => gradmesh::ColourSpace::Oklab,
            ColourSpaceArg::SrgbLinear => gradmesh::ColourSpace::SrgbLinear,
            ColourSpaceArg::Srgb => gradmesh::ColourSpace::Srgb,
        }
    }
}

/// `--pdf-colour`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PdfColourArg {
    /// CIE Lab with the D65 white point.
    Lab,
    /// sRGB (DeviceRGB), split finer so that RGB interpolation stays within the tolerance.
    Srgb,
}

impl From<PdfColourArg> for gradmesh::export::PdfColour {
    fn from(c: PdfColourArg) -> Self {
        match c {
            PdfColourArg::Lab => gradmesh::export::PdfColour::Lab,
            PdfColourArg::Srgb => gradmesh::export::PdfColour::Srgb,
        }
    }
}

/// `--svg-mesh`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SvgMeshArg {
    /// As Inkscape and the SVG 2 draft paint them: Coons patches, colour bilinear in sRGB
    /// (smoothed across patches for type="bicubic").
    Classic,
    /// Converted into the scheme (as `convert` writes them), drawn as limit surfaces.
    Scheme,
}

impl From<SvgMeshArg> for gradmesh::render::SvgMeshRendering {
    fn from(mode: SvgMeshArg) -> Self {
        match mode {
            SvgMeshArg::Classic => gradmesh::render::SvgMeshRendering::Classic,
            SvgMeshArg::Scheme => gradmesh::render::SvgMeshRendering::Scheme,
        }
    }
}

/// `--png-compression`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PngCompressionArg {
    /// Every row Sub-filtered, a fixed Huffman code, compressed on every core.
    Fast,
    /// The filter chosen row by row, zlib's best level.
    Best,
}

impl From<PngCompressionArg> for gradmesh::render::PngCompression {
    fn from(c: PngCompressionArg) -> Self {
        match c {
            PngCompressionArg::Fast => gradmesh::render::PngCompression::Fast,
            PngCompressionArg::Best => gradmesh::render::PngCompression::Best,
        }
    }
}

/// `--gamut`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum GamutArg {
    /// Reduce chroma in Oklch until the colour fits (CSS Color 4).
    Chroma,
    /// Clip each channel.
    Clip,
}

impl From<GamutArg> for GamutMapping {
    fn from(gamut: GamutArg) -> Self {
        match gamut {
            GamutArg::Chroma => GamutMapping::Chroma,
            GamutArg::Clip => GamutMapping::Clip,
        }
    }
}

/// `gradmesh info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Input files (.json, .off, .obj, .svg, .pdf, .ai).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// The page of a PDF input.
    #[command(flatten)]
    pub page: PageArg,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `gradmesh edits`.
#[derive(Debug, Args)]
pub struct EditsArgs {
    /// Input file (.json).
    pub input: PathBuf,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `gradmesh convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input file (.json, .off, .obj, .svg, .pdf, .ai).
    pub input: PathBuf,
    /// Output file (.json).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Allow the output to be the input file itself.
    #[arg(long)]
    pub force: bool,
    /// Fit each layer's control colours, and refined-level colour edits where they do not
    /// suffice, by least squares to the classic painting of the mesh gradient (SVG) or
    /// patch-mesh shading (PDF) it came from, so that the scheme looks as the file does.
    #[arg(long)]
    pub fit: bool,
    /// The paper's options.
    #[command(flatten)]
    pub variant: VariantArgs,
    /// The page of a PDF input.
    #[command(flatten)]
    pub page: PageArg,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `gradmesh refine`.
#[derive(Debug, Args)]
pub struct RefineArgs {
    /// Input file (.json, .off, .obj, .svg, .pdf, .ai).
    pub input: PathBuf,
    /// Output file: .obj (`v x y 0 c1 c2 c3` and `f` lines) or .json.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Level: 0 is the input, 1 the ternary step, k the ternary step and k-1 Catmull-Clark steps.
    #[arg(short, long, default_value_t = 3)]
    pub levels: usize,
    /// Write limit positions and colours instead of control points.
    #[arg(long)]
    pub limit: bool,
    /// Allow the output to be the input file itself.
    #[arg(long)]
    pub force: bool,
    /// The paper's options.
    #[command(flatten)]
    pub variant: VariantArgs,
    /// Deepest refinement level accepted.
    #[arg(long, value_name = "LEVEL", help_heading = "Limits", default_value_t = Limits::DEFAULT.refinement_level)]
    pub max_level: usize,
    /// Most faces of the deepest level, estimated before refining.
    #[arg(long, value_name = "N", help_heading = "Limits", default_value_t = Limits::DEFAULT.refined_faces)]
    pub max_refined_faces: u64,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `gradmesh vectorise`.
#[derive(Debug, Args)]
pub struct VectoriseArgs {
    /// The picture (.png or .jpg); its pixels are the output's coordinates.
    pub input: PathBuf,
    /// Output file (.json): one mesh covering the picture, or its opaque part where some pixels
    /// are transparent.
    #[arg(short, long)]
    pub output: PathBuf,
    /// The most control points (default 1024 when --psnr is not given either).
    #[arg(long, value_name = "N")]
    pub points: Option<usize>,
    /// Stop once the fit reaches this PSNR in dB (or at --points, if given, first).
    #[arg(long, value_name = "DB")]
    pub psnr: Option<f64>,
    /// The time spent on the fit.
    #[arg(long, value_enum, default_value_t = QualityArg::Default)]
    pub quality: QualityArg,
    /// Allow the output to be the input file itself.
    #[arg(long)]
    pub force: bool,
    /// Largest picture decoded, in pixels (checked in the file's header first).
    #[arg(long, value_name = "N", help_heading = "Limits", default_value_t = gradmesh::MAX_IMAGE_PIXELS)]
    pub max_pixels: u64,
    /// Largest input file, in bytes.
    #[arg(long, value_name = "BYTES", help_heading = "Limits", default_value_t = gradmesh::MAX_IMAGE_BYTES)]
    pub max_input_bytes: u64,
}

/// `--quality` of `gradmesh vectorise`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum QualityArg {
    /// Coarse sampling, large rounds.
    Fast,
    /// The balance of time and accuracy.
    Default,
    /// Finer sampling, smaller rounds.
    Best,
}

impl From<QualityArg> for gradmesh::Quality {
    fn from(q: QualityArg) -> Self {
        match q {
            QualityArg::Fast => gradmesh::Quality::Fast,
            QualityArg::Default => gradmesh::Quality::Default,
            QualityArg::Best => gradmesh::Quality::Best,
        }
    }
}

/// `gradmesh render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Input files (.json, .off, .obj, .svg, .pdf, .ai), drawn in order: the first at the bottom.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output file: .png (pixels), .pdf (tensor-product patch shadings) or .svg (mesh
    /// gradients over a PNG fallback).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image width in pixels (with only --height, derived from the view's aspect ratio).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (with only --width, derived from the view's aspect ratio).
    #[arg(long)]
    pub height: Option<u32>,
    /// The rectangle of the plane shown: X0 Y0 is the top-left corner, y grows downward; for
    /// an SVG file, in its user units. Default: the first input's view box if it is an SVG
    /// file, else the bounds of the meshes.
    #[arg(long, num_args = 4, value_names = ["X0", "Y0", "X1", "Y1"], allow_negative_numbers = true)]
    pub view: Option<Vec<f64>>,
    /// Background colour (a CSS colour such as white or #202020); default transparent.
    #[arg(long)]
    pub background: Option<String>,
    /// Bits per channel of the PNG: 8 or 16.
    #[arg(long, default_value_t = 8, value_parser = clap::builder::PossibleValuesParser::new(["8", "16"]).map(|s| s.parse::<u8>().unwrap()))]
    pub bits: u8,
    /// Do not dither 8-bit output.
    #[arg(long)]
    pub no_dither: bool,
    /// Compression of 8-bit PNG: fast (on every core), or best (a smaller file, about ten
    /// times the encoding time).
    #[arg(long, value_name = "LEVEL", default_value = "fast")]
    pub png_compression: PngCompressionArg,
    /// Interpolate colour linearly over every triangle (no quadratic faces: more triangles).
    #[arg(long)]
    pub linear_colour: bool,
    /// Draw the outline of each mesh on top, one pixel wide.
    #[arg(long)]
    pub boundary: bool,
    /// Interpolate in this colour space instead of each mesh's own.
    #[arg(long, value_name = "SPACE")]
    pub colour_space: Option<ColourSpaceArg>,
    /// Gamut mapping of out-of-gamut colours.
    #[arg(long, default_value = "chroma")]
    pub gamut: GamutArg,
    /// How the mesh gradients of SVG inputs and the patch-mesh shadings of PDF inputs are
    /// drawn, each clipped to its shape: `classic` as Inkscape paints them and as the PDF
    /// specification defines them, `scheme` converted into the scheme (the layers `convert`
    /// writes). PDF and SVG output of an SVG input with `classic` write the meshes' own patches;
    /// those of a PDF input take the scheme.
    #[arg(long, value_name = "MODE", default_value = "classic")]
    pub svg_mesh: SvgMeshArg,
    /// Slow and simple reference rendering (for checking the fast path).
    #[arg(long)]
    pub reference: bool,
    /// Refine to this level instead of choosing one from the image size.
    #[arg(long)]
    pub level: Option<usize>,
    /// PDF and SVG: largest colour difference (ΔE00) between a viewer's bilinear colour and
    /// the surface's.
    #[arg(long, value_name = "DELTA_E", default_value_t = gradmesh::export::DEFAULT_TOLERANCE, help_heading = "Vector output")]
    pub tolerance: f64,
    /// PDF and SVG: largest distance, in pixels, between the flat patches at the surface's irregular
    /// spots and the surface.
    #[arg(long, value_name = "PX", default_value_t = gradmesh::export::DEFAULT_GEOMETRY_TOLERANCE_PX, help_heading = "Vector output")]
    pub geometry_tolerance: f64,
    /// PDF: the shadings' colour space (sRGB, drawn alike by every viewer; or Lab, for viewers
    /// that interpolate in Lab and convert it exactly).
    #[arg(
        long,
        value_name = "SPACE",
        default_value = "srgb",
        help_heading = "Vector output"
    )]
    pub pdf_colour: PdfColourArg,
    /// SVG: leave out the PNG of the picture beneath the mesh gradients (shown by viewers
    /// without mesh gradients, such as browsers).
    #[arg(long, help_heading = "Vector output")]
    pub no_fallback: bool,
    /// Print the time each stage took, and the level drawn for each layer.
    #[arg(long)]
    pub timings: bool,
    /// The largest image accepted, in pixels (refused before anything is allocated).
    #[arg(long, value_name = "N", default_value_t = gradmesh::render::MAX_PIXELS, help_heading = "Limits")]
    pub max_pixels: u64,
    /// The most memory, in bytes, that drawing an SVG file's whole picture may need (estimated
    /// before it is drawn) [default: the machine's memory, MemTotal in /proc/meminfo].
    #[arg(long, value_name = "BYTES", help_heading = "Limits")]
    pub max_memory: Option<u64>,
    /// Allow the output to be one of the input files.
    #[arg(long)]
    pub force: bool,
    /// The paper's options.
    #[command(flatten)]
    pub variant: VariantArgs,
    /// The page of a PDF input.
    #[command(flatten)]
    pub page: PageArg,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}
