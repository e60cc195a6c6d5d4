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

/// Scalp and strand pipelines: the vertex-pulling strands of the compute path and, where the
/// device has VK_EXT_mesh_shader, the task + mesh strands.
pub struct HairDraw {
    ctx: Arc<Context>,
    scalp: Pipeline,
    strands: Pipeline,
    mesh_strands: Option<Pipeline>,
}

/// Whether the device's mesh shader limits fit `strands.task` / `strands.mesh`.
pub fn mesh_path_supported(ctx: &Context) -> bool {
    ctx.info.mesh_limits.is_some_and(|l| {
        l.max_mesh_output_vertices >= 130
            && l.max_mesh_output_primitives >= 128
            && l.max_task_payload_size >= 20
            && l.max_mesh_work_group_invocations >= 32
            && l.max_mesh_work_group_total_count
                >= crate::bake::blue_noise::MAX_STRANDS_PER_BUNDLE as u32
            && l.max_task_work_group_count[0] >= 65535
    })
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
        let mesh_strands = if mesh_path_supported(ctx) {
            let (t, m, f) = (
                shader::compile("strands.task")?,
                shader::compile("strands.mesh")?,
                shader::compile("strands.frag")?,
            );
            Some(Pipeline::graphics(
                ctx,
                layout,
                &GraphicsDesc {
                    name: "mesh strands",
                    stages: vec![
                        (vk::ShaderStageFlags::TASK_EXT, &t),
                        (vk::ShaderStageFlags::MESH_EXT, &m),
                        (vk::ShaderStageFlags::FRAGMENT, &f),
                    ],
                    color_format: COLOR_FORMAT,
                    depth_format: DEPTH_FORMAT,
                },
            )?)
        } else {
            None
        };
        Ok(HairDraw {
            ctx: ctx.clone(),
            scalp: graphics("scalp", "scalp.vert", "scalp.frag")?,
            strands: graphics("strands", "strands.vert", "strands.frag")?,
            mesh_strands,
        })
    }

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.mesh_strands.is_some()
    }

    /// Record the scalp of `hair` (inside dynamic rendering).
    pub fn record_scalp(&self, cmd: vk::CommandBuffer, hair: &HairGpu) {
        self.scalp.bind(cmd, hair.set.set, &hair.model_cols());
        // SAFETY: recording inside a render pass instance with viewport/scissor set.
        unsafe {
            self.ctx
                .device
                .cmd_draw(cmd, hair.bundle_count() * 6, 1, 0, 0)
        };
    }

    /// Mesh path: one task workgroup per bundle generates and draws the strands of `hair`
    /// (inside dynamic rendering; the indirect block's counters must be zeroed before).
    pub fn record_mesh_strands(&self, cmd: vk::CommandBuffer, hair: &HairGpu) {
        let (Some(p), Some(ext)) = (&self.mesh_strands, &self.ctx.mesh_ext) else {
            return;
        };
        p.bind(cmd, hair.set.set, &hair.model_cols());
        let b = hair.bundle_count();
        let row = 65535;
        // SAFETY: mesh pipeline bound; group counts within maxTaskWorkGroupCount (checked).
        unsafe { ext.cmd_draw_mesh_tasks(cmd, b.min(row), b.div_ceil(row), 1) };
    }

    /// Compute path: draw the strands generated into `hair`'s vertex buffer (inside dynamic
    /// rendering).
    pub fn record_pulled_strands(&self, cmd: vk::CommandBuffer, hair: &HairGpu) {
        self.strands.bind(cmd, hair.set.set, &hair.model_cols());
        // SAFETY: draw arguments at offset 16 of the indirect buffer (written by scan.comp).
        unsafe {
            self.ctx
                .device
                .cmd_draw_indirect(cmd, hair.indirect.raw, 16, 1, 16)
        };
    }
}
