//! The opaque scalps of every character in one draw (two triangles per bundle, pulled from the
//! root slice). Reads: frame block, character records, bundle table, textures. Writes: colour
//! and depth.

use std::sync::Arc;

use ash::vk;

use super::{PassSets, shader_options};
use crate::vk::shader::compile;
use crate::vk::{CommandRecorder, Context, GpuResult, GraphicsDesc, Pipeline, PipelineLayout};

/// The scalp pipeline.
pub struct ScalpPass {
    pipeline: Pipeline,
}

impl ScalpPass {
    /// Compile the pipeline for the given target formats.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        color: vk::Format,
        depth: vk::Format,
    ) -> GpuResult<Self> {
        let opts = shader_options(1);
        let (v, f) = (compile("scalp.vert", &opts)?, compile("scalp.frag", &opts)?);
        let desc = GraphicsDesc::new("scalp", color, depth)
            .stage(vk::ShaderStageFlags::VERTEX, &v)
            .stage(vk::ShaderStageFlags::FRAGMENT, &f);
        Ok(ScalpPass {
            pipeline: Pipeline::graphics(ctx, layout, &desc)?,
        })
    }

    /// Draw the scalps of `bundles` bundles (inside rendering).
    pub fn record(&self, rec: &mut CommandRecorder, sets: PassSets, bundles: u32) {
        rec.bind(&self.pipeline, &sets.both());
        rec.draw(bundles * 6);
    }
}
