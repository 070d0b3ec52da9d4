//! Command-line flags.

use std::path::PathBuf;

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
}

/// `gradmesh info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Input files (.json, .off, .obj).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
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
}
