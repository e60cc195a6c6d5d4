//! A host frame's passes around the renderer's own ([`super`]): first the
//! host's depth into the renderer's (`glsl/host_depth.frag`, or a clear when the host gives no
//! depth) with the colour cleared to transparent, then, after the frame, its hair composited
//! premultiplied over the host's colour (`glsl/host_composite.frag`), and the host's images
//! handed back in the uses the host asked for.
//!
//! Reads: the host's depth (sampled), the renderer's output image (sampled). Writes: the
//! renderer's colour and depth, the host's colour.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;

use super::DepthMapping;
use crate::render::core::binding::device_shader_options;
use crate::render::core::frame_res::FrameRes;
use crate::render::core::graph::{FrameGraph, Res};
use crate::render::core::pipelines::TargetFormats;
use crate::render::core::slots::FRAMES_IN_FLIGHT;
use crate::vk::shader::compile;
use crate::vk::{
    Access, Attachment, BindingDesc, BlendMode, Context, DepthMode, DescriptorKind, DescriptorSet,
    DescriptorSetLayout, GpuError, GpuResult, GraphicsDesc, Image, Pipeline, PipelineLayout,
    Sampler,
};

/// Binding of the host's depth in the passes' set.
const HOST_DEPTH_BINDING: u32 = 0;
/// Binding of the renderer's output image.
const HAIR_BINDING: u32 = 1;

/// The host frame passes' pipelines and per-slot sets.
///
/// The host's depth and the renderer's output sit in separate sets: a frame without host
/// depth binds no set that still names an earlier frame's depth (which the host may have
/// destroyed since).
pub struct HostTargetPasses {
    ctx: Arc<Context>,
    /// The composite's layout (the renderer's output).
    layout: Arc<PipelineLayout>,
    /// Per frame slot: the host's depth.
    depth_sets: Vec<DescriptorSet>,
    /// Per frame slot: the renderer's output.
    sets: Vec<DescriptorSet>,
    sampler: Sampler,
    depth: Pipeline,
    /// Composite pipelines by the host colour's format and samples.
    composite: HashMap<(vk::Format, u32), Pipeline>,
}

/// A host frame's images in the frame graph.
#[derive(Clone, Copy)]
pub struct HostTargetRes<'a> {
    /// The host's colour, its image and the use it is handed back in.
    pub color: (Res, &'a Image, Access),
    /// The host's depth, likewise, when there is one.
    pub depth: Option<(Res, Access)>,
}

impl HostTargetPasses {
    /// Compile the depth pass for the renderer's `targets`.
    pub fn new(ctx: &Arc<Context>, targets: TargetFormats) -> GpuResult<Self> {
        let set_layout = |b| {
            DescriptorSetLayout::new(ctx, &[BindingDesc::single(b, DescriptorKind::SampledImage)])
        };
        let (depth_set_layout, set_layout) =
            (set_layout(HOST_DEPTH_BINDING)?, set_layout(HAIR_BINDING)?);
        let depth_layout = PipelineLayout::new(ctx, std::slice::from_ref(&depth_set_layout))?;
        let layout = PipelineLayout::new(ctx, std::slice::from_ref(&set_layout))?;
        let opts = device_shader_options(ctx, 1);
        let v = compile("fullscreen.vert", &opts)?;
        let f = compile("host_depth.frag", &opts)?;
        let desc = targets
            .graphics_desc("host depth")
            .depth(DepthMode::Replace)
            .stage(vk::ShaderStageFlags::VERTEX, &v)
            .stage(vk::ShaderStageFlags::FRAGMENT, &f);
        let sets = |name, layout| {
            (0..FRAMES_IN_FLIGHT)
                .map(|_| DescriptorSet::new(ctx, name, layout))
                .collect::<GpuResult<Vec<_>>>()
        };
        Ok(HostTargetPasses {
            ctx: ctx.clone(),
            depth: Pipeline::graphics(ctx, &depth_layout, &desc)?,
            layout,
            depth_sets: sets("host depth set", &depth_set_layout)?,
            sets: sets("host composite set", &set_layout)?,
            sampler: Sampler::nearest_clamp(ctx)?,
            composite: HashMap::new(),
        })
    }

