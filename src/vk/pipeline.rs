//! Pipeline layouts, compute pipelines and graphics pipelines (dynamic rendering, no vertex
//! input: every draw pulls its data from buffers and textures). Fixed-function state is part
//! of the description ([`GraphicsDesc`]), so transparent or depth-only passes are one field away.

use std::sync::Arc;

use ash::vk;

use super::descriptor::DescriptorSetLayout;
use super::{Context, GpuResult, VkContext};

/// Push constant bytes of every pipeline layout (all stages).
pub const PUSH_CONSTANT_BYTES: u32 = 32;

/// A pipeline layout: descriptor set layouts (set `i` = element `i`) and the push constants.
pub struct PipelineLayout {
    ctx: Arc<Context>,
    raw: vk::PipelineLayout,
    _sets: Vec<Arc<DescriptorSetLayout>>,
}

impl PipelineLayout {
    /// A layout with `sets` and [`PUSH_CONSTANT_BYTES`] of push constants.
    pub fn new(ctx: &Arc<Context>, sets: &[Arc<DescriptorSetLayout>]) -> GpuResult<Arc<Self>> {
        let raw_sets: Vec<_> = sets.iter().map(|s| s.raw()).collect();
        let push = [vk::PushConstantRange {
            stage_flags: vk::ShaderStageFlags::ALL,
            offset: 0,
            size: PUSH_CONSTANT_BYTES,
        }];
        let info = vk::PipelineLayoutCreateInfo::default()
            .set_layouts(&raw_sets)
            .push_constant_ranges(&push);
        // SAFETY: valid create info.
        let raw = unsafe { ctx.device.create_pipeline_layout(&info, None) }
            .ctx("create pipeline layout")?;
        Ok(Arc::new(PipelineLayout {
            ctx: ctx.clone(),
            raw,
            _sets: sets.to_vec(),
        }))
    }
}

impl Drop for PipelineLayout {
    fn drop(&mut self) {
        // SAFETY: pipelines hold an Arc to their layout, so none is alive.
        unsafe { self.ctx.device.destroy_pipeline_layout(self.raw, None) };
    }
}

/// Depth test of a graphics pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthMode {
    /// No depth test or write.
    Off,
    /// Test `LESS` and write (opaque geometry).
    TestWrite,
    /// Test `LESS_OR_EQUAL`, no write (transparent geometry over opaque depth).
    TestOnly,
    /// Test `EQUAL`, no write (the fragments of a depth-peeled layer).
    Equal,
    /// No test, write every fragment (a depth image filled by a full-screen pass).
    Replace,
}

/// Colour blending of a graphics pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlendMode {
    /// Replace.
    Opaque,
    /// Premultiplied alpha over.
    PremultipliedOver,
    /// Additive.
    Additive,
}

/// Face culling of a graphics pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CullMode {
    /// Two-sided.
    None,
    /// Cull back faces (counter-clockwise front).
    Back,
    /// Cull front faces (counter-clockwise front): the far side of a closed mesh, each pixel
    /// it covers once whether the eye is outside or inside.
    Front,
}

/// How to build a graphics pipeline.
pub struct GraphicsDesc<'a> {
    /// Debug name.
    pub name: &'a str,
    /// `(stage, SPIR-V)` for each stage (vertex or task + mesh, and fragment).
    pub stages: Vec<(vk::ShaderStageFlags, &'a [u32])>,
    /// Colour attachment format.
    pub color_format: vk::Format,
    /// Depth attachment format.
    pub depth_format: vk::Format,
    /// Depth state.
    pub depth: DepthMode,
    /// Blend state.
    pub blend: BlendMode,
    /// Culling.
    pub cull: CullMode,
    /// Samples per pixel of the attachments.
    pub samples: u32,
}

impl<'a> GraphicsDesc<'a> {
    /// Opaque, depth-tested, two-sided triangles.
    pub fn new(name: &'a str, color_format: vk::Format, depth_format: vk::Format) -> Self {
        GraphicsDesc {
            name,
            stages: Vec::new(),
            color_format,
            depth_format,
            depth: DepthMode::TestWrite,
            blend: BlendMode::Opaque,
            cull: CullMode::None,
            samples: 1,
        }
    }

    /// Add a shader stage.
    pub fn stage(mut self, stage: vk::ShaderStageFlags, spirv: &'a [u32]) -> Self {
        self.stages.push((stage, spirv));
        self
    }

    /// Set the depth mode.
    pub fn depth(mut self, depth: DepthMode) -> Self {
        self.depth = depth;
        self
    }

    /// Set the blend mode.
    pub fn blend(mut self, blend: BlendMode) -> Self {
        self.blend = blend;
        self
    }

    /// Set the cull mode.
    pub fn cull(mut self, cull: CullMode) -> Self {
        self.cull = cull;
        self
    }

    /// Set the sample count (MSAA).
    pub fn samples(mut self, samples: u32) -> Self {
        self.samples = samples;
        self
    }
}

fn raster_state(cull: CullMode) -> vk::PipelineRasterizationStateCreateInfo<'static> {
    vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(match cull {
            CullMode::None => vk::CullModeFlags::NONE,
            CullMode::Back => vk::CullModeFlags::BACK,
            CullMode::Front => vk::CullModeFlags::FRONT,
        })
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0)
}

