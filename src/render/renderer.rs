//! Headless renderer: owns the pipelines and render targets, renders characters to RGBA8.

use std::sync::Arc;

use ash::vk;
use glam::Vec3;

use super::compute_path::ComputeGenerate;
use super::draw::{COLOR_FORMAT, DEPTH_FORMAT, HairDraw};
use super::frame::{Camera, FrameParams, LodSettings};
use super::hair_gpu::{HAIR_VERTEX_BYTES, HairGpu, INDIRECT_BYTES};
use crate::vk::image::Sampler;
use crate::vk::profiler::{MeshPrimitivesQuery, Profiler};
use crate::vk::{Buffer, BufferDesc, Context, GpuError, GpuResult, Image, ImageDesc};

/// Which generation path draws the strands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RenderPath {
    /// Task + mesh shaders (VK_EXT_mesh_shader).
    Mesh,
    /// Compute generation + vertex pulling.
    Compute,
}

/// Per-render choices.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderSettings {
    /// Forced path; `None` picks mesh where available, else compute.
    pub path: Option<RenderPath>,
    /// Level of detail.
    pub lod: LodSettings,
}

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
    /// Strands generated (after culling and LoD), over all characters.
    pub strands: u64,
    /// Strand triangles generated.
    pub triangles: u64,
    /// The path used.
    pub path: RenderPath,
    /// Mesh path: primitives the mesh shaders emitted, from `MESH_PRIMITIVES_GENERATED_EXT`
    /// queries where the device supports them.
    pub mesh_primitives_query: Option<u64>,
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
        settings: &RenderSettings,
    ) -> GpuResult<RenderOutput> {
        if hairs.is_empty() || width == 0 || height == 0 || width > 8192 || height > 8192 {
            return Err(GpuError::Unsupported(format!(
                "nothing to render or bad size {width}x{height}"
            )));
        }
        for hair in hairs {
            let p = &hair.params;
            let frame = FrameParams::new(
                camera,
                light_dir,
                width,
                height,
                p.strands_per_bundle,
                p.verts_log2,
                hair.bundle_count(),
                &settings.lod,
            );
            hair.frame.write_shared(bytemuck::bytes_of(&frame))?;
        }
        let ctx = self.ctx.clone();
        self.pipelines(&hairs[0])?;
        let pipelines = self.pipelines.as_ref().expect("created above");
        let path = match settings.path {
            Some(RenderPath::Mesh) if !pipelines.draw.has_mesh_path() => {
                return Err(GpuError::Unsupported(format!(
                    "{}: no usable VK_EXT_mesh_shader for --path mesh",
                    ctx.info.name
                )));
            }
            Some(p) => p,
            None if pipelines.draw.has_mesh_path() => RenderPath::Mesh,
            None => RenderPath::Compute,
        };
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
                    &BufferDesc::new(
                        "indirect readback",
                        INDIRECT_BYTES,
                        vk::BufferUsageFlags::TRANSFER_DST,
                    )
                    .readback(),
                )
            })
            .collect::<GpuResult<_>>()?;
        let mesh_query = if path == RenderPath::Mesh {
            MeshPrimitivesQuery::new(&ctx, hairs.len() as u32)?
        } else {
            None
        };
        let profiler = &mut self.profiler;
        let background = self.background;
        let mut readback = ctx.submit_and_wait(|cmd| -> GpuResult<Buffer> {
            profiler.reset(cmd);
            if let Some(q) = &mesh_query {
                q.reset(cmd);
            }
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
                match path {
                    RenderPath::Compute => pipelines.generate.record(cmd, hair, profiler),
                    RenderPath::Mesh => {
                        // The task shader accumulates statistics into the indirect block.
                        ctx.barrier(
                            cmd,
                            (
                                vk::PipelineStageFlags2::ALL_COMMANDS,
                                vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE,
                            ),
                            (
                                vk::PipelineStageFlags2::TRANSFER,
                                vk::AccessFlags2::TRANSFER_WRITE,
                            ),
                        );
                        // SAFETY: recording outside a render pass; the buffer allows TRANSFER_DST.
                        unsafe {
                            ctx.device
                                .cmd_fill_buffer(cmd, hair.indirect.raw, 0, INDIRECT_BYTES, 0)
                        };
                        ctx.barrier(
                            cmd,
                            (
                                vk::PipelineStageFlags2::TRANSFER,
                                vk::AccessFlags2::TRANSFER_WRITE,
                            ),
                            (
                                vk::PipelineStageFlags2::TASK_SHADER_EXT,
                                vk::AccessFlags2::SHADER_STORAGE_READ
                                    | vk::AccessFlags2::SHADER_STORAGE_WRITE,
                            ),
                        );
                    }
                }
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
                profiler.begin(
                    cmd,
                    if path == RenderPath::Mesh {
                        "mesh draw"
                    } else {
                        "draw"
                    },
                );
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
                pipelines.draw.record_scalp(cmd, hair);
                match path {
                    RenderPath::Compute => pipelines.draw.record_pulled_strands(cmd, hair),
                    RenderPath::Mesh => {
                        if let Some(q) = &mesh_query {
                            q.begin(cmd, i as u32);
                        }
                        pipelines.draw.record_mesh_strands(cmd, hair);
                        if let Some(q) = &mesh_query {
                            q.end(cmd, i as u32);
                        }
                    }
                }
                // SAFETY: matching begin above.
                unsafe { ctx.device.cmd_end_rendering(cmd) };
                profiler.end(cmd);
                ctx.barrier(
                    cmd,
                    (
                        vk::PipelineStageFlags2::ALL_COMMANDS,
                        vk::AccessFlags2::MEMORY_WRITE,
                    ),
                    (
                        vk::PipelineStageFlags2::ALL_COMMANDS,
                        vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE,
                    ),
                );
                // SAFETY: the barrier above orders the shader writes before this copy.
                unsafe {
                    ctx.device.cmd_copy_buffer(
                        cmd,
                        hair.indirect.raw,
                        stat.raw,
                        &[vk::BufferCopy {
                            src_offset: 0,
                            dst_offset: 0,
                            size: INDIRECT_BYTES,
                        }],
                    )
                };
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
        for mut s in stats {
            let words: Vec<u32> = bytemuck::pod_collect_to_vec(&s.read()?);
            strands += words[3] as u64;
            triangles += words[8] as u64;
        }
        let mesh_primitives_query = match &mesh_query {
            Some(q) => Some(q.total(hairs.len() as u32)?),
            None => None,
        };
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
            path,
            mesh_primitives_query,
        })
    }

    /// Read back the compute path's generated vertices of `hair` (`[x, y, z, width, tx, ty, tz,
    /// s]` each, bundle-major) and the number of strands of the last render.
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
            &BufferDesc::new(
                "indirect readback",
                INDIRECT_BYTES,
                vk::BufferUsageFlags::TRANSFER_DST,
            )
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
                        size: INDIRECT_BYTES,
                    }],
                );
            }
        })?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&ind.read()?);
        let n = (words[9] as u64 * HAIR_VERTEX_BYTES) as usize;
        let bytes = verts.read()?;
        Ok((
            bytemuck::pod_collect_to_vec(&bytes[..n.min(bytes.len())]),
            words[3],
        ))
    }
}
