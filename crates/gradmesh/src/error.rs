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

/// Something legal but suspicious in the input.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// The layer, when the document has several.
    pub layer: Option<usize>,
    /// What was noticed, naming the element.
    pub message: String,
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
