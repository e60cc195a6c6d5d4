//! The CPU reference (the oracle the GPU paths are tested against): strand generation from the
//! baked textures ([`generate`]) and level of detail, eq. 7-12 ([`lod`]); and linear hair
//! skinning ([`lhs`]), the baseline the paper compares with.

pub mod generate;
pub mod lhs;
pub mod lod;
pub mod root_surface;
pub mod texel;
pub mod volume;
