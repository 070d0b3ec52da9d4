//! Command-line flags.

use std::path::PathBuf;

use clap::builder::TypedValueParser as _;
use clap::{Args, Parser, Subcommand};

/// Gradient meshes of arbitrary topology (Lieng, Kosinka, Shen & Dodgson 2017).
#[derive(Debug, Parser)]
#[command(name = "gradmesh", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print counts, face sizes, valences, bounds, colour space and warnings of meshes.
    Info(InfoArgs),
    /// Convert a mesh (.json, .off, .obj) to the native JSON format.
    Convert(ConvertArgs),
    /// Write the refined control mesh (or its limit points) at a given level.
    Refine(RefineArgs),
    /// Render the limit surface of meshes, drawn in order as layers, to a PNG.
    Render(RenderArgs),
    /// List the multi-resolution edits of a mesh: the vertex each names, and what it changes.
    Edits(EditsArgs),
}

/// Limits on the input (`gradmesh::Limits`), raised for trusted input.
/// The paper's options (section 4.5), applied to every layer; without them each layer keeps
/// what its file says.
#[derive(Debug, Args)]
#[command(next_help_heading = "Scheme options")]
pub struct VariantArgs {
    /// Make the limit surface pass through the control points.
    #[arg(long)]
    pub interpolate_positions: bool,
    /// The first refinement: ternary (the paper's) or binary (two binary splits).
    #[arg(long, value_name = "STEP", value_parser = ["ternary", "binary"])]
    pub first_step: Option<String>,
}

impl VariantArgs {
    /// Applies the options to every layer of `doc`.
    pub fn apply(&self, doc: &mut gradmesh::Document) {
        for mesh in &mut doc.layers {
            if self.interpolate_positions {
                mesh.interpolate_positions = true;
            }
            match self.first_step.as_deref() {
                Some("binary") => mesh.first_step = gradmesh::FirstStep::Binary,
                Some("ternary") => mesh.first_step = gradmesh::FirstStep::Ternary,
                _ => {}
            }
        }
    }
}

#[derive(Debug, Args)]
#[command(next_help_heading = "Limits")]
pub struct LimitArgs {
    /// Largest input file, in bytes [default: 268435456].
    #[arg(long, value_name = "BYTES")]
    pub max_input_bytes: Option<u64>,
    /// Most control points in one mesh [default: 16777216].
    #[arg(long, value_name = "N")]
    pub max_points: Option<u64>,
    /// Most faces in one mesh [default: 16777216].
    #[arg(long, value_name = "N")]
    pub max_faces: Option<u64>,
    /// Most face corners in one mesh [default: 67108864].
    #[arg(long, value_name = "N")]
    pub max_corners: Option<u64>,
}

impl LimitArgs {
    /// The default limits, with the flags given.
    pub fn limits(&self) -> gradmesh::Limits {
        let d = gradmesh::Limits::DEFAULT;
        gradmesh::Limits {
            input_bytes: self.max_input_bytes.unwrap_or(d.input_bytes),
            points: self.max_points.unwrap_or(d.points),
            faces: self.max_faces.unwrap_or(d.faces),
            corners: self.max_corners.unwrap_or(d.corners),
            ..d
        }
    }
}

/// `gradmesh info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Input files (.json, .off, .obj).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
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
    /// Input file (.json, .off, .obj).
    pub input: PathBuf,
    /// Output file (.json).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Allow the output to be the input file itself.
    #[arg(long)]
    pub force: bool,
    /// The paper's options.
    #[command(flatten)]
    pub variant: VariantArgs,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `gradmesh refine`.
#[derive(Debug, Args)]
pub struct RefineArgs {
    /// Input file (.json, .off, .obj).
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
    /// Deepest refinement level accepted [default: 12].
    #[arg(long, value_name = "LEVEL", help_heading = "Limits")]
    pub max_level: Option<usize>,
    /// Most faces of the deepest level, estimated before refining [default: 8388608].
    #[arg(long, value_name = "N", help_heading = "Limits")]
    pub max_refined_faces: Option<u64>,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// `gradmesh render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Input files (.json, .off, .obj), drawn in order: the first at the bottom.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output file (.png).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image width in pixels (with only --height, derived from the view's aspect ratio).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (with only --width, derived from the view's aspect ratio).
    #[arg(long)]
    pub height: Option<u32>,
    /// The rectangle of the plane shown: X0 Y0 is the top-left corner, y grows downward.
    /// Default: the bounds of the meshes.
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
    /// Interpolate colour linearly over every triangle (no quadratic faces: more triangles, as before 2026-12).
    #[arg(long)]
    pub linear_colour: bool,
    /// Draw the outline of each mesh on top, one pixel wide.
    #[arg(long)]
    pub boundary: bool,
    /// Interpolate in this colour space instead of each mesh's own: lab, oklab, srgb-linear, srgb.
    #[arg(long)]
    pub colour_space: Option<String>,
    /// Gamut mapping of out-of-gamut colours: chroma (reduce chroma in Oklch) or clip.
    #[arg(long)]
    pub gamut: Option<String>,
    /// Slow and simple reference rendering (for checking the fast path).
    #[arg(long)]
    pub reference: bool,
    /// Refine to this level instead of choosing one from the image size.
    #[arg(long)]
    pub level: Option<usize>,
    /// Print the time each stage took, and the level drawn for each layer.
    #[arg(long)]
    pub timings: bool,
    /// The largest image accepted, in pixels (refused before anything is allocated).
    #[arg(long, value_name = "N", default_value_t = gradmesh::render::MAX_PIXELS, help_heading = "Limits")]
    pub max_pixels: u64,
    /// Allow the output to be one of the input files.
    #[arg(long)]
    pub force: bool,
    /// The paper's options.
    #[command(flatten)]
    pub variant: VariantArgs,
    /// Limits.
    #[command(flatten)]
    pub limits: LimitArgs,
}
