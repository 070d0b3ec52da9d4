//! Tessellation: the planned faces' triangles stitched without cracks, and a layer prepared for
//! drawing (triangles binned to bands, the exact outline, the nearest boundary point).

pub(super) mod adaptive;
pub(super) mod clip;
pub(super) mod layer;
pub(super) mod nearest;
pub(super) mod outline;
pub(super) mod stitch;
