//! Animated hair meshes (paper 003 sections 3.4 and 4: hair animates by moving the hair mesh).
//! [`motion`] moves whole characters (walk, turn, sway); [`crate::dynamics`] simulates the
//! layer vertices above the scalp (position-based, small steps) on the CPU or, through the
//! renderer, on the GPU; the renderer rebuilds the textures of the new pose on the GPU
//! (`bake::deform`, `passes::hair_mesh_update`).

pub mod crowd;
pub mod motion;
pub mod walk;

pub use crate::dynamics::{Collider, DynamicsSettings, HairDynamics, Wind};
pub use crowd::{AnimationStats, CrowdAnimation, DynamicsPath};
pub use motion::CharacterMotion;
