//! Transparent strands (`render::transparency`): the k-buffer insert and its resolve, or depth
//! peeling and its resolve, after the opaque pass. Reads: frame block, crowd tables, the
//! vertex pool (compute) or textures (mesh), the opaque depth. Writes: the per-pixel buffers
//! (`TransparencyBuffers`), then the colour target (and its MSAA resolve).
//!
//! Pipelines are compiled the first time a frame uses their mode.

use std::sync::Arc;

use ash::vk;

use super::strands::StrandDraw;
use super::{DrawTarget, PassSets, TargetFormats, clear_args, shader_options};
use crate::render::RenderPath;
use crate::render::targets::RenderTargets;
use crate::render::transparency::{Transparency, TransparencyBuffers};
use crate::vk::shader::compile;
use crate::vk::{
    Access, Attachment, BlendMode, Buffer, CommandRecorder, Context, DepthMode, GpuError,
    GpuResult, MeshPrimitivesQuery, Pipeline, PipelineLayout, Profiler,
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
    /// `GenerateArgs` (the compute path's draw arguments; the mesh path's statistics).
    pub args: &'a Buffer,
    /// Colour and depth after the opaque pass.
    pub targets: &'a mut RenderTargets,
    /// Per-pixel buffers, sized for this mode and size.
    pub buffers: &'a mut TransparencyBuffers,
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
        let mut opts = shader_options(1);
        if peel {
            opts = opts.define("PEEL_RESOLVE", 1);
        }
        let v = compile("fullscreen.vert", &opts)?;
        let f = compile("oit_resolve.frag", &opts)?;
        let desc = self
            .formats
            .graphics_desc(if peel { "peel resolve" } else { "oit resolve" })
            .depth(DepthMode::Off)
            .blend(BlendMode::Transmittance)
            .stage(vk::ShaderStageFlags::VERTEX, &v)
            .stage(vk::ShaderStageFlags::FRAGMENT, &f);
        Pipeline::graphics(&self.ctx, &self.layout, &desc)
    }

    /// Empty the k-buffer of `budget` nodes per pixel for `pixels` pixels (before the
    /// k-buffer insert or the software rasterizer).
    pub fn clear_kbuffer(
        rec: &mut CommandRecorder,
        buffers: &TransparencyBuffers,
        budget: u32,
        pixels: u64,
    ) {
        rec.barrier(
            &[Access::FragmentReadWrite, Access::ComputeReadWrite],
            &[Access::TransferWrite],
        );
        rec.fill_buffer(&buffers.nodes, 0, pixels * budget as u64 * 8, u32::MAX);
        rec.fill_buffer(&buffers.tail, 0, pixels * 16, 0);
        rec.barrier(
            &[Access::TransferWrite],
            &[Access::FragmentReadWrite, Access::ComputeReadWrite],
        );
    }

    /// Record the transparent strand passes of `draw.mode` (prepared with [`Self::prepare`]):
    /// the k-buffer clear and insert, or the peeled layers; [`Self::record_resolve`]
    /// composites them.
    pub fn record_layers(
        &self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        mut draw: TransparentDraw,
    ) -> GpuResult<()> {
        let unprepared = || GpuError::Unsupported("transparency pipelines not prepared".into());
        let (w, h) = draw.targets.size();
        let pixels = w as u64 * h as u64;
        match draw.mode {
            Transparency::Opaque => Ok(()),
            Transparency::KBuffer { budget } => {
                let p = self.kbuffer.as_ref().ok_or_else(unprepared)?;
                Self::clear_kbuffer(rec, draw.buffers, budget, pixels);
                let t = &*draw.targets;
                rec.image_barrier(&t.depth, t.depth_access, Access::DepthAttachment);
                profiler.begin(rec, "oit insert");
                rec.begin_rendering_depth(Attachment {
                    image: &t.depth,
                    clear: None,
                    resolve: None,
                });
                let mut query = draw.mesh_query;
                if let Some(q) = query
                    .as_deref_mut()
                    .filter(|_| draw.path == RenderPath::Mesh)
                {
                    q.begin(rec);
                }
                let result = p
                    .insert
                    .record(rec, draw.sets, draw.bundles, draw.path, draw.args);
                if let Some(q) = query.filter(|_| draw.path == RenderPath::Mesh) {
                    q.end(rec);
                }
                rec.end_rendering();
                profiler.end(rec);
                result?;
                draw.targets.depth_access = Access::DepthAttachment;
                Ok(())
            }
            Transparency::DepthPeeling { layers } => {
                let p = self.peel.as_ref().ok_or_else(unprepared)?;
                Self::record_peeling(rec, profiler, p, &mut draw, layers, pixels)?;
                draw.targets.depth_access = Access::TransferRead;
                Ok(())
            }
        }
    }

    /// Composite the k-buffer (`peel` false) or the peeling accumulation over the colour
    /// target (and its MSAA resolve), leaving them as colour attachments.
    pub fn record_resolve(
        &self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        peel: bool,
        sets: PassSets,
        targets: &RenderTargets,
    ) -> GpuResult<()> {
        let unprepared = || GpuError::Unsupported("transparency pipelines not prepared".into());
        let resolve = if peel {
            &self.peel.as_ref().ok_or_else(unprepared)?.resolve
        } else {
            &self.kbuffer.as_ref().ok_or_else(unprepared)?.resolve
        };
        rec.barrier(
            &[Access::FragmentReadWrite, Access::ComputeReadWrite],
            &[Access::FragmentReadWrite],
        );
        let t = targets;
        rec.image_barrier(&t.color, Access::ColorAttachment, Access::ColorAttachment);
        profiler.begin(rec, "transparency resolve");
        rec.begin_rendering_color(Attachment {
            image: &t.color,
            clear: None,
            resolve: t.resolved.as_ref(),
        });
        rec.bind(resolve, &sets.both());
        rec.draw(3);
        rec.end_rendering();
        profiler.end(rec);
        Ok(())
    }

    /// `layers` depth-peeling layers, each composited under the ones before into the
    /// accumulation buffer.
    fn record_peeling(
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        p: &PeelPipelines,
        draw: &mut TransparentDraw,
        layers: u32,
        pixels: u64,
    ) -> GpuResult<()> {
        let t = &*draw.targets;
        let TransparencyBuffers {
            peel_image,
            peel_access,
            peel_depth,
            peel_accum,
            ..
        } = &mut *draw.buffers;
        let image = peel_image
            .as_ref()
            .ok_or_else(|| GpuError::Unsupported("peel depth image not allocated".into()))?;
        // Previous layer: depth 0 (nothing peeled); opaque depth in the second half.
        rec.image_barrier(&t.depth, t.depth_access, Access::TransferRead);
        rec.barrier(&[Access::FragmentReadWrite], &[Access::TransferWrite]);
        rec.fill_buffer(peel_depth, 0, pixels * 4, 0);
        rec.copy_image_to_buffer_at(&t.depth, peel_depth, pixels * 4);
        rec.fill_buffer(peel_accum, 0, pixels * 16, 0);
        rec.barrier(&[Access::TransferWrite], &[Access::FragmentReadWrite]);
        let mesh = draw.path == RenderPath::Mesh;
        let att = |clear| Attachment {
            image,
            clear,
            resolve: None,
        };
        profiler.begin(rec, "peel layers");
        let mut result = Ok(());
        for layer in 0..layers {
            let from = if layer == 0 {
                *peel_access
            } else {
                Access::TransferRead
            };
            rec.image_barrier(image, from, Access::DepthAttachment);
            for (i, strands) in [&p.depth, &p.color].into_iter().enumerate() {
                if i == 1 {
                    rec.image_barrier(image, Access::DepthAttachment, Access::DepthAttachment);
                }
                if mesh {
                    // The task shader counts statistics again: keep one pass's worth.
                    clear_args(rec, draw.args);
                }
                rec.begin_rendering_depth(att(if i == 0 { Some([1.0; 4]) } else { None }));
                result =
                    result.and(strands.record(rec, draw.sets, draw.bundles, draw.path, draw.args));
                rec.end_rendering();
            }
            // This layer's depth becomes the next layer's "previous".
            rec.barrier(
                &[Access::FragmentReadWrite],
                &[Access::FragmentReadWrite, Access::TransferWrite],
            );
            rec.image_barrier(image, Access::DepthAttachment, Access::TransferRead);
            rec.copy_image_to_buffer_at(image, peel_depth, 0);
            rec.barrier(&[Access::TransferWrite], &[Access::FragmentReadWrite]);
        }
        profiler.end(rec);
        *peel_access = Access::TransferRead;
        result
    }
}
