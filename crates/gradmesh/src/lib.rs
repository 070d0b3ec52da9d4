//! gradmesh: gradient meshes of arbitrary manifold topology.
//!
//! The pipeline follows Lieng, Kosinka, Shen and Dodgson, "A Colour Interpolation Scheme for
//! Topologically Unrestricted Gradient Meshes" (Computer Graphics Forum 36(6), 2017):
//!
//! 1. [`GradientMesh`]: control points with colours, handles and edge tags, checked by
//!    [`validate`](fn@validate);
//! 2. [`ternary_step`](mod@ternary_step): the special first refinement that makes colours interpolating
//!    (or [`binary_step`](mod@binary_step), the paper's alternative of two binary splits);
//! 3. [`catmull_clark`](mod@catmull_clark): Catmull-Clark refinement with Pixar's rules, topology refined once and
//!    data interpolated with precomputed stencils;
//! 4. [`edits`](mod@edits): multi-resolution edits, applied to refined levels between steps;
//! 5. [`limit`](mod@limit): limit positions and colours of refined vertices.
//!
//! ```
//! use gradmesh::{refine::Refinement, ColourSpace, GradientMesh};
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
//! assert!((limit[refinement.vertex_at_level(a, 3)][2] - 50.0).abs() < 1e-12);
//! # Ok::<(), gradmesh::Error>(())
//! ```

pub mod binary_step;
pub mod catmull_clark;
pub mod colour;
pub mod edit_check;
pub mod edits;
pub mod error;
pub mod formats;
pub mod level;
pub mod limit;
pub mod limits;
pub mod mesh;
pub mod multires;
pub mod refine;
pub mod render;
pub mod rules;
pub mod scheme;
pub mod ternary_step;
pub mod topology;
pub mod validate;

pub use colour::ColourSpace;
pub use error::{Error, ErrorKind, Location, Result, Warning};
pub use limits::Limits;
pub use mesh::{
    BoundaryInterpolation, ControlPoint, CreasingMethod, Document, EdgeKind, EdgeTag, FirstStep,
    GradientMesh, WedgeOverride,
};
pub use multires::{ColourEdit, Edit, FineEdits, OpacityEdit, VertexAddress};
pub use refine::{RefinedMesh, Refinement};
pub use topology::Topology;
pub use validate::validate;
