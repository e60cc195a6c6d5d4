//! The renderer's features, one folder each: a feature owns its mode, its checks, its state
//! between frames, its pipelines and the frame-block fields it writes, and adds its passes to
//! a frame's graph, returning what it made. Features take from [`super::core`] and their own
//! folder only, never from each other or the renderer (`tests/module_house.rs` checks).

pub mod dynamics;
pub mod host;
pub mod props;
pub mod soft_raster;
pub mod temporal;
pub mod transparency;
pub mod volume;
