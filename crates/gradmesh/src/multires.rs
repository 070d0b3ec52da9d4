//! Multi-resolution edits as data: the name of a refined vertex and what changes there. How
//! they are checked is in `edit_check`, how they are applied in `edits`; the module
//! documentation of `edits` describes the addressing and what an edit does.

use std::fmt;

use kurbo::Vec2;

/// The deepest level an edit may name (a sector then has 3 * 2^6 = 192 quads a side).
pub const MAX_EDIT_LEVEL: u32 = 8;

/// The name of a vertex of a refined level, through the coarse face and corner it lies in
/// (`docs/format.md`, section 1.5, describes the addressing and what an edit does).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VertexAddress {
    /// The level, 1 (after the ternary step) or deeper.
    pub level: u32,
    /// The coarse face.
    pub face: u32,
    /// The control point at the sector's corner: a corner of `face`.
    pub point: u32,
    /// Coordinates in the sector's grid at `level`, each in `0..=sector_size(level)`.
    pub at: [u32; 2],
}

impl VertexAddress {
    /// The vertex `at` of the sector of `face` at corner `point`, at `level`.
    pub fn new(level: u32, face: u32, point: u32, at: [u32; 2]) -> Self {
        VertexAddress {
            level,
            face,
            point,
            at,
        }
    }

    /// The largest coordinate of a sector's grid at `level`: 1 at level 1, `3 * 2^(level - 2)`
    /// below.
    pub fn sector_size(level: u32) -> u32 {
        if level <= 1 {
            1
        } else {
            3 << (level - 2).min(29)
        }
    }
}

impl fmt::Display for VertexAddress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "level {}, face {} at point {}, [{}, {}]",
            self.level, self.face, self.point, self.at[0], self.at[1]
        )
    }
}

/// A change of colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColourEdit {
    /// Added to the colour the subdivision gives at the vertex (in the mesh's colour space).
    Offset([f64; 3]),
    /// The colour, outright.
    Set([f64; 3]),
}

/// A change of opacity (the result is clamped to 0..=1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OpacityEdit {
    /// Added to the opacity the subdivision gives at the vertex.
    Offset(f64),
    /// The opacity, outright.
    Set(f64),
}

/// One multi-resolution edit: what changes at one refined vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct Edit {
    /// The vertex.
    pub address: VertexAddress,
    /// Its new colour, if it changes.
    pub colour: Option<ColourEdit>,
    /// Its new opacity, if it changes.
    pub opacity: Option<OpacityEdit>,
    /// Its move, in its local frame (see the module documentation of `edits`).
    pub offset: Option<Vec2>,
}

impl Edit {
    /// An edit of the vertex at `address` that changes nothing yet.
    pub fn new(address: VertexAddress) -> Self {
        Edit {
            address,
            colour: None,
            opacity: None,
            offset: None,
        }
    }

    /// Whether the edit changes colour or opacity (and so flattens the ring after the next step).
    pub fn changes_colour(&self) -> bool {
        self.colour.is_some() || self.opacity.is_some()
    }
}

/// Which edits a mesh allows below level 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FineEdits {
    /// Colour, opacity and position (the default).
    #[default]
    ColourAndPosition,
    /// Colour and opacity only: geometry is edited on the control mesh (the paper's artistic
    /// mode, Figure 10).
    ColourOnly,
}

impl FineEdits {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FineEdits::ColourAndPosition => "colour-and-position",
            FineEdits::ColourOnly => "colour-only",
        }
    }
}
