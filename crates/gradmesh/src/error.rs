//! Errors and warnings that say what is wrong and where.

use std::fmt;
use std::path::PathBuf;

/// Where in the input a problem lies.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Location {
    /// The file, when the input came from one.
    pub file: Option<PathBuf>,
    /// The layer (mesh) of a document, when it has several.
    pub layer: Option<usize>,
    /// The line of a text file (1-based).
    pub line: Option<usize>,
}

impl Location {
    /// A location in a file.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Location {
            file: Some(path.into()),
            ..Location::default()
        }
    }

    /// This location at a line.
    pub fn at_line(&self, line: usize) -> Self {
        Location {
            line: Some(line),
            ..self.clone()
        }
    }

    fn is_empty(&self) -> bool {
        self.file.is_none() && self.layer.is_none() && self.line.is_none()
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut sep = "";
        if let Some(file) = &self.file {
            write!(f, "{}", file.display())?;
            sep = ":";
        }
        if let Some(line) = self.line {
            write!(f, "{sep}{line}")?;
            sep = ":";
        }
        if let Some(layer) = self.layer {
            if sep.is_empty() {
                write!(f, "layer {layer}")?;
            } else {
                write!(f, "{sep} layer {layer}")?;
            }
        }
        Ok(())
    }
}

/// What is wrong with a mesh or a file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The text of a file does not follow its format.
    #[error("{0}")]
    Syntax(String),
    /// A number is NaN or infinite.
    #[error("{what} is not a finite number ({value})")]
    NotFinite {
        /// What the number is (for example `point 4 x`).
        what: String,
        /// The offending value, as text.
        value: String,
    },
    /// A face refers to a point that does not exist.
    #[error(
        "face {face}: corner {corner} refers to point {index}, but there are only {count} points"
    )]
    IndexOutOfRange {
        /// Face index.
        face: usize,
        /// Corner within the face.
        corner: usize,
        /// The index found.
        index: u64,
        /// Number of points.
        count: usize,
    },
    /// A face has fewer than three distinct corners, or repeats a point.
    #[error("face {face}: {reason}")]
    DegenerateFace {
        /// Face index.
        face: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// An edge joins two points at the same position.
    #[error("edge {a}-{b} has zero length (both points at ({x}, {y}))")]
    ZeroLengthEdge {
        /// First point.
        a: u32,
        /// Second point.
        b: u32,
        /// Position x.
        x: f64,
        /// Position y.
        y: f64,
    },
    /// More than two faces share an edge.
    #[error("edge {a}-{b} is non-manifold: it is shared by faces {faces:?}")]
    NonManifoldEdge {
        /// First point.
        a: u32,
        /// Second point.
        b: u32,
        /// The faces that share it.
        faces: Vec<usize>,
    },
    /// The faces around a point do not form a single fan.
    #[error("point {point} is non-manifold: its faces form {fans} separate fans")]
    NonManifoldVertex {
        /// The point.
        point: u32,
        /// Number of fans found.
        fans: usize,
    },
    /// Two faces traverse their shared edge in the same direction.
    #[error("faces {face_a} and {face_b} are wound inconsistently: both run edge {a}->{b} in the same direction")]
    InconsistentWinding {
        /// First face.
        face_a: usize,
        /// Second face.
        face_b: usize,
        /// Edge start.
        a: u32,
        /// Edge end.
        b: u32,
    },
    /// A handle or tag names an edge that no face has.
    #[error("{what} names edge {a}-{b}, which is not an edge of any face")]
    NoSuchEdge {
        /// What names the edge (`handle`, `edge tag`, ...).
        what: String,
        /// First point.
        a: u32,
        /// Second point.
        b: u32,
    },
    /// A value is outside its allowed range.
    #[error("{what}: {message}")]
    Invalid {
        /// The element concerned.
        what: String,
        /// What was expected and what was found.
        message: String,
    },
    /// A limit protecting against runaway input was exceeded.
    #[error(
        "{what} is {}, above the limit of {}",
        group_digits(*.found),
        group_digits(*.limit)
    )]
    LimitExceeded {
        /// What was counted.
        what: String,
        /// The amount requested.
        found: u64,
        /// The limit.
        limit: u64,
    },
    /// A file's extension names no format that the operation reads or writes.
    #[error("{0}")]
    UnsupportedFormat(String),
    /// Reading or writing a file failed.
    #[error("{0}")]
    Io(String),
}

/// An error with the place it occurred.
#[derive(Clone, Debug, PartialEq)]
pub struct Error {
    /// Where.
    pub location: Location,
    /// What.
    pub kind: ErrorKind,
}

