//! Transparent strands (`render::transparency`): the k-buffer insert and its resolve, or depth
//! peeling and its resolve, after the opaque pass; what each pass reads and writes is
//! declared where it is added to the frame graph.
//!
//! Pipelines are compiled the first time a frame uses their mode.

use std::sync::Arc;

use ash::vk;

use super::strands::{StrandDraw, StrandUse, strand_uses};
use super::{DrawTarget, FrameRes, PassSets, TargetFormats, device_shader_options};
use crate::render::RenderPath;
use crate::render::core::graph::FrameGraph;
use crate::render::transparency::Transparency;
use crate::vk::shader::compile;
use crate::vk::{
    Access, Attachment, BlendMode, Context, DepthMode, GpuError, GpuResult, MeshPrimitivesQuery,
    Pipeline, PipelineLayout,
};

/// What the transparent passes of one frame draw.
pub struct TransparentDraw<'a> {
    /// The mode (not opaque).
    pub mode: Transparency,
    /// Camera sets.
    pub sets: PassSets<'a>,
    /// Bundles of all characters.
    pub bundles: u32,
    /// Generation path (compute: the vertex pool is already generated).
    pub path: RenderPath,
    /// Target size.
    pub size: (u32, u32),
    /// Mesh-primitive query of the frame (wraps the k-buffer insert).
    pub mesh_query: Option<&'a mut MeshPrimitivesQuery>,
}

struct KBufferPipelines {
    insert: StrandDraw,
    resolve: Pipeline,
}

struct PeelPipelines {
    depth: StrandDraw,
    color: StrandDraw,
    resolve: Pipeline,
}

/// The transparent passes.
pub struct TransparencyPass {
    ctx: Arc<Context>,
    layout: Arc<PipelineLayout>,
    formats: TargetFormats,
    task_bundles: u32,
    kbuffer: Option<KBufferPipelines>,
    peel: Option<PeelPipelines>,
}

