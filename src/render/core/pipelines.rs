//! What the frame's graphics and compute pipelines are made for: the targets they draw into,
//! and the helpers every pass builds its pipelines and dispatches with.

use std::sync::Arc;

use super::binding::device_shader_options;
use super::targets::DEPTH_FORMAT;
use crate::vk::{Context, GpuResult, PipelineLayout, shader::compile};

/// Formats and sample count of the targets the graphics passes draw into.
#[derive(Clone, Copy, Debug)]
pub struct TargetFormats {
    /// Colour format.
    pub color: ash::vk::Format,
    /// Depth format.
    pub depth: ash::vk::Format,
    /// Samples per pixel.
    pub samples: u32,
}

impl TargetFormats {
    /// An opaque, depth-tested graphics pipeline description for these targets.
    pub fn graphics_desc<'a>(&self, name: &'a str) -> crate::vk::GraphicsDesc<'a> {
        crate::vk::GraphicsDesc::new(name, self.color, self.depth).samples(self.samples)
    }
}

/// What a graphics pipeline draws into.
#[derive(Clone, Copy, Debug)]
pub enum DrawTarget {
    /// The camera view's colour and depth.
    Camera(TargetFormats),
    /// One of the light's depth maps: depth only, no fragment shader.
    ShadowDepth,
    /// The deep opacity layers: colour only, additive, no depth.
    ShadowOpacity,
    /// K-buffer insert: the camera's depth (tested, not written), no colour; fragments go to
    /// the per-pixel node buffers.
    OitInsert(TargetFormats),
    /// Depth peeling, first pass of a layer: depth only.
    PeelDepth,
    /// Depth peeling, second pass of a layer: depth test `EQUAL`; fragments go to the
    /// accumulation buffer.
    PeelColor,
}

impl DrawTarget {
    /// The pipeline description (formats, depth, blending) for this target.
    pub fn graphics_desc<'a>(&self, name: &'a str) -> crate::vk::GraphicsDesc<'a> {
        use crate::vk::{BlendMode, DepthMode, GraphicsDesc};
        use ash::vk::Format;
        match self {
            DrawTarget::Camera(t) => t.graphics_desc(name),
            DrawTarget::ShadowDepth => GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT),
            DrawTarget::ShadowOpacity => GraphicsDesc::new(
                name,
                super::targets::SHADOW_LAYERS_FORMAT,
                Format::UNDEFINED,
            )
            .depth(DepthMode::Off)
            .blend(BlendMode::Additive),
            DrawTarget::OitInsert(t) => GraphicsDesc::new(name, Format::UNDEFINED, t.depth)
                .samples(t.samples)
                .depth(DepthMode::TestOnly),
            DrawTarget::PeelDepth => GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT),
            DrawTarget::PeelColor => {
                GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT).depth(DepthMode::Equal)
            }
        }
    }

    /// The fragment shader strands drawn into this target use (`None`: depth only).
    pub fn strand_fragment_shader(&self) -> Option<&'static str> {
        match self {
            DrawTarget::Camera(_) => Some("strands.frag"),
            DrawTarget::ShadowDepth => None,
            DrawTarget::ShadowOpacity => Some("shadow.frag"),
            DrawTarget::OitInsert(_) => Some("oit.frag"),
            DrawTarget::PeelDepth => Some("peel_depth.frag"),
            DrawTarget::PeelColor => Some("peel_color.frag"),
        }
    }
}

/// A vertex (+ fragment, where given) pipeline drawing into `target`.
pub fn vertex_pipeline(
    ctx: &Arc<Context>,
    layout: &Arc<PipelineLayout>,
    name: &str,
    shaders: (&str, Option<&str>),
    target: DrawTarget,
) -> GpuResult<crate::vk::Pipeline> {
    let opts = match target {
        // The light's prop pass draws the bodies' map, in its own view.
        DrawTarget::ShadowDepth => device_shader_options(ctx, 1).define("BODY_MAP_PASS", 1),
        _ => device_shader_options(ctx, 1),
    };
    let v = compile(shaders.0, &opts)?;
    let f = shaders.1.map(|f| compile(f, &opts)).transpose()?;
    let mut desc = target
        .graphics_desc(name)
        .stage(ash::vk::ShaderStageFlags::VERTEX, &v);
    if let Some(f) = &f {
        desc = desc.stage(ash::vk::ShaderStageFlags::FRAGMENT, f);
    }
    crate::vk::Pipeline::graphics(ctx, layout, &desc)
}

/// A compute pipeline over its own set 0 of `bindings` storage buffers (passes outside the
/// frame's sets: the hair mesh update, LHS skinning): the set layout and the pipeline.
pub fn own_set_compute(
    ctx: &Arc<Context>,
    name: &str,
    shader: &str,
    bindings: impl IntoIterator<Item = u32>,
) -> GpuResult<(Arc<crate::vk::DescriptorSetLayout>, crate::vk::Pipeline)> {
    let bindings: Vec<crate::vk::BindingDesc> = bindings
        .into_iter()
        .map(|b| crate::vk::BindingDesc::single(b, crate::vk::DescriptorKind::StorageBuffer))
        .collect();
    let set_layout = crate::vk::DescriptorSetLayout::new(ctx, &bindings)?;
    let layout = PipelineLayout::new(ctx, std::slice::from_ref(&set_layout))?;
    let spirv = compile(shader, &device_shader_options(ctx, 1))?;
    let pipeline = crate::vk::Pipeline::compute(ctx, name, &layout, &spirv)?;
    Ok((set_layout, pipeline))
}

/// `(x, y)` workgroup counts for `groups` workgroups with at most `DISPATCH_ROW` per row.
pub fn dispatch_2d(groups: u32) -> (u32, u32) {
    let row = super::shared::DISPATCH_ROW;
    (groups.min(row), groups.div_ceil(row))
}
