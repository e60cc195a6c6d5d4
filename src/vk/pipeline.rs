//! Pipeline layouts, compute pipelines and graphics pipelines (dynamic rendering, no vertex
//! input: every draw pulls its data from buffers and textures).

use std::sync::Arc;

use ash::vk;

use super::{Context, GpuResult, VkContext};

/// Push constant bytes shared by every pipeline (a `mat4` model transform).
pub const PUSH_CONSTANT_BYTES: u32 = 64;

/// A pipeline and its layout.
pub struct Pipeline {
    ctx: Arc<Context>,
    /// The pipeline.
    pub raw: vk::Pipeline,
    /// Its layout.
    pub layout: vk::PipelineLayout,
    /// Compute or graphics.
    pub bind_point: vk::PipelineBindPoint,
}

fn module(ctx: &Context, spirv: &[u32]) -> GpuResult<vk::ShaderModule> {
    let info = vk::ShaderModuleCreateInfo::default().code(spirv);
    // SAFETY: SPIR-V produced by shaderc.
    unsafe { ctx.device.create_shader_module(&info, None) }.ctx("create shader module")
}

fn layout(ctx: &Context, set_layout: vk::DescriptorSetLayout) -> GpuResult<vk::PipelineLayout> {
    let sets = [set_layout];
    let push = [vk::PushConstantRange {
        stage_flags: vk::ShaderStageFlags::ALL,
        offset: 0,
        size: PUSH_CONSTANT_BYTES,
    }];
    let info = vk::PipelineLayoutCreateInfo::default()
        .set_layouts(&sets)
        .push_constant_ranges(&push);
    // SAFETY: valid create info.
    unsafe { ctx.device.create_pipeline_layout(&info, None) }.ctx("create pipeline layout")
}

/// How to build a graphics pipeline.
pub struct GraphicsDesc<'a> {
    /// Debug name.
    pub name: &'a str,
    /// `(stage, SPIR-V)` for each stage (vertex or task+mesh, and fragment).
    pub stages: Vec<(vk::ShaderStageFlags, &'a [u32])>,
    /// Colour attachment format.
    pub color_format: vk::Format,
    /// Depth attachment format.
    pub depth_format: vk::Format,
}

impl Pipeline {
    /// A compute pipeline from SPIR-V with entry point `main`.
    pub fn compute(
        ctx: &Arc<Context>,
        name: &str,
        set_layout: vk::DescriptorSetLayout,
        spirv: &[u32],
    ) -> GpuResult<Self> {
        let m = module(ctx, spirv)?;
        let layout = layout(ctx, set_layout)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(m)
            .name(c"main");
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout)];
        // SAFETY: module and layout are valid; the module may be destroyed after creation.
        let result = unsafe {
            ctx.device
                .create_compute_pipelines(vk::PipelineCache::null(), &info, None)
        };
        // SAFETY: no longer needed after pipeline creation.
        unsafe { ctx.device.destroy_shader_module(m, None) };
        let raw = result.map_err(|(_, e)| e).ctx("create compute pipeline")?[0];
        ctx.name_object(raw, name);
        Ok(Pipeline {
            ctx: ctx.clone(),
            raw,
            layout,
            bind_point: vk::PipelineBindPoint::COMPUTE,
        })
    }

    /// A graphics pipeline: triangle lists, no culling, depth test less, opaque.
    pub fn graphics(
        ctx: &Arc<Context>,
        set_layout: vk::DescriptorSetLayout,
        desc: &GraphicsDesc,
    ) -> GpuResult<Self> {
        let modules: Vec<_> = desc
            .stages
            .iter()
            .map(|(_, s)| module(ctx, s))
            .collect::<GpuResult<_>>()?;
        let layout = layout(ctx, set_layout)?;
        let stages: Vec<_> = desc
            .stages
            .iter()
            .zip(&modules)
            .map(|((stage, _), m)| {
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(*stage)
                    .module(*m)
                    .name(c"main")
            })
            .collect();
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::LESS);
        let blend_attachments = [vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA)];
        let blend =
            vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let color_formats = [desc.color_format];
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&color_formats)
            .depth_attachment_format(desc.depth_format);
        let mesh = desc
            .stages
            .iter()
            .any(|(s, _)| s.contains(vk::ShaderStageFlags::MESH_EXT));
        let mut info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .push_next(&mut rendering);
        if !mesh {
            info = info
                .vertex_input_state(&vertex_input)
                .input_assembly_state(&assembly);
        }
        // SAFETY: all state structs live until the call returns.
        let result = unsafe {
            ctx.device
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
        };
        for m in modules {
            // SAFETY: not needed after creation.
            unsafe { ctx.device.destroy_shader_module(m, None) };
        }
        let raw = result.map_err(|(_, e)| e).ctx("create graphics pipeline")?[0];
        ctx.name_object(raw, desc.name);
        Ok(Pipeline {
            ctx: ctx.clone(),
            raw,
            layout,
            bind_point: vk::PipelineBindPoint::GRAPHICS,
        })
    }

    /// Bind this pipeline, descriptor set 0 and the model-transform push constant.
    pub fn bind(&self, cmd: vk::CommandBuffer, set: vk::DescriptorSet, model: &[f32; 16]) {
        // SAFETY: recording; the set was created with this pipeline's set layout.
        unsafe {
            self.ctx
                .device
                .cmd_bind_pipeline(cmd, self.bind_point, self.raw);
            self.ctx.device.cmd_bind_descriptor_sets(
                cmd,
                self.bind_point,
                self.layout,
                0,
                &[set],
                &[],
            );
            self.ctx.device.cmd_push_constants(
                cmd,
                self.layout,
                vk::ShaderStageFlags::ALL,
                0,
                bytemuck::cast_slice(model),
            );
        }
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: not in use once dropped.
        unsafe {
            self.ctx.device.destroy_pipeline(self.raw, None);
            self.ctx.device.destroy_pipeline_layout(self.layout, None);
        }
    }
}
