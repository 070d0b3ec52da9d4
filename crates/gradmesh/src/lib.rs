//! gradmesh: gradient meshes of arbitrary manifold topology.
//!
//! The pipeline follows Lieng, Kosinka, Shen and Dodgson, "A Colour Interpolation Scheme for
//! Topologically Unrestricted Gradient Meshes" (Computer Graphics Forum 36(6), 2017):
//!
//! 1. [`GradientMesh`]: control points with colours, handles and edge tags, checked by
//!    [`validate`];
//! 2. [`ternary_step`]: the special first refinement that makes colours interpolating;
//! 3. [`catmull_clark`]: Catmull-Clark refinement with Pixar's rules, topology refined once and
//!    data interpolated with precomputed stencils;
//! 4. [`limit`]: limit positions and colours of refined vertices.

pub mod catmull_clark;
pub mod colour;
pub mod error;
pub mod formats;
pub mod limit;
pub mod mesh;
pub mod refine;
pub mod render;
pub mod rules;
pub mod ternary_step;
pub mod topology;
pub mod validate;

pub use colour::ColourSpace;
pub use error::{Error, ErrorKind, Location, Result, Warning};
pub use mesh::{
    BoundaryInterpolation, ControlPoint, CreasingMethod, Document, EdgeKind, EdgeTag, GradientMesh,
    WedgeOverride,
};
pub use refine::{RefinedMesh, Refinement};
pub use topology::Topology;
pub use validate::validate;
