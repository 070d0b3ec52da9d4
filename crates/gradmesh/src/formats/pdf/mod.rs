//! Reading the patch-mesh shadings (types 6 and 7) of a PDF page, or of an Illustrator file
//! that is PDF inside, into a normalised [`PdfPicture`], and converting them into layers of
//! the scheme.
//!
//! lopdf reads the file's objects (cross-reference tables and streams, object streams, the
//! filters of streams, with a repair of broken cross-reference data); the content streams are
//! interpreted and the shading streams decoded here (the `pdf-read` feature: [`read_pdf`] and
//! [`read_path_with_limits`]; the patches, their conversion and their drawing are always here).
//! What is read and how is in `docs/pdf.md`.

#[cfg(feature = "pdf-read")]
mod bits;
mod colour;
#[cfg(feature = "pdf-read")]
mod content;
mod convert;
#[cfg(feature = "pdf-read")]
mod functions;
#[cfg(feature = "pdf-read")]
mod objects;
mod postscript;
#[cfg(feature = "pdf-read")]
mod read;
mod scene;
#[cfg(feature = "pdf-read")]
mod shading;
#[cfg(feature = "pdf-read")]
mod spaces;

pub use colour::{Function, PdfColourSpace, ShadingColour};
pub use convert::{fill_to_layer, picture_to_document};
pub use postscript::Program as PostScriptProgram;
#[cfg(feature = "pdf-read")]
pub use read::{read_path_with_limits, read_pdf, PdfDocument};
pub(crate) use scene::coons_interior;
pub(crate) use scene::POINT_ORDER;
pub use scene::{Patch, PdfPicture, ShadingFill};

/// Whether `bytes` start like a PDF file (`%PDF-` within the first kilobyte, as viewers
/// accept it; Illustrator's `.ai` files saved with PDF compatibility do).
pub fn is_pdf(bytes: &[u8]) -> bool {
    bytes[..bytes.len().min(1024)]
        .windows(5)
        .any(|w| w == b"%PDF-")
}

#[cfg(all(test, feature = "pdf-read"))]
mod tests;
