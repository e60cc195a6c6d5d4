//! The GPU side: the crowd's tables, one frame for all characters, one file per pass.
//! Data flow per frame: [`Crowd`] (textures, records, bundles) -> generation (task shader, or
//! [`passes::compute_generate`]) -> strips and scalps ([`passes::strands`], [`passes::scalp`])
//! -> colour image ([`targets`]). The CPU/GPU contract lives in [`shared`].

pub mod camera;
pub mod core;
pub mod crowd;
pub mod debug;
pub mod deform;
pub mod features;
pub mod frame;
pub mod passes;
pub mod renderer;
pub mod scene;
pub mod schedule;
pub mod settings;
pub mod shadow;
pub mod world;

pub use self::core::shared::FrameStats;
pub use self::core::slots::{Dropped, FRAMES_IN_FLIGHT, FrameReport, ViewBudgets};
pub use self::core::{graph, shared, slots, targets, workspace};
pub use camera::{
    CROWD_ALPHA_STRANDS, CROWD_AREA_BELOW, CROWD_STRANDS_PER_PIXEL, Camera, DEFAULT_VIEW_DIR,
    LodSettings, View,
};
pub use crowd::{CharacterId, Crowd, StrandParams};
pub use features::props::{self as prop_table, skinned as skinned_props};
pub use features::soft_raster::{payload, pixel as soft_pixel};
pub use features::{dynamics, host, soft_raster as soft, temporal, transparency, volume};
pub use host::{HostCamera, HostFrame, HostImage};
pub use renderer::{
    DeviceCaps, FrameOptions, FrameSettings, FrameTicket, PresentTarget, RenderPath, Renderer,
    RendererDesc, check_msaa, software_raster_conflict, supported_msaa,
};
pub use settings::{LightRaster, parse_switch};
pub use shadow::ShadowMode;
pub use soft::StrandRaster;
pub use temporal::Temporal;
pub use transparency::Transparency;
pub use volume::VolumeTier;
