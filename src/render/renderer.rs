//! Headless renderer: owns the pipelines and render targets, renders characters to RGBA8.

use std::sync::Arc;

use ash::vk;
use glam::Vec3;

use super::compute_path::ComputeGenerate;
use super::draw::{COLOR_FORMAT, DEPTH_FORMAT, HairDraw};
use super::frame::{Camera, FrameParams};
use super::hair_gpu::{HAIR_VERTEX_BYTES, HairGpu};
use crate::vk::image::Sampler;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, BufferDesc, Context, GpuError, GpuResult, Image, ImageDesc};

/// A rendered frame and what it cost.
pub struct RenderOutput {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// RGBA8 pixels (sRGB), row-major, top row first.
    pub rgba: Vec<u8>,
    /// GPU milliseconds per pass, summed over characters, in first-seen order.
    pub pass_ms: Vec<(String, f64)>,
    /// Strands generated (after culling), over all characters.
    pub strands: u64,
    /// Strand triangles drawn.
    pub triangles: u64,
}

struct Pipelines {
    generate: ComputeGenerate,
    draw: HairDraw,
}

/// Renders hair characters headlessly.
pub struct Renderer {
    ctx: Arc<Context>,
    /// Linear clamp sampler for the five textures.
    pub sampler: Sampler,
    pipelines: Option<Pipelines>,
    profiler: Profiler,
    /// Background colour (linear RGB).
    pub background: [f32; 3],
}

