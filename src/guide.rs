//! The guide: how the renderer works and what it measures, one chapter per module (the
//! Markdown files in `src/guide/`, rendered by `cargo doc`). The README is the front door;
//! these are the rooms. Pictures are linked relative to `src/guide/`, so they show where the
//! Markdown is browsed in the repository.
//!
//! | chapter | what it holds |
//! |---|---|
//! | [`testing`] | setup, the test suite, its times, mutation testing |
//! | [`tools`] | every tool's flags |
//! | [`crowd`] | the crowd demo, its people, your own character |
//! | [`embedding`] | the renderer inside an engine's frame |
//! | [`bevy`] | the Bevy plugin (`tools/bevy_hair`) |
//! | [`generation`] | GPU generation for a whole crowd, level of detail |
//! | [`bake`] | how a hair mesh becomes five textures |
//! | [`shading`] | shading, shadows, transparency, thick strands, multiple scattering |
//! | [`soft_raster`] | the compute software rasterizer |
//! | [`temporal`] | temporal accumulation and its flicker measure |
//! | [`animation`] | animated hair meshes and their dynamics |
//! | [`volume`] | the volume tier: far hair from density volumes |
//! | [`paper`] | the paper's comparison with LHS and static strands |
//! | [`fit`] | hair meshes fitted to strand models |
//! | [`robustness`] | input checks, output policy, limits, fuzzing |
//! | [`formats`] | the sample assets and file formats |
//! | [`frame_graph`] | the frame graph |
//! | [`measured`] | measured tables |
//! | [`layout`] | where the code lives |

#[doc = include_str!("guide/testing.md")]
pub mod testing {}
#[doc = include_str!("guide/tools.md")]
pub mod tools {}
#[doc = include_str!("guide/crowd.md")]
pub mod crowd {}
#[doc = include_str!("guide/embedding.md")]
pub mod embedding {}
#[doc = include_str!("guide/bevy.md")]
pub mod bevy {}
#[doc = include_str!("guide/generation.md")]
pub mod generation {}
#[doc = include_str!("guide/bake.md")]
pub mod bake {}
#[doc = include_str!("guide/shading.md")]
pub mod shading {}
#[doc = include_str!("guide/soft_raster.md")]
pub mod soft_raster {}
#[doc = include_str!("guide/temporal.md")]
pub mod temporal {}
#[doc = include_str!("guide/animation.md")]
pub mod animation {}
#[doc = include_str!("guide/volume.md")]
pub mod volume {}
#[doc = include_str!("guide/paper.md")]
pub mod paper {}
#[doc = include_str!("guide/fit.md")]
pub mod fit {}
#[doc = include_str!("guide/robustness.md")]
pub mod robustness {}
#[doc = include_str!("guide/formats.md")]
pub mod formats {}
#[doc = include_str!("guide/frame_graph.md")]
pub mod frame_graph {}
#[doc = include_str!("guide/measured.md")]
pub mod measured {}
#[doc = include_str!("guide/layout.md")]
pub mod layout {}
