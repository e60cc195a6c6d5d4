//! One file per pass. Each pass owns its pipelines and records itself with `record`, naming
//! what it reads and writes.

pub mod compute_generate;
pub mod scalp;
pub mod strands;

use crate::vk::{DescriptorSet, shader::ShaderOptions};

/// The two descriptor sets every pass binds: set 0 (frame and crowd tables) and set 1 (the
/// bindless textures).
#[derive(Clone, Copy)]
pub struct PassSets<'a> {
    /// Set 0.
    pub frame: &'a DescriptorSet,
    /// Set 1.
    pub textures: &'a DescriptorSet,
}

impl<'a> PassSets<'a> {
    /// As a slice for binding.
    pub fn both(&self) -> [&'a DescriptorSet; 2] {
        [self.frame, self.textures]
    }
}

/// Compile options of every hair shader: the generated `shared.glsl` and the task workgroup
/// width.
pub fn shader_options(task_bundles: u32) -> ShaderOptions {
    ShaderOptions::default()
        .include("shared.glsl", super::shared::glsl_header())
        .define("TASK_BUNDLES", task_bundles)
}

/// `(x, y)` workgroup counts for `groups` workgroups with at most `DISPATCH_ROW` per row.
pub fn dispatch_2d(groups: u32) -> (u32, u32) {
    let row = super::shared::DISPATCH_ROW;
    (groups.min(row), groups.div_ceil(row))
}