impl Renderer {
    /// A renderer on `ctx`.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        Ok(Renderer {
            ctx: ctx.clone(),
            sampler: Sampler::linear_clamp(ctx)?,
            pipelines: None,
            profiler: Profiler::new(ctx, 64)?,
            background: [0.6, 0.65, 0.7],
        })
    }

    fn pipelines(&mut self, hair: &HairGpu) -> GpuResult<&Pipelines> {
        if self.pipelines.is_none() {
            self.pipelines = Some(Pipelines {
                generate: ComputeGenerate::new(&self.ctx, hair.set.layout)?,
                draw: HairDraw::new(&self.ctx, hair.set.layout)?,
            });
        }
        Ok(self.pipelines.as_ref().expect("just created"))
    }

    /// Render `hairs` from `camera` at `width x height`.
    pub fn render(
        &mut self,
        hairs: &[HairGpu],
        camera: &Camera,
        light_dir: Vec3,
        width: u32,
        height: u32,
    ) -> GpuResult<RenderOutput> {
        if hairs.is_empty() || width == 0 || height == 0 || width > 8192 || height > 8192 {
            return Err(GpuError::Unsupported(format!(
                "nothing to render or bad size {width}x{height}"
            )));
        }
        for hair in hairs {
            let frame = FrameParams::new(
                camera,
                light_dir,
                width,
                height,
                hair.params.strands_per_bundle,
                hair.params.verts_log2,
                hair.bundle_count(),
            );
            hair.frame.write_shared(bytemuck::bytes_of(&frame))?;
        }
        let ctx = self.ctx.clone();
        let color = Image::new(
            &ctx,
            &ImageDesc::new_2d("color", COLOR_FORMAT, width, height)
                .usage(vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC),
        )?;
        let depth = Image::new(
            &ctx,
            &ImageDesc::new_2d("depth", DEPTH_FORMAT, width, height)
                .usage(vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT),
        )?;
        let stats: Vec<Buffer> = hairs
            .iter()
            .map(|_| {
                Buffer::new(
                    &ctx,
                    &BufferDesc::new("indirect readback", 32, vk::BufferUsageFlags::TRANSFER_DST)
                        .readback(),
                )
            })
            .collect::<GpuResult<_>>()?;
        self.pipelines(&hairs[0])?;
        let pipelines = self.pipelines.as_ref().expect("created above");
        let profiler = &mut self.profiler;
        let background = self.background;
        let mut readback = ctx.submit_and_wait(|cmd| -> GpuResult<Buffer> {
            profiler.reset(cmd);
            color.transition(
                cmd,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            );
            depth.transition(
                cmd,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
            );
            for (i, (hair, stat)) in hairs.iter().zip(&stats).enumerate() {
                pipelines.generate.record(cmd, hair, profiler);
                let load = if i == 0 {
                    vk::AttachmentLoadOp::CLEAR
                } else {
                    vk::AttachmentLoadOp::LOAD
                };
                let color_att = [vk::RenderingAttachmentInfo::default()
                    .image_view(color.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(load)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        color: vk::ClearColorValue {
                            float32: [background[0], background[1], background[2], 1.0],
                        },
                    })];
                let depth_att = vk::RenderingAttachmentInfo::default()
                    .image_view(depth.view)
                    .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                    .load_op(load)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        depth_stencil: vk::ClearDepthStencilValue {
                            depth: 1.0,
                            stencil: 0,
                        },
                    });
                let area = vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent: vk::Extent2D { width, height },
                };
                let info = vk::RenderingInfo::default()
                    .render_area(area)
                    .layer_count(1)
                    .color_attachments(&color_att)
                    .depth_attachment(&depth_att);
                profiler.begin(cmd, "draw");
                // SAFETY: attachments are in the layouts named above; viewport covers the target.
                unsafe {
                    ctx.device.cmd_begin_rendering(cmd, &info);
                    ctx.device.cmd_set_viewport(
                        cmd,
                        0,
                        &[vk::Viewport {
                            x: 0.0,
                            y: 0.0,
                            width: width as f32,
                            height: height as f32,
                            min_depth: 0.0,
                            max_depth: 1.0,
                        }],
                    );
                    ctx.device.cmd_set_scissor(cmd, 0, &[area]);
                }
                pipelines.draw.record(cmd, hair);
                // SAFETY: matching begin above.
                unsafe {
                    ctx.device.cmd_end_rendering(cmd);
                    ctx.device.cmd_copy_buffer(
                        cmd,
                        hair.indirect.raw,
                        stat.raw,
                        &[vk::BufferCopy {
                            src_offset: 0,
                            dst_offset: 0,
                            size: 32,
                        }],
                    );
                }
                profiler.end(cmd);
                ctx.barrier(
                    cmd,
                    (
                        vk::PipelineStageFlags2::ALL_GRAPHICS,
                        vk::AccessFlags2::MEMORY_WRITE,
                    ),
                    (
                        vk::PipelineStageFlags2::ALL_GRAPHICS,
                        vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE,
                    ),
                );
            }
            color.transition(
                cmd,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            );
            color.record_readback(cmd)
        })??;
        let rgba = readback.read()?;
        let mut strands = 0;
        let mut triangles = 0;
        for (hair, mut s) in hairs.iter().zip(stats) {
            let words: Vec<u32> = bytemuck::pod_collect_to_vec(&s.read()?);
            strands += words[3] as u64;
            triangles += words[3] as u64 * (1u64 << hair.params.verts_log2) * 2;
        }
        let mut pass_ms: Vec<(String, f64)> = Vec::new();
        for (name, ms) in self.profiler.results()? {
            match pass_ms.iter_mut().find(|(n, _)| *n == name) {
                Some(e) => e.1 += ms,
                None => pass_ms.push((name, ms)),
            }
        }
        Ok(RenderOutput {
            width,
            height,
            rgba,
            pass_ms,
            strands,
            triangles,
        })
    }

    /// Read back the generated vertices of `hair` (`[x, y, z, width, tx, ty, tz, s]` each) and
    /// the number of strands generated by the last render.
    pub fn read_vertices(&self, hair: &HairGpu) -> GpuResult<(Vec<[f32; 8]>, u32)> {
        let ctx = &self.ctx;
        let mut verts = Buffer::new(
            ctx,
            &BufferDesc::new(
                "vertex readback",
                hair.vertices.size,
                vk::BufferUsageFlags::TRANSFER_DST,
            )
            .readback(),
        )?;
        let mut ind = Buffer::new(
            ctx,
            &BufferDesc::new("indirect readback", 32, vk::BufferUsageFlags::TRANSFER_DST)
                .readback(),
        )?;
        ctx.submit_and_wait(|cmd| {
            // SAFETY: both copies are within the buffers' sizes.
            unsafe {
                ctx.device.cmd_copy_buffer(
                    cmd,
                    hair.vertices.raw,
                    verts.raw,
                    &[vk::BufferCopy {
                        src_offset: 0,
                        dst_offset: 0,
                        size: hair.vertices.size,
                    }],
                );
                ctx.device.cmd_copy_buffer(
                    cmd,
                    hair.indirect.raw,
                    ind.raw,
                    &[vk::BufferCopy {
                        src_offset: 0,
                        dst_offset: 0,
                        size: 32,
                    }],
                );
            }
        })?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&ind.read()?);
        let total = words[3];
        let per = (1u64 << hair.params.verts_log2) + 1;
        let n = (total as u64 * per * HAIR_VERTEX_BYTES) as usize;
        let bytes = verts.read()?;
        Ok((
            bytemuck::pod_collect_to_vec(&bytes[..n.min(bytes.len())]),
            total,
        ))
    }
}
