//! The whole picture of an SVG file whose mesh-gradient fills gradmesh reads: what is not a
//! mesh fill (other shapes, paints, text, images) drawn by resvg, guarded against its panics
//! and its allocations beyond the limits.
//!
//! [`render_whole_picture`] composites the mesh layers between that content in paint order
//! (`gradmesh render drawing.svg`); [`render_backdrop`] draws that content alone, the mesh
//! fills left out (the editor's locked backdrop under its layers).

pub mod resvg_guard;
mod whole_picture;

pub use whole_picture::{
    bytes_per_pixel, missing_images, render_backdrop, render_whole_picture, WholePicture,
};
