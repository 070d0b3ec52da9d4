//! Other sources of triangles for the same rasteriser: SVG mesh gradients painted classically
//! and PDF patch-mesh shadings painted as the PDF specification defines them.

pub(super) mod classic;
pub(super) mod patches;