    /// Check the host's images (colour: a colour format; depth: a single-sample depth format
    /// created for sampling; both of one size) and compile the composite pipeline for the
    /// colour's format.
    pub fn prepare(&mut self, color: &Image, depth: Option<&Image>) -> GpuResult<()> {
        let refuse = |what: String| Err(GpuError::Unsupported(format!("host frame: {what}")));
        let c = &color.desc;
        if crate::vk::image::is_depth_format(c.format)
            || !c.usage.contains(vk::ImageUsageFlags::COLOR_ATTACHMENT)
        {
            return refuse(format!(
                "colour target {} ({:?}) is not a colour attachment",
                c.name, c.format
            ));
        }
        if let Some(d) = depth.map(|d| &d.desc) {
            if !crate::vk::image::is_depth_format(d.format)
                || !d.usage.contains(vk::ImageUsageFlags::SAMPLED)
                || d.samples != 1
            {
                return refuse(format!(
                    "depth {} ({:?}, {} samples) must be a single-sample depth image with SAMPLED usage",
                    d.name, d.format, d.samples
                ));
            }
            if d.extent != c.extent {
                return refuse(format!(
                    "depth {:?} and colour {:?} differ in size",
                    d.extent, c.extent
                ));
            }
        }
        let key = (c.format, c.samples);
        if let std::collections::hash_map::Entry::Vacant(e) = self.composite.entry(key) {
            let opts = device_shader_options(&self.ctx, 1);
            let v = compile("fullscreen.vert", &opts)?;
            let f = compile("host_composite.frag", &opts)?;
            let desc = GraphicsDesc::new("host composite", c.format, vk::Format::UNDEFINED)
                .samples(c.samples)
                .depth(DepthMode::Off)
                .blend(BlendMode::PremultipliedOver)
                .stage(vk::ShaderStageFlags::VERTEX, &v)
                .stage(vk::ShaderStageFlags::FRAGMENT, &f);
            e.insert(Pipeline::graphics(&self.ctx, &self.layout, &desc)?);
        }
        Ok(())
    }

    /// Point slot `slot`'s set at the host's depth and the renderer's `output` (the slot's last
    /// frame has completed).
    pub fn bind(&self, slot: usize, depth: Option<&Image>, output: &Image) -> GpuResult<()> {
        if let Some(d) = depth {
            self.depth_sets[slot].write_image(HOST_DEPTH_BINDING, 0, d, &self.sampler)?;
        }
        self.sets[slot].write_image(HAIR_BINDING, 0, output, &self.sampler)
    }

    /// Add the pass that fills the renderer's depth from the host's (`mapping`) and clears its
    /// colour to transparent; without a host depth, a clear of both.
    pub fn add_depth<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        slot: usize,
        (host, mapping): (Option<Res>, DepthMapping),
    ) {
        let (color, depth) = (r.images.color, r.images.depth);
        g.begin_scope("host depth");
        let p = g
            .pass("host depth")
            .discard(r.color, Access::ColorAttachment)
            .discard(r.depth, Access::DepthAttachment)
            .read_some(host, Access::SampledRead);
        let set = &self.depth_sets[slot];
        p.record(move |rec, _| {
            let clear = host.is_none();
            rec.begin_rendering(
                Attachment {
                    image: color,
                    clear: clear.then_some([0.0; 4]),
                    resolve: None,
                },
                Attachment {
                    image: depth,
                    clear: clear.then_some([1.0; 4]),
                    resolve: None,
                },
            );
            if !clear {
                rec.bind(&self.depth, &[set]);
                rec.push_constants(&self.depth, &mapping.constants());
                rec.draw(3);
            }
            rec.end_rendering();
            Ok(())
        });
        g.end_scope();
    }

    /// Add the composite of the renderer's output over the host's colour, then hand the host's
    /// images back in the uses it asked for.
    pub fn add_composite<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        slot: usize,
        host: HostTargetRes<'a>,
    ) -> GpuResult<()> {
        let (color_res, color, color_after) = host.color;
        let key = (color.desc.format, color.desc.samples);
        let pipeline = self.composite.get(&key).ok_or_else(|| {
            GpuError::Unsupported(format!("host frame: no composite pipeline for {key:?}"))
        })?;
        let set = &self.sets[slot];
        g.begin_scope("host composite");
        g.pass("host composite")
            .read(r.output, Access::SampledRead)
            .write(color_res, Access::ColorAttachment)
            .record(move |rec, _| {
                rec.begin_rendering_color(Attachment {
                    image: color,
                    clear: None,
                    resolve: None,
                });
                rec.bind(pipeline, &[set]);
                rec.draw(3);
                rec.end_rendering();
                Ok(())
            });
        g.end_scope();
        let mut back = g.pass("hand back host images");
        for (res, after) in std::iter::once((color_res, color_after)).chain(host.depth) {
            back = match after.writes() {
                true => back.write(res, after),
                false => back.read(res, after),
            };
        }
        back.done();
        Ok(())
    }
}
