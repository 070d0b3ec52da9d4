//! Reading SVG mesh gradients (`<meshgradient>`, SVG 2 draft and Inkscape) into a normalised
//! [`SvgScene`], and converting them into layers of the scheme.
//!
//! What is read and how it maps is in `docs/svg.md`. The XML is parsed by `roxmltree`, the
//! attribute values by `svgtypes`, the outlines by kurbo.
//!
//! ```
//! use gradmesh::formats::svg;
//!
//! let text = r##"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
//!   <meshgradient id="m" x="0" y="0" gradientUnits="userSpaceOnUse">
//!     <meshrow><meshpatch>
//!       <stop path="l 100,0" stop-color="#f00"/>
//!       <stop path="l 0,100" stop-color="#0f0"/>
//!       <stop path="l -100,0" stop-color="#00f"/>
//!       <stop path="l 0,-100" stop-color="#ff0"/>
//!     </meshpatch></meshrow>
//!   </meshgradient>
//!   <rect width="100" height="100" fill="url(#m)"/>
//! </svg>"##;
//! let scene = svg::read_svg(text)?;
//! // The stops go round the patch from its top-left corner: the third is the bottom right.
//! assert_eq!(scene.fills[0].mesh.corner(1, 1).colour, [0.0, 0.0, 1.0]);
//! let (doc, warnings) = svg::scene_to_document(&scene, gradmesh::ColourSpace::Lab);
//! assert_eq!((doc.layers[0].points.len(), doc.layers[0].faces.len()), (4, 1));
//! assert!(warnings.is_empty());
//! # Ok::<(), gradmesh::Error>(())
//! ```

mod attr;
mod convert;
mod gradient;
mod lines;
mod mask;
pub(crate) mod paint;
mod read;
mod scene;
mod shape;

use std::path::Path;

pub use convert::{fill_to_layer, scene_to_document};
pub use read::{read_svg_with_limits, MAX_DEPTH};
pub use scene::{
    AspectRatio, Corner, FillRule, MeshFill, MeshGrid, MeshType, SvgScene, DEFAULT_SIZE,
};

use crate::colour::ColourSpace;
use crate::error::{Error, ErrorKind, Warning};
use crate::mesh::Document;
use crate::size_limits::Limits;

/// Reads an SVG document within the default [`Limits`].
pub fn read_svg(text: &str) -> Result<SvgScene, Error> {
    read_svg_with_limits(text, &Limits::DEFAULT)
}

/// An SVG file's mesh-gradient fills as a document, with the part of the plane the file shows.
#[derive(Clone, Debug)]
pub struct SvgDocument {
    /// One layer per shape filled with a mesh gradient, bottom first.
    pub document: Document,
    /// What was left out, naming the element.
    pub warnings: Vec<Warning>,
    /// The rectangle of user space the picture shows ([`SvgScene::view_rect`]).
    pub view: kurbo::Rect,
    /// The picture's size in CSS pixels ([`SvgScene::pixel_size`]).
    pub pixel_size: (f64, f64),
    /// The fills the layers were converted from, `fills[i]` for layer `i`: their clips, and
    /// what the classic rendering draws.
    pub fills: Vec<MeshFill>,
}

/// Reads an SVG document and converts every mesh-gradient fill into a layer with colours in
/// `space`, within `limits` (each layer is checked as any mesh read is). A file without any
/// mesh-gradient fill is an error. The warnings name what was left out.
pub fn read_document_with_limits(
    text: &str,
    space: ColourSpace,
    limits: &Limits,
) -> Result<SvgDocument, Error> {
    let scene = read_svg_with_limits(text, limits)?;
    if scene.fills.is_empty() {
        return Err(ErrorKind::Invalid {
            what: "the SVG document".into(),
            message: "no shape is filled with a mesh gradient".into(),
        }
        .into());
    }
    let (doc, warnings) = scene_to_document(&scene, space);
    for (i, mesh) in doc.layers.iter().enumerate() {
        limits.check_mesh(mesh).map_err(|e| e.in_layer(i))?;
    }
    Ok(SvgDocument {
        document: doc,
        warnings,
        view: scene.view_rect(),
        pixel_size: scene.pixel_size(),
        fills: scene.fills,
    })
}

/// Reads an SVG file as [`read_document_with_limits`] does, in Lab; the layers are named after their
/// gradients. A file larger than [`Limits::input_bytes`] is refused before it is read; every
/// error is located in the file.
pub fn read_path_with_limits(path: &Path, limits: &Limits) -> Result<SvgDocument, Error> {
    let text = super::read_text(path, limits.input_bytes).map_err(|e| e.in_file(path))?;
    read_document_with_limits(&text, ColourSpace::Lab, limits).map_err(|e| e.in_file(path))
}

#[cfg(test)]
mod tests;
