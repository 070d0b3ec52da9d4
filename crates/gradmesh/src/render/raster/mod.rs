//! Rasterisation: spans of snapped triangles with the top-left rule, exact-area coverage of the
//! outline.

pub(super) mod coverage;
pub(super) mod triangles;
