//! Real-time strand hair from hair meshes (Bhokare, Montalvo, Diaz, Yuksel, SIGGRAPH 2024).
//!
//! Data flows one way, and the modules follow it:
//! [`model`] (hair mesh, OBJ, style) -> [`bake`](mod@bake) (five textures, `.hmb` file) ->
//! [`reference`](mod@reference) (CPU oracle of strand generation and LoD) | [`render`] (GPU generation,
//! shading, image) on the thin Vulkan layer [`vk`].

#![warn(missing_docs)]

pub mod animate;
pub mod bake;
pub mod budget;
pub mod characters;
pub mod cli;
pub mod dynamics;
pub mod error;
pub mod fit;
pub mod fsutil;
pub mod fuzz;
pub mod guide;
pub mod model;
pub mod reference;
pub mod render;
pub mod rng;
pub mod shade;
pub mod skin;
pub mod vk;

pub use bake::{BakeOptions, BakedHairMesh, BundleDesc, MeshInfo, bake};
pub use error::{HairError, Result};
pub use model::hair_mesh::{ExtrudeDesc, Face, HairMesh, extrude};
pub use model::style::HairStyle;
pub use reference::generate::{CpuGenerator, StrandSet};