fn depth_state(mode: DepthMode) -> vk::PipelineDepthStencilStateCreateInfo<'static> {
    let d = vk::PipelineDepthStencilStateCreateInfo::default();
    match mode {
        DepthMode::Off => d,
        DepthMode::TestWrite => d
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::LESS),
        DepthMode::TestOnly => d
            .depth_test_enable(true)
            .depth_compare_op(vk::CompareOp::LESS_OR_EQUAL),
        DepthMode::Equal => d
            .depth_test_enable(true)
            .depth_compare_op(vk::CompareOp::EQUAL),
        DepthMode::Replace => d
            .depth_test_enable(true)
            .depth_write_enable(true)
            .depth_compare_op(vk::CompareOp::ALWAYS),
    }
}

fn blend_attachment(mode: BlendMode) -> vk::PipelineColorBlendAttachmentState {
    let b = vk::PipelineColorBlendAttachmentState::default()
        .color_write_mask(vk::ColorComponentFlags::RGBA);
    let (src, dst) = match mode {
        BlendMode::Opaque => return b,
        BlendMode::PremultipliedOver => {
            (vk::BlendFactor::ONE, vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
        }
        BlendMode::Additive => (vk::BlendFactor::ONE, vk::BlendFactor::ONE),
    };
    let (src_a, dst_a) = (src, dst);
    b.blend_enable(true)
        .src_color_blend_factor(src)
        .dst_color_blend_factor(dst)
        .color_blend_op(vk::BlendOp::ADD)
        .src_alpha_blend_factor(src_a)
        .dst_alpha_blend_factor(dst_a)
        .alpha_blend_op(vk::BlendOp::ADD)
}

/// A compute or graphics pipeline.
pub struct Pipeline {
    ctx: Arc<Context>,
    raw: vk::Pipeline,
    layout: Arc<PipelineLayout>,
    bind_point: vk::PipelineBindPoint,
}

/// Shader modules destroyed when dropped (after pipeline creation, or on an error path).
struct Modules<'a> {
    ctx: &'a Context,
    raw: Vec<vk::ShaderModule>,
}

impl Modules<'_> {
    fn add(&mut self, spirv: &[u32]) -> GpuResult<vk::ShaderModule> {
        let info = vk::ShaderModuleCreateInfo::default().code(spirv);
        // SAFETY: SPIR-V produced by shaderc.
        let m = unsafe { self.ctx.device.create_shader_module(&info, None) }
            .ctx("create shader module")?;
        self.raw.push(m);
        Ok(m)
    }
}

impl Drop for Modules<'_> {
    fn drop(&mut self) {
        for &m in &self.raw {
            // SAFETY: modules are not needed after pipeline creation.
            unsafe { self.ctx.device.destroy_shader_module(m, None) };
        }
    }
}

impl Pipeline {
    /// A compute pipeline from SPIR-V with entry point `main`.
    pub fn compute(
        ctx: &Arc<Context>,
        name: &str,
        layout: &Arc<PipelineLayout>,
        spirv: &[u32],
    ) -> GpuResult<Self> {
        let mut modules = Modules {
            ctx,
            raw: Vec::new(),
        };
        let m = modules.add(spirv)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(m)
            .name(c"main");
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout.raw)];
        // SAFETY: module and layout are valid.
        let raw = unsafe {
            ctx.device
                .create_compute_pipelines(vk::PipelineCache::null(), &info, None)
        }
        .map_err(|(_, e)| e)
        .ctx("create compute pipeline")?[0];
        ctx.name_object(raw, name);
        Ok(Pipeline {
            ctx: ctx.clone(),
            raw,
            layout: layout.clone(),
            bind_point: vk::PipelineBindPoint::COMPUTE,
        })
    }

    /// A graphics pipeline as described (triangle lists, dynamic viewport and scissor).
    pub fn graphics(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        desc: &GraphicsDesc,
    ) -> GpuResult<Self> {
        let mut modules = Modules {
            ctx,
            raw: Vec::new(),
        };
        let mut stages = Vec::new();
        for (stage, spirv) in &desc.stages {
            let m = modules.add(spirv)?;
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(*stage)
                    .module(m)
                    .name(c"main"),
            );
        }
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = raster_state(desc.cull);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(super::sample_flags(desc.samples));
        let depth = depth_state(desc.depth);
        // No colour format: a depth-only pipeline (shadow maps).
        let has_color = desc.color_format != vk::Format::UNDEFINED;
        let blend_attachments = [blend_attachment(desc.blend)];
        let blend = vk::PipelineColorBlendStateCreateInfo::default()
            .attachments(&blend_attachments[..has_color as usize]);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let color_formats = [desc.color_format];
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&color_formats[..has_color as usize])
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
            .layout(layout.raw)
            .push_next(&mut rendering);
        if !mesh {
            info = info
                .vertex_input_state(&vertex_input)
                .input_assembly_state(&assembly);
        }
        // SAFETY: all state structs live until the call returns.
        let raw = unsafe {
            ctx.device
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
        }
        .map_err(|(_, e)| e)
        .ctx("create graphics pipeline")?[0];
        ctx.name_object(raw, desc.name);
        Ok(Pipeline {
            ctx: ctx.clone(),
            raw,
            layout: layout.clone(),
            bind_point: vk::PipelineBindPoint::GRAPHICS,
        })
    }

    pub(crate) fn raw(&self) -> vk::Pipeline {
        self.raw
    }

    pub(crate) fn layout_raw(&self) -> vk::PipelineLayout {
        self.layout.raw
    }

    pub(crate) fn bind_point(&self) -> vk::PipelineBindPoint {
        self.bind_point
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: owners drop pipelines after the frames using them retired.
        unsafe { self.ctx.device.destroy_pipeline(self.raw, None) };
    }
}
