//! The CPU reference (the oracle the GPU paths are tested against): strand generation from the
//! baked textures ([`generate`]) and level of detail, eq. 7-12 ([`lod`]).

pub mod generate;
pub mod lod;
