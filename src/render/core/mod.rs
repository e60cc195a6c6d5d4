//! The renderer's core, which every feature builds on and which imports nothing above it: the
//! camera ([`camera`]), the frame graph and its pool of transient resources ([`graph`]), the CPU/GPU contract
//! ([`shared`], a leaf), the camera's targets and shadow maps ([`targets`]), the frames in
//! flight and what a finished frame reports ([`slots`]), the working buffers that outlive a
//! frame ([`workspace`]), the generation path every feature reads ([`path`]), what every pass
//! binds and compiles with ([`binding`]), the targets pipelines draw into ([`pipelines`]) and
//! the frame's resources in its graph ([`frame_res`]).

pub mod binding;
pub mod camera;
pub mod frame_res;
pub mod graph;
pub mod ids;
pub mod mode_name;
pub mod path;
pub mod pipelines;
pub mod readback;
pub mod shared;
pub mod slots;
pub mod targets;
pub mod workspace;
