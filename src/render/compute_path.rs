//! Compute path (no mesh shaders): cull + count bundles, prefix sum, generate strand vertices.
//! Reads: the five textures, bundle table, style, root samples. Writes: counts, offsets,
//! indirect arguments and the `HairVertex` buffer that `StrandDraw` pulls from.

use std::sync::Arc;

use ash::vk;

use super::hair_gpu::HairGpu;
use crate::vk::pipeline::Pipeline;
use crate::vk::profiler::Profiler;
use crate::vk::{Context, GpuResult, shader};

/// The three compute pipelines of the generation pass.
pub struct ComputeGenerate {
    ctx: Arc<Context>,
    cull: Pipeline,
    scan: Pipeline,
    generate: Pipeline,
}

impl ComputeGenerate {
    /// Compile the pipelines for descriptor layout `layout`.
    pub fn new(ctx: &Arc<Context>, layout: vk::DescriptorSetLayout) -> GpuResult<Self> {
        Ok(ComputeGenerate {
            ctx: ctx.clone(),
            cull: Pipeline::compute(ctx, "cull", layout, &shader::compile("cull.comp")?)?,
            scan: Pipeline::compute(ctx, "scan", layout, &shader::compile("scan.comp")?)?,
            generate: Pipeline::compute(
                ctx,
                "generate",
                layout,
                &shader::compile("generate.comp")?,
            )?,
        })
    }

    /// Record generation of `hair`'s strands into its vertex buffer.
    pub fn record(&self, cmd: vk::CommandBuffer, hair: &HairGpu, profiler: &mut Profiler) {
        let model = hair.model_cols();
        let compute = vk::PipelineStageFlags2::COMPUTE_SHADER;
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        // Previous users of the vertex buffer (draws) must finish before we overwrite it.
        self.ctx.barrier(
            cmd,
            (
                vk::PipelineStageFlags2::VERTEX_SHADER | vk::PipelineStageFlags2::DRAW_INDIRECT,
                vk::AccessFlags2::MEMORY_READ,
            ),
            (compute, rw),
        );
        profiler.begin(cmd, "cull");
        self.cull.bind(cmd, hair.set.set, &model);
        // SAFETY: recording with a bound compute pipeline.
        unsafe {
            self.ctx
                .device
                .cmd_dispatch(cmd, hair.bundle_count().div_ceil(64), 1, 1)
        };
        profiler.end(cmd);
        self.ctx.barrier(cmd, (compute, rw), (compute, rw));
        profiler.begin(cmd, "scan");
        self.scan.bind(cmd, hair.set.set, &model);
        // SAFETY: as above.
        unsafe { self.ctx.device.cmd_dispatch(cmd, 1, 1, 1) };
        profiler.end(cmd);
        self.ctx.barrier(
            cmd,
            (compute, rw),
            (
                compute | vk::PipelineStageFlags2::DRAW_INDIRECT,
                rw | vk::AccessFlags2::INDIRECT_COMMAND_READ,
            ),
        );
        profiler.begin(cmd, "generate");
        self.generate.bind(cmd, hair.set.set, &model);
        // SAFETY: indirect arguments were written by the scan pass (barrier above).
        unsafe {
            self.ctx
                .device
                .cmd_dispatch_indirect(cmd, hair.indirect.raw, 0)
        };
        profiler.end(cmd);
        self.ctx.barrier(
            cmd,
            (compute, vk::AccessFlags2::SHADER_STORAGE_WRITE),
            (
                vk::PipelineStageFlags2::VERTEX_SHADER
                    | vk::PipelineStageFlags2::DRAW_INDIRECT
                    | vk::PipelineStageFlags2::TRANSFER,
                vk::AccessFlags2::SHADER_STORAGE_READ
                    | vk::AccessFlags2::INDIRECT_COMMAND_READ
                    | vk::AccessFlags2::TRANSFER_READ,
            ),
        );
    }
}
