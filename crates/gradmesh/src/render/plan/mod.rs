//! Planning: how well triangles show the surface (colour error, size, outline distance), each
//! face's grid and whether it takes quadratic colour.

pub(super) mod face_plans;
pub(super) mod measure;
pub(super) mod quadratic;
