//! What every pass binds and compiles with: the two descriptor sets of a view, and the shader
//! options of the hair shaders on this device.

use crate::vk::shader::ShaderOptions;
use crate::vk::{Context, DescriptorSet};

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
    /// The camera's sets and the light's: each frame block's set with the crowd's textures.
    pub fn camera_and_light(
        (camera, light): (&'a DescriptorSet, &'a DescriptorSet),
        textures: &'a DescriptorSet,
    ) -> (Self, Self) {
        let of = |frame| PassSets { frame, textures };
        (of(camera), of(light))
    }

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

/// [`shader_options`] for `ctx`'s device: with `VISIBILITY` where it has 64-bit buffer
/// atomics (camera passes note each pixel's nearest surface for the motion vectors,
/// `temporal.glsl`).
pub fn device_shader_options(ctx: &Context, task_bundles: u32) -> ShaderOptions {
    match ctx.info.int64_atomics {
        true => shader_options(task_bundles).define("VISIBILITY", 1),
        false => shader_options(task_bundles),
    }
}
