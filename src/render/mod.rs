//! Rendering: per-character GPU resources, the generation passes and the raster passes.
//! Data flow: [`HairGpu`] (textures) -> [`compute_path::ComputeGenerate`] (strand vertices)
//! -> [`draw::HairDraw`] (scalp + strips) -> colour image.

pub mod compute_path;
pub mod draw;
pub mod frame;
pub mod hair_gpu;
pub mod renderer;
pub mod scene;

pub use frame::LodSettings;
pub use frame::{Camera, FrameParams};
pub use hair_gpu::{HairGpu, StrandParams};
pub use renderer::{RenderOutput, RenderPath, RenderSettings, Renderer};
