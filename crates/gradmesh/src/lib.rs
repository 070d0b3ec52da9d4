//! gradmesh: gradient meshes of arbitrary manifold topology.
//!
//! The pipeline follows Lieng, Kosinka, Shen and Dodgson, "A Colour Interpolation Scheme for
//! Topologically Unrestricted Gradient Meshes" (Computer Graphics Forum 36(6), 2017):
//!
//! 1. [`GradientMesh`]: control points with colours, handles and edge tags, checked by
//!    [`validate`](fn@validate) into a [`BaseMesh`] (discontinuities split);
//! 2. the ternary step: the special first refinement that makes colours interpolating (or
//!    the paper's alternative of two binary splits, [`FirstStep`]);
//! 3. Catmull-Clark refinement with Pixar's rules, topology refined once and data
//!    interpolated with precomputed stencils ([`Refinement`], [`refine_level`]);
//! 4. multi-resolution edits ([`Edit`]), applied to refined levels between steps;
//! 5. limit positions and colours of refined vertices ([`Refinement::limit`]);
//! 6. [`formats`] reads and writes files, and [`render`] draws the limit surface.
//!
//! ```
//! use gradmesh::{ColourSpace, GradientMesh, Refinement};
//! use kurbo::Point;
//!
//! let mut mesh = GradientMesh::new(ColourSpace::Lab);
//! let a = mesh.add_point(Point::new(0.0, 0.0), [50.0, 60.0, 40.0]);
//! let b = mesh.add_point(Point::new(100.0, 0.0), [90.0, -10.0, 80.0]);
//! let c = mesh.add_point(Point::new(50.0, 90.0), [40.0, 10.0, -50.0]);
//! mesh.add_face(vec![a, b, c]);
//!
//! // Topology of levels 0..=3 is built once; data is evaluated with precomputed stencils.
//! let (mut refinement, warnings) = Refinement::new(&mesh, 3)?;
//! assert!(warnings.is_empty());
//! let data = refinement.evaluate();
//! // Limit position, colour and opacity of every level-3 vertex. Point `a` keeps its colour.
//! let limit = refinement.limit(&data, 3);
//! assert!((limit[refinement.vertex_at_level(a, 3)].colour[0] - 50.0).abs() < 1e-12);
//! # Ok::<(), gradmesh::Error>(())
//! ```

mod binary_step;
mod catmull_clark;
mod classic_fit;
mod colour;
mod edit_check;
mod edits;
mod error;
pub mod export;
mod fit;
mod folds;
pub mod formats;
mod join;
mod level;
mod limit_matrix;
mod limit_surface;
mod mesh;
mod multires;
mod refine;
pub mod render;
mod rules;
mod scheme;
mod size_limits;
mod ternary_step;
mod topology;
mod union_find;
mod validate;
mod view;

pub use classic_fit::{fit_joined_to_classic, fit_to_classic, ClassicFitOptions};
pub use colour::{parse_css_colour, ColourSpace};
pub use edit_check::EditSet;
pub use error::{Error, ErrorKind, Location, Result, Warning, WarningKind};
pub use fit::{
    fit_colours, fit_colours_with_detail, psnr, vectorise, vectorise_with_progress, DetailFit,
    DetailOptions, Progress, Quality, RgbaImage, VectoriseOptions, Vectorised, MAX_IMAGE_BYTES,
    MAX_IMAGE_PIXELS,
};
pub use join::{join_meshes, JoinTolerance, Joined};
pub use limit_matrix::{limit_matrix, LimitMatrix};
pub use mesh::{ControlPoint, Document, EdgeKind, EdgeTag, GradientMesh, WedgeOverride};
pub use multires::{ColourEdit, Edit, FineEdits, OpacityEdit, VertexAddress, MAX_EDIT_LEVEL};
pub use refine::{refine_level, LevelPoints, RefinedData, RefinedLevel, Refinement};
pub use scheme::{BoundaryInterpolation, CreasingMethod, FirstStep, SHARPNESS_INFINITE};
pub use size_limits::Limits;
pub use topology::Topology;
pub use validate::{validate, BaseMesh, VertexData};

/// The README's Rust examples, compiled and run by `cargo test --doc`.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeExamples;

/// The pipeline's inner steps, for tests against independent oracles and for benchmarks. Not a
/// stable API: these change with the implementation.
#[doc(hidden)]
pub mod internals {
    /// The paper's alternative first step: two binary splits.
    pub mod binary_step {
        pub use crate::binary_step::*;
    }
    /// One Catmull-Clark step and its stencils.
    pub mod catmull_clark {
        pub use crate::catmull_clark::*;
    }
    /// Limit stencils.
    pub mod limit {
        pub use crate::limit_surface::*;
    }
    /// Refinement size estimates.
    pub mod limits {
        pub use crate::size_limits::*;
    }
    /// Pixar's subdivision rules.
    pub mod rules {
        pub use crate::rules::*;
    }
    /// The paper's ternary first step.
    pub mod ternary_step {
        pub use crate::ternary_step::*;
    }
}
