//! Raster passes: the opaque scalp (pulled from the root slice) and the strand strips (pulled
//! from the generated vertex buffer). Both read descriptor set 0; both write colour and depth.

use std::sync::Arc;

use ash::vk;

use super::hair_gpu::HairGpu;
use crate::vk::pipeline::{GraphicsDesc, Pipeline};
use crate::vk::{Context, GpuResult, shader};

/// Colour target format (sRGB encoding on write).
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Depth target format.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Scalp and strand pipelines.
pub struct HairDraw {
    ctx: Arc<Context>,
    scalp: Pipeline,
    strands: Pipeline,
}

impl HairDraw {
    /// Compile both pipelines.
    pub fn new(ctx: &Arc<Context>, layout: vk::DescriptorSetLayout) -> GpuResult<Self> {
        let graphics = |name: &str, vs: &str, fs: &str| -> GpuResult<Pipeline> {
            let (v, f) = (shader::compile(vs)?, shader::compile(fs)?);
            Pipeline::graphics(
                ctx,
                layout,
                &GraphicsDesc {
                    name,
                    stages: vec![
                        (vk::ShaderStageFlags::VERTEX, &v),
                        (vk::ShaderStageFlags::FRAGMENT, &f),
                    ],
                    color_format: COLOR_FORMAT,
                    depth_format: DEPTH_FORMAT,
                },
            )
        };
        Ok(HairDraw {
            ctx: ctx.clone(),
            scalp: graphics("scalp", "scalp.vert", "scalp.frag")?,
            strands: graphics("strands", "strands.vert", "strands.frag")?,
        })
    }

    /// Record the scalp and the strands of `hair` (inside dynamic rendering).
    pub fn record(&self, cmd: vk::CommandBuffer, hair: &HairGpu) {
        let model = hair.model_cols();
        self.scalp.bind(cmd, hair.set.set, &model);
        // SAFETY: recording inside a render pass instance with viewport/scissor set.
        unsafe {
            self.ctx
                .device
                .cmd_draw(cmd, hair.bundle_count() * 6, 1, 0, 0)
        };
        self.strands.bind(cmd, hair.set.set, &model);
        // SAFETY: draw arguments at offset 16 of the indirect buffer (written by scan.comp).
        unsafe {
            self.ctx
                .device
                .cmd_draw_indirect(cmd, hair.indirect.raw, 16, 1, 16)
        };
    }
}