impl TransparencyPass {
    /// Nothing compiled yet; `formats` are the camera targets'.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        formats: TargetFormats,
        task_bundles: u32,
    ) -> Self {
        TransparencyPass {
            ctx: ctx.clone(),
            layout: layout.clone(),
            formats,
            task_bundles,
            kbuffer: None,
            peel: None,
        }
    }

    /// Check that the device and targets support `mode`, and compile its pipelines if this is
    /// its first use.
    pub fn prepare(&mut self, mode: Transparency) -> GpuResult<()> {
        match mode {
            Transparency::Opaque => {}
            Transparency::KBuffer { .. } => {
                if !self.ctx.info.int64_atomics {
                    return Err(GpuError::Unsupported(format!(
                        "{}: k-buffer OIT needs shaderInt64 and shaderBufferInt64Atomics",
                        self.ctx.info.name
                    )));
                }
                if self.kbuffer.is_none() {
                    self.kbuffer = Some(KBufferPipelines {
                        insert: self.strands(DrawTarget::OitInsert(self.formats))?,
                        resolve: self.resolve_pipeline(false)?,
                    });
                }
            }
            Transparency::DepthPeeling { .. } => {
                if self.formats.samples > 1 {
                    return Err(GpuError::Unsupported(
                        "depth peeling is the single-sample reference: use it without MSAA".into(),
                    ));
                }
                if self.peel.is_none() {
                    self.peel = Some(PeelPipelines {
                        depth: self.strands(DrawTarget::PeelDepth)?,
                        color: self.strands(DrawTarget::PeelColor)?,
                        resolve: self.resolve_pipeline(true)?,
                    });
                }
            }
        }
        Ok(())
    }

    fn strands(&self, target: DrawTarget) -> GpuResult<StrandDraw> {
        StrandDraw::new(&self.ctx, &self.layout, target, self.task_bundles)
    }

    fn resolve_pipeline(&self, peel: bool) -> GpuResult<Pipeline> {
        let mut opts = device_shader_options(&self.ctx, 1);
        if peel {
            opts = opts.define("PEEL_RESOLVE", 1);
        }
        let v = compile("fullscreen.vert", &opts)?;
        let f = compile("oit_resolve.frag", &opts)?;
        let desc = self
            .formats
            .graphics_desc(if peel { "peel resolve" } else { "oit resolve" })
            .depth(DepthMode::Off)
            .blend(BlendMode::PremultipliedOver)
            .stage(vk::ShaderStageFlags::VERTEX, &v)
            .stage(vk::ShaderStageFlags::FRAGMENT, &f);
        Pipeline::graphics(&self.ctx, &self.layout, &desc)
    }

    /// Add the pass that empties the k-buffer of `budget` nodes per pixel for `pixels`
    /// pixels (before the k-buffer insert or the software rasterizer).
    pub fn add_kbuffer_clear<'a>(
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        budget: u32,
        pixels: u64,
    ) {
        let (nodes, tail) = (r.oit_nodes, r.oit_tail);
        g.pass("k-buffer clear")
            .discard(nodes, Access::TransferWrite)
            .discard(tail, Access::TransferWrite)
            .record(move |rec, res| {
                rec.fill_buffer(res.buffer(nodes)?, 0, pixels * budget as u64 * 8, u32::MAX);
                rec.fill_buffer(res.buffer(tail)?, 0, pixels * 16, 0);
                Ok(())
            });
    }

    /// Add the transparent strand passes of `draw.mode` (prepared with [`Self::prepare`]):
    /// the k-buffer clear and insert, or the peeled layers; [`Self::add_resolve`] composites
    /// them.
    pub fn add_layers<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        draw: TransparentDraw<'a>,
    ) -> GpuResult<()> {
        let unprepared = || GpuError::Unsupported("transparency pipelines not prepared".into());
        let (w, h) = draw.size;
        let pixels = w as u64 * h as u64;
        match draw.mode {
            Transparency::Opaque => Ok(()),
            Transparency::KBuffer { budget } => {
                let p = self.kbuffer.as_ref().ok_or_else(unprepared)?;
                Self::add_kbuffer_clear(g, r, budget, pixels);
                g.begin_scope("oit insert");
                let pass = g
                    .pass("oit insert")
                    .write(r.depth, Access::DepthAttachment)
                    .write(r.oit_nodes, Access::FragmentReadWrite)
                    .write(r.oit_tail, Access::FragmentReadWrite)
                    .write_some(r.visibility, Access::FragmentReadWrite);
                let (sets, bundles, path, args) =
                    (draw.sets, draw.bundles, draw.path, r.args_buffer);
                let depth = r.images.depth;
                let mut query = draw.mesh_query.filter(|_| path == RenderPath::Mesh);
                strand_uses(pass, r, path, StrandUse::CameraShaded).record(move |rec, _| {
                    rec.begin_rendering_depth(Attachment {
                        image: depth,
                        clear: None,
                        resolve: None,
                    });
                    if let Some(q) = query.as_deref_mut() {
                        q.begin(rec);
                    }
                    let result = p.insert.record(rec, sets, bundles, path, args);
                    if let Some(q) = query {
                        q.end(rec);
                    }
                    rec.end_rendering();
                    result
                });
                g.end_scope();
                Ok(())
            }
            Transparency::DepthPeeling { layers } => {
                let p = self.peel.as_ref().ok_or_else(unprepared)?;
                Self::add_peeling(g, r, p, &draw, layers, pixels)
            }
        }
    }

    /// Add the pass that composites the k-buffer (`peel` false) or the peeling accumulation
    /// over the colour target (and its MSAA resolve).
    pub fn add_resolve<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        peel: bool,
        sets: PassSets<'a>,
    ) -> GpuResult<()> {
        let unprepared = || GpuError::Unsupported("transparency pipelines not prepared".into());
        let resolve = if peel {
            &self.peel.as_ref().ok_or_else(unprepared)?.resolve
        } else {
            &self.kbuffer.as_ref().ok_or_else(unprepared)?.resolve
        };
        g.begin_scope("transparency resolve");
        let mut pass = g
            .pass("transparency resolve")
            .read(r.constants, Access::FragmentRead)
            .write(r.color, Access::ColorAttachment);
        pass = if peel {
            pass.read(r.peel_accum, Access::FragmentRead)
        } else {
            pass.read_all(&[r.oit_nodes, r.oit_tail], Access::FragmentRead)
        };
        if let Some(resolved) = r.resolved {
            // The resolve overwrites every pixel.
            pass = pass.discard(resolved, Access::ColorAttachment);
        }
        let (color, resolved) = (r.images.color, r.images.resolved);
        pass.record(move |rec, _| {
            rec.begin_rendering_color(Attachment {
                image: color,
                clear: None,
                resolve: resolved,
            });
            rec.bind(resolve, &sets.both());
            rec.draw(3);
            rec.end_rendering();
            Ok(())
        });
        g.end_scope();
        Ok(())
    }

    /// `layers` depth-peeling layers, each composited under the ones before into the
    /// accumulation buffer.
    fn add_peeling<'a>(
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        p: &'a PeelPipelines,
        draw: &TransparentDraw<'a>,
        layers: u32,
        pixels: u64,
    ) -> GpuResult<()> {
        let missing = || GpuError::Unsupported("peel depth image not declared".into());
        let image_res = r.peel_image.ok_or_else(missing)?;
        let (peel_depth, peel_accum, depth) = (r.peel_depth, r.peel_accum, r.images.depth);
        g.begin_scope("peel layers");
        // Previous layer: depth 0 (nothing peeled); opaque depth in the second half.
        g.pass("peel setup")
            .read(r.depth, Access::TransferRead)
            .discard(r.peel_depth, Access::TransferWrite)
            .discard(r.peel_accum, Access::TransferWrite)
            .record(move |rec, res| {
                let prev = res.buffer(peel_depth)?;
                rec.fill_buffer(prev, 0, pixels * 4, 0);
                rec.copy_image_to_buffer_at(depth, prev, pixels * 4);
                rec.fill_buffer(res.buffer(peel_accum)?, 0, pixels * 16, 0);
                Ok(())
            });
        let (sets, bundles, path, args) = (draw.sets, draw.bundles, draw.path, r.args_buffer);
        let mesh = path == RenderPath::Mesh;
        for _ in 0..layers {
            for (i, strands) in [&p.depth, &p.color].into_iter().enumerate() {
                if mesh {
                    // The task shader counts statistics again: keep one pass's worth.
                    super::add_clear_args(g, r);
                }
                let pass = if i == 0 {
                    g.pass("peel depth")
                        .discard(image_res, Access::DepthAttachment)
                } else {
                    g.pass("peel colour")
                        .write(image_res, Access::DepthAttachment)
                        .write(r.peel_accum, Access::FragmentReadWrite)
                        .write_some(r.visibility, Access::FragmentReadWrite)
                };
                let pass = pass.read(r.peel_depth, Access::FragmentRead);
                let used = match i {
                    0 => StrandUse::CameraDepth,
                    _ => StrandUse::CameraShaded,
                };
                strand_uses(pass, r, path, used).record(move |rec, res| {
                    rec.begin_rendering_depth(Attachment {
                        image: res.image(image_res)?,
                        clear: (i == 0).then_some([1.0; 4]),
                        resolve: None,
                    });
                    let result = strands.record(rec, sets, bundles, path, args);
                    rec.end_rendering();
                    result
                });
            }
            // This layer's depth becomes the next layer's "previous".
            g.pass("peel copy")
                .read(image_res, Access::TransferRead)
                .write(r.peel_depth, Access::TransferWrite)
                .record(move |rec, res| {
                    rec.copy_image_to_buffer_at(res.image(image_res)?, res.buffer(peel_depth)?, 0);
                    Ok(())
                });
        }
        g.end_scope();
        Ok(())
    }
}
