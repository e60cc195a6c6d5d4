//! Animated hair meshes (paper 003 sections 3.4 and 4: hair animates by moving the hair mesh).
//! [`motion`] moves whole characters (walk, turn, sway); [`dynamics`] simulates the layer
//! vertices above the scalp (position-based, small steps); the renderer rebuilds the textures
//! of the new pose on the GPU (`bake::deform`, `passes::hair_mesh_update`).

pub mod crowd;
pub mod dynamics;
pub mod motion;

pub use crowd::{AnimationStats, CrowdAnimation};
pub use dynamics::{Collider, DynamicsSettings, HairDynamics, Wind};
pub use motion::CharacterMotion;
