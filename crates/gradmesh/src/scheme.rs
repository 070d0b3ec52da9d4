//! The scheme's options, shared by every layer above: how boundaries, semi-sharp creases and
//! the first refinement step behave (OpenSubdiv's `Sdc` options, and the paper's first step).

/// Sharpness at or above this value is infinite (OpenSubdiv's `SHARPNESS_INFINITE`).
pub const SHARPNESS_INFINITE: f64 = 10.0;

/// How the boundary of a mesh is refined (OpenSubdiv's `VtxBoundaryInterpolation`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundaryInterpolation {
    /// Boundary edges are sharp and boundary points with a single face are corners (the default,
    /// and what the paper's authors do: a rectangle keeps its corners).
    #[default]
    EdgeAndCorner,
    /// Boundary edges are sharp; every boundary point follows the B-spline rule.
    EdgeOnly,
}

impl BoundaryInterpolation {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            BoundaryInterpolation::EdgeAndCorner => "edge-and-corner",
            BoundaryInterpolation::EdgeOnly => "edge-only",
        }
    }
}

/// How the sharpness of semi-sharp edges decreases from one level to the next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CreasingMethod {
    /// Subtract one at each level.
    #[default]
    Uniform,
    /// Chaikin's rule: blend with the sharpness of neighbouring semi-sharp edges, then subtract one.
    Chaikin,
}

impl CreasingMethod {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CreasingMethod::Uniform => "uniform",
            CreasingMethod::Chaikin => "chaikin",
        }
    }
}

/// The special first refinement that makes colours interpolating (paper sections 4.3 and 4.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FirstStep {
    /// One linear ternary split (the paper's choice, the default): a face of `n` corners
    /// becomes a central `n`-gon surrounded by `2 n` quads.
    #[default]
    Ternary,
    /// Two linear binary splits (the paper's alternative): a face of `n` corners becomes `4 n`
    /// quads, with more points to place (see `docs/binary-step.md`).
    Binary,
}

impl FirstStep {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FirstStep::Ternary => "ternary",
            FirstStep::Binary => "binary",
        }
    }
}

/// The largest magnitude of a coordinate, handle component or colour channel: the refinement
/// squares differences of positions, which overflow beyond about 1e154.
pub const MAX_MAGNITUDE: f64 = 1e150;

/// The largest magnitude of a coordinate of a mesh with
/// `GradientMesh::interpolate_positions`: the correction measures each point's weight by
/// moving it one unit, which is lost in rounding at larger coordinates.
pub const MAX_INTERPOLATED_MAGNITUDE: f64 = 1e12;

/// The shortest edge refined: squared lengths of shorter edges underflow to zero.
pub const MIN_EDGE_LENGTH: f64 = 1e-150;

/// The most times a handle may be longer than its edge: the ternary step multiplies the two
/// ratios of a corner's handles, which must stay far from overflow. (Handles longer than half
/// their edge are already warned about.)
pub const MAX_HANDLE_RATIO: f64 = 1e50;
