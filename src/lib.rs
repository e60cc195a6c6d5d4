//! Real-time strand hair from hair meshes (Bhokare, Montalvo, Diaz, Yuksel, SIGGRAPH 2024).
//!
//! Data flows one way: [`HairMesh`] (OBJ, [`obj_io`]) -> [`bake::bake`] -> [`BakedHairMesh`]
//! (five textures, [`baked_file`]) -> strand generation ([`generate`] on the CPU, shaders in
//! `glsl/` on the GPU) -> shading -> image.

pub mod bake;
pub mod baked_file;
pub mod blue_noise;
pub mod curve;
pub mod error;
pub mod fsutil;
pub mod generate;
pub mod hair_mesh;
pub mod layout;
pub mod lod;
pub mod obj_io;
pub mod rng;
pub mod style;

pub use bake::{BakeOptions, BakedHairMesh, BundleDesc, MeshInfo, bake};
pub use error::{HairError, Result};
pub use generate::{CpuGenerator, StrandSet};
pub use hair_mesh::{ExtrudeDesc, Face, HairMesh, extrude};
pub use style::HairStyle;
pub mod render;
pub mod vk;