impl Error {
    /// An error without a location yet.
    pub fn new(kind: ErrorKind) -> Self {
        Error {
            location: Location::default(),
            kind,
        }
    }

    /// A syntax error at a line of a file.
    pub fn syntax(location: &Location, line: usize, message: impl Into<String>) -> Self {
        Error {
            location: location.at_line(line),
            kind: ErrorKind::Syntax(message.into()),
        }
    }

    /// The same error, located in `file` (kept if a file is already set).
    pub fn in_file(mut self, file: impl Into<PathBuf>) -> Self {
        if self.location.file.is_none() {
            self.location.file = Some(file.into());
        }
        self
    }

    /// The same error, located in layer `layer`.
    pub fn in_layer(mut self, layer: usize) -> Self {
        self.location.layer = Some(layer);
        self
    }
}

impl From<ErrorKind> for Error {
    fn from(kind: ErrorKind) -> Self {
        Error::new(kind)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.location.is_empty() {
            write!(f, "{}", self.kind)
        } else {
            write!(f, "{}: {}", self.location, self.kind)
        }
    }
}

impl std::error::Error for Error {}

/// What kind of thing a [`Warning`] is about, so that a program can count warnings by kind
/// without reading their text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum WarningKind {
    /// A handle longer than half its edge: the surface may fold there.
    HandleMayFold,
    /// The surface folds over itself (as `render::find_folds` finds).
    Fold,
    /// A control point's colour lies outside the sRGB gamut.
    OutsideGamut,
    /// A point that no face uses.
    UnusedPoint,
    /// A wedge entry on a point that is on no discontinuous edge.
    WedgeEntryWithoutDiscontinuity,
    /// Multi-resolution edits below the level written, which have no effect on it.
    EditsBelowLevel,
    /// Content of an SVG file that is not a mesh-gradient fill (other shapes, other paints):
    /// left out of the meshes.
    SvgNotMeshFill,
    /// A mesh gradient or one of its patches left out (no area to draw).
    SvgMeshLeftOut,
    /// Something in an SVG file ignored or read differently from what it says (an invalid view
    /// box, an unknown mesh type, extra stops, corners merged).
    SvgReadDifferently,
    /// Content of a PDF page that is not a patch-mesh shading, or a shading or part of one
    /// read differently from what the file says (an unsupported colour space, a second clip).
    PdfLeftOut,
}

impl WarningKind {
    /// `count` warnings of this kind in a few words: "3 handles may fold".
    pub fn counted(self, count: usize) -> String {
        let one = count == 1;
        let (singular, plural) = match self {
            WarningKind::HandleMayFold => ("handle may fold", "handles may fold"),
            WarningKind::Fold => ("fold", "folds"),
            WarningKind::OutsideGamut => ("colour outside sRGB", "colours outside sRGB"),
            WarningKind::UnusedPoint => ("point on no face", "points on no face"),
            WarningKind::WedgeEntryWithoutDiscontinuity => (
                "wedge entry on no discontinuous edge",
                "wedge entries on no discontinuous edge",
            ),
            WarningKind::EditsBelowLevel => (
                "edit level below the level written",
                "edit levels below the level written",
            ),
            WarningKind::SvgNotMeshFill => (
                "part that is not a mesh gradient left out",
                "parts that are not mesh gradients left out",
            ),
            WarningKind::SvgMeshLeftOut => ("mesh part left out", "mesh parts left out"),
            WarningKind::SvgReadDifferently => (
                "SVG attribute ignored or read differently",
                "SVG attributes ignored or read differently",
            ),
            WarningKind::PdfLeftOut => (
                "PDF part left out or read differently",
                "PDF parts left out or read differently",
            ),
        };
        format!("{count} {}", if one { singular } else { plural })
    }
}

/// Something legal but suspicious in the input.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// The layer, when the document has several.
    pub layer: Option<usize>,
    /// What it is about.
    pub kind: WarningKind,
    /// What was noticed, naming the element.
    pub message: String,
    /// How many things of its kind it reports: 1, or more for a warning that sums up the
    /// rest of a long list ("12 more points ...").
    pub count: usize,
}

impl Warning {
    /// A warning about one thing, in no particular layer.
    pub fn new(kind: WarningKind, message: impl Into<String>) -> Self {
        Warning {
            layer: None,
            kind,
            message: message.into(),
            count: 1,
        }
    }

    /// The same warning, standing for `count` things of its kind.
    pub fn counting(self, count: usize) -> Self {
        Warning { count, ..self }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.layer {
            Some(l) => write!(f, "layer {l}: {}", self.message),
            None => write!(f, "{}", self.message),
        }
    }
}

/// Result with this crate's error.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// `1234567` as `1,234,567`.
pub fn group_digits(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, ch) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    out
}
