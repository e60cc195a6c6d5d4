//! Command buffers and the typed recorder the passes use: bind, push constants, dispatch, draw,
//! mesh tasks, dynamic rendering, copies and barriers expressed as [`Access`] uses. Nothing
//! outside `vk/` records raw Vulkan commands.

use std::sync::Arc;

use ash::vk;
use bytemuck::Pod;

use super::access::{Access, masks};
use super::buffer::Buffer;
use super::descriptor::DescriptorSet;
use super::image::{Image, aspect};
use super::pipeline::Pipeline;
use super::swapchain::SwapchainImage;
use super::{Context, GpuError, GpuResult, VkContext};

/// A buffer <-> image copy of all of `image`, texels tightly packed.
fn whole_image_copy(image: &Image) -> vk::BufferImageCopy {
    let [width, height, depth] = image.desc.extent;
    vk::BufferImageCopy::default()
        .image_subresource(
            vk::ImageSubresourceLayers::default()
                .aspect_mask(aspect(image.desc.format))
                .layer_count(1),
        )
        .image_extent(vk::Extent3D {
            width,
            height,
            depth,
        })
}

/// A primary command buffer with its own pool, re-recorded every time it is used.
pub struct CommandBuffer {
    ctx: Arc<Context>,
    pool: vk::CommandPool,
    raw: vk::CommandBuffer,
}

impl CommandBuffer {
    /// A resettable command buffer on the context's queue family.
    pub fn new(ctx: &Arc<Context>, name: &str) -> GpuResult<Self> {
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create info.
        let pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }
            .ctx("create command pool")?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool was just created on this device.
        let raw = match unsafe { ctx.device.allocate_command_buffers(&alloc) } {
            Ok(v) => v[0],
            Err(e) => {
                // SAFETY: the pool has no buffers in use.
                unsafe { ctx.device.destroy_command_pool(pool, None) };
                return Err(GpuError::Vk {
                    what: "allocate command buffer",
                    result: e,
                });
            }
        };
        ctx.name_object(raw, name);
        Ok(CommandBuffer {
            ctx: ctx.clone(),
            pool,
            raw,
        })
    }

    /// Begin recording (the previous submission of this buffer must have completed).
    pub fn begin(&mut self) -> GpuResult<CommandRecorder<'_>> {
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: the caller waited for the previous submission (fence of its frame).
        unsafe {
            self.ctx
                .device
                .reset_command_buffer(self.raw, vk::CommandBufferResetFlags::empty())
                .ctx("reset command buffer")?;
            self.ctx
                .device
                .begin_command_buffer(self.raw, &begin)
                .ctx("begin command buffer")?;
        }
        Ok(CommandRecorder {
            ctx: &self.ctx,
            raw: self.raw,
            rendering: false,
            open_scopes: 0,
            unscoped: 0,
        })
    }

    /// Finish recording.
    pub fn end(&mut self) -> GpuResult<()> {
        // SAFETY: the buffer is in the recording state (begin succeeded).
        unsafe { self.ctx.device.end_command_buffer(self.raw) }.ctx("end command buffer")
    }

    pub(crate) fn raw(&self) -> vk::CommandBuffer {
        self.raw
    }
}

impl Drop for CommandBuffer {
    fn drop(&mut self) {
        // SAFETY: owners wait for the submission before dropping (frames retire first).
        unsafe { self.ctx.device.destroy_command_pool(self.pool, None) };
    }
}

/// A colour or depth attachment of a dynamic rendering instance.
#[derive(Clone, Copy)]
pub struct Attachment<'a> {
    /// The image (in the layout of [`Access::ColorAttachment`] / [`Access::DepthAttachment`]).
    pub image: &'a Image,
    /// Clear to this value, or keep the contents when `None`.
    pub clear: Option<[f32; 4]>,
    /// Multisampled colour: average the samples into this single-sample image (in
    /// [`Access::ColorAttachment`]) at the end of rendering.
    pub resolve: Option<&'a Image>,
}

/// An image a barrier transitions.
#[derive(Clone, Copy)]
pub enum BarrierImage<'a> {
    /// One of ours.
    Image(&'a Image),
    /// A swapchain image.
    Swapchain(&'a SwapchainImage),
}

/// One image's dependency in a [`CommandRecorder::pipeline_barrier`].
pub struct ImageBarrier<'a> {
    /// The image.
    pub image: BarrierImage<'a>,
    /// The uses to wait for (their stages; their writes are made available).
    pub prev: Vec<Access>,
    /// The use whose layout the image is in now (ignored with `discard`).
    pub from: Access,
    /// The next use (its layout is the new one).
    pub next: Access,
    /// The old contents are not needed: transition from `UNDEFINED`.
    pub discard: bool,
}

/// A rendering attachment for `a` in `layout`: stored, cleared to `a.clear` (depth from its
/// first component) or loaded, resolved into `a.resolve` where given.
fn attachment_info<'a>(a: &Attachment, layout: vk::ImageLayout) -> vk::RenderingAttachmentInfo<'a> {
    let mut info = vk::RenderingAttachmentInfo::default()
        .image_view(a.image.view())
        .image_layout(layout)
        .store_op(vk::AttachmentStoreOp::STORE);
    if let Some(r) = a.resolve {
        info = info
            .resolve_mode(vk::ResolveModeFlags::AVERAGE)
            .resolve_image_view(r.view())
            .resolve_image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
    }
    match a.clear {
        Some(c) => {
            let value = if layout == vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL {
                vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: c[0],
                        stencil: 0,
                    },
                }
            } else {
                vk::ClearValue {
                    color: vk::ClearColorValue { float32: c },
                }
            };
            info.load_op(vk::AttachmentLoadOp::CLEAR).clear_value(value)
        }
        None => info.load_op(vk::AttachmentLoadOp::LOAD),
    }
}

/// The whole of `image` as a render area.
fn full_area(image: &Image) -> vk::Rect2D {
    let [width, height, _] = image.desc.extent;
    vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent: vk::Extent2D { width, height },
    }
}

/// Records commands into a command buffer; every method is a safe wrapper of one Vulkan call.
pub struct CommandRecorder<'a> {
    ctx: &'a Context,
    raw: vk::CommandBuffer,
    rendering: bool,
    /// Timing scopes open now ([`super::Profiler::begin`] opens one).
    open_scopes: u32,
    /// Commands recorded while no timing scope was open.
    unscoped: u32,
}

impl<'a> CommandRecorder<'a> {
    /// Record into a host's command buffer `raw`: in the recording state, allocated on `ctx`'s
    /// device from a pool of its queue family, outside any render pass. The host ends and
    /// submits it.
    pub(crate) fn host(ctx: &'a Context, raw: vk::CommandBuffer) -> Self {
        CommandRecorder {
            ctx,
            raw,
            rendering: false,
            open_scopes: 0,
            unscoped: 0,
        }
    }
}

impl CommandRecorder<'_> {
    pub(crate) fn raw(&self) -> vk::CommandBuffer {
        self.raw
    }

    /// Count a command: one recorded while no timing scope is open is work the frame report
    /// could not attribute ([`Self::unscoped_commands`]).
    fn count_command(&mut self) {
        if self.open_scopes == 0 {
            self.unscoped += 1;
        }
    }

    /// A timing scope opened (`true`) or closed.
    pub(crate) fn scope_changed(&mut self, open: bool) {
        if open {
            self.open_scopes += 1;
        } else {
            self.open_scopes = self.open_scopes.saturating_sub(1);
        }
    }

    /// Commands recorded so far outside every timing scope (a frame's passes record none:
    /// the frame graph opens a scope around each pass that is not in one).
    pub fn unscoped_commands(&self) -> u32 {
        self.unscoped
    }

    /// Bind `pipeline` and its descriptor sets (set `i` = `sets[i]`).
    pub fn bind(&mut self, pipeline: &Pipeline, sets: &[&DescriptorSet]) {
        self.count_command();
        let raw_sets: Vec<vk::DescriptorSet> = sets.iter().map(|s| s.raw()).collect();
        // SAFETY: recording; the sets were created from the pipeline's set layouts.
        unsafe {
            self.ctx
                .device
                .cmd_bind_pipeline(self.raw, pipeline.bind_point(), pipeline.raw());
            if !raw_sets.is_empty() {
                self.ctx.device.cmd_bind_descriptor_sets(
                    self.raw,
                    pipeline.bind_point(),
                    pipeline.layout_raw(),
                    0,
                    &raw_sets,
                    &[],
                );
            }
        }
    }

    /// Set push constants of `pipeline` (all stages, offset 0).
    pub fn push_constants<T: Pod>(&mut self, pipeline: &Pipeline, data: &T) {
        self.count_command();
        let bytes = bytemuck::bytes_of(data);
        // Past the layout's range is undefined behaviour in the driver: never let it through.
        assert!(
            bytes.len() as u32 <= super::pipeline::PUSH_CONSTANT_BYTES,
            "{} bytes of push constants: the layouts hold {}",
            bytes.len(),
            super::pipeline::PUSH_CONSTANT_BYTES
        );
        // SAFETY: recording; the range lies within the layout's push constant range.
        unsafe {
            self.ctx.device.cmd_push_constants(
                self.raw,
                pipeline.layout_raw(),
                vk::ShaderStageFlags::ALL,
                0,
                bytes,
            )
        };
    }

    /// Dispatch a bound compute pipeline.
    pub fn dispatch(&mut self, x: u32, y: u32, z: u32) {
        self.count_command();
        // SAFETY: recording with a bound compute pipeline.
        unsafe { self.ctx.device.cmd_dispatch(self.raw, x, y, z) };
    }

    /// Dispatch with `VkDispatchIndirectCommand` at `offset` of `args`.
    pub fn dispatch_indirect(&mut self, args: &Buffer, offset: u64) {
        self.count_command();
        // SAFETY: recording; the buffer has INDIRECT_BUFFER usage (checked by validation).
        unsafe {
            self.ctx
                .device
                .cmd_dispatch_indirect(self.raw, args.raw(), offset)
        };
    }

    /// Draw `vertices` vertices of one instance (no vertex input; shaders pull their data).
    pub fn draw(&mut self, vertices: u32) {
        self.count_command();
        // SAFETY: recording inside a rendering instance with a bound graphics pipeline.
        unsafe { self.ctx.device.cmd_draw(self.raw, vertices, 1, 0, 0) };
    }

    /// Draw `instances` instances of `vertices` vertices starting at `first_vertex`, with
    /// instance indices from `first_instance`.
    pub fn draw_instanced(
        &mut self,
        vertices: u32,
        instances: u32,
        first_vertex: u32,
        first_instance: u32,
    ) {
        self.count_command();
        // SAFETY: recording inside a rendering instance with a bound graphics pipeline.
        unsafe {
            self.ctx
                .device
                .cmd_draw(self.raw, vertices, instances, first_vertex, first_instance)
        };
    }

    /// Draw `indices` 32-bit indices of `index` from `first_index`, `instances` instances from
    /// `first_instance` (no vertex input: the shader reads its vertex by `gl_VertexIndex`, the
    /// index, so the device can reuse a shaded vertex that several triangles share).
    pub fn draw_indexed_instanced(
        &mut self,
        index: &Buffer,
        (first_index, indices): (u32, u32),
        (first_instance, instances): (u32, u32),
    ) {
        self.count_command();
        // SAFETY: recording inside a rendering instance; the buffer has INDEX_BUFFER usage
        // (checked by validation) and the range lies within it (the caller's mesh table).
        unsafe {
            self.ctx
                .device
                .cmd_bind_index_buffer(self.raw, index.raw(), 0, vk::IndexType::UINT32);
            self.ctx.device.cmd_draw_indexed(
                self.raw,
                indices,
                instances,
                first_index,
                0,
                first_instance,
            )
        };
    }

    /// Draw with one `VkDrawIndirectCommand` at `offset` of `args`.
    pub fn draw_indirect(&mut self, args: &Buffer, offset: u64) {
        self.count_command();
        // SAFETY: recording inside a rendering instance.
        unsafe {
            self.ctx
                .device
                .cmd_draw_indirect(self.raw, args.raw(), offset, 1, 16)
        };
    }

    /// Launch task workgroups of a bound task/mesh pipeline.
    pub fn draw_mesh_tasks(&mut self, x: u32, y: u32, z: u32) -> GpuResult<()> {
        self.count_command();
        let ext = self
            .ctx
            .mesh_ext
            .as_ref()
            .ok_or_else(|| GpuError::Unsupported("VK_EXT_mesh_shader is not enabled".into()))?;
        // SAFETY: recording inside a rendering instance; counts checked by the caller against
        // maxTaskWorkGroupCount.
        unsafe { ext.cmd_draw_mesh_tasks(self.raw, x, y, z) };
        Ok(())
    }

    /// Begin dynamic rendering into `color` and `depth` over their full extent, with viewport
    /// and scissor covering it.
    pub fn begin_rendering(&mut self, color: Attachment, depth: Attachment) {
        self.count_command();
        let color_att = [attachment_info(
            &color,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        )];
        let depth_att = attachment_info(&depth, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL);
        let area = full_area(color.image);
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&color_att)
            .depth_attachment(&depth_att);
        self.begin(&info, area);
    }

    /// Begin dynamic rendering into `depth` only (shadow maps), viewport and scissor covering
    /// it.
    pub fn begin_rendering_depth(&mut self, depth: Attachment) {
        self.count_command();
        let att = attachment_info(&depth, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL);
        let area = full_area(depth.image);
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .depth_attachment(&att);
        self.begin(&info, area);
    }

    /// Begin dynamic rendering into `color` only (overlays such as the control panel, the deep
    /// opacity layers), viewport and scissor covering it.
    pub fn begin_rendering_color(&mut self, color: Attachment) {
        self.count_command();
        let atts = [attachment_info(
            &color,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        )];
        let area = full_area(color.image);
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&atts);
        self.begin(&info, area);
    }

    /// Begin dynamic rendering with no attachments over `width x height` (draws whose shaders
    /// only write buffers, such as the software rasterizer's mesh-shader segment pass).
    pub fn begin_rendering_empty(&mut self, width: u32, height: u32) {
        self.count_command();
        let area = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D { width, height },
        };
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1);
        self.begin(&info, area);
    }

    /// Begin rendering as `info` says, with viewport and scissor covering `area`.
    fn begin(&mut self, info: &vk::RenderingInfo, area: vk::Rect2D) {
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: area.extent.width as f32,
            height: area.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: the attachments are in the layouts `info` names (the callers' barriers) and
        // this command buffer is recording.
        unsafe {
            self.ctx.device.cmd_begin_rendering(self.raw, info);
            self.ctx.device.cmd_set_viewport(self.raw, 0, &[viewport]);
            self.ctx.device.cmd_set_scissor(self.raw, 0, &[area]);
        }
        self.rendering = true;
    }

    /// End the rendering instance begun last.
    pub fn end_rendering(&mut self) {
        if self.rendering {
            self.count_command();
            // SAFETY: matches begin_rendering.
            unsafe { self.ctx.device.cmd_end_rendering(self.raw) };
            self.rendering = false;
        }
    }

    /// A global memory dependency between buffer uses, for one-off submissions outside a
    /// frame (uploads, readbacks of tests).
    pub fn barrier(&mut self, prev: &[Access], next: &[Access]) {
        self.pipeline_barrier(Some((prev, next)), &[]);
    }

    /// An image dependency and layout transition from use `prev` to `next`, for one-off
    /// submissions outside a frame (uploads, texture readbacks).
    pub fn image_barrier(&mut self, image: &Image, prev: Access, next: Access) {
        let b = ImageBarrier {
            image: BarrierImage::Image(image),
            prev: vec![prev],
            from: prev,
            next,
            discard: false,
        };
        self.pipeline_barrier(None, &[b]);
    }

    /// One pipeline barrier: a global memory dependency from buffer uses `memory.0` to
    /// `memory.1` (when given) and the image dependencies and layout transitions of `images`.
    /// Task and mesh uses are dropped on devices without mesh shaders (they never ran there).
    /// The frame graph derives these from declared uses; nothing else should need them.
    pub fn pipeline_barrier(
        &mut self,
        memory: Option<(&[Access], &[Access])>,
        images: &[ImageBarrier],
    ) {
        self.count_command();
        let mesh = self.ctx.info.mesh_shader;
        let keep = |list: &[Access]| -> Vec<Access> {
            list.iter()
                .copied()
                .filter(|a| mesh || !a.is_mesh_stage())
                .collect()
        };
        let mut globals = Vec::new();
        if let Some((prev, next)) = memory {
            let (ss, sa, ds, da) = masks(&keep(prev), &keep(next));
            globals.push(
                vk::MemoryBarrier2::default()
                    .src_stage_mask(ss)
                    .src_access_mask(sa)
                    .dst_stage_mask(ds)
                    .dst_access_mask(da),
            );
        }
        let transitions: Vec<vk::ImageMemoryBarrier2> = images
            .iter()
            .map(|b| {
                let (ss, sa, ds, da) = masks(&keep(&b.prev), &[b.next]);
                let (raw, range) = match b.image {
                    BarrierImage::Image(i) => (i.raw(), i.full_range()),
                    BarrierImage::Swapchain(s) => (
                        s.raw,
                        vk::ImageSubresourceRange::default()
                            .aspect_mask(vk::ImageAspectFlags::COLOR)
                            .level_count(1)
                            .layer_count(1),
                    ),
                };
                // Presentation and acquisition order through semaphores; the transfer stage
                // keeps the masks valid for the swapchain's transitions.
                let extra = match b.image {
                    BarrierImage::Swapchain(_) => vk::PipelineStageFlags2::TRANSFER,
                    BarrierImage::Image(_) => vk::PipelineStageFlags2::NONE,
                };
                let old = if b.discard {
                    vk::ImageLayout::UNDEFINED
                } else {
                    b.from.layout()
                };
                vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(ss | extra)
                    .src_access_mask(sa)
                    .dst_stage_mask(ds | extra)
                    .dst_access_mask(da)
                    .old_layout(old)
                    .new_layout(b.next.layout())
                    .image(raw)
                    .subresource_range(range)
            })
            .collect();
        if globals.is_empty() && transitions.is_empty() {
            return;
        }
        let dep = vk::DependencyInfo::default()
            .memory_barriers(&globals)
            .image_memory_barriers(&transitions);
        // SAFETY: recording outside a rendering instance; the images are live.
        unsafe { self.ctx.device.cmd_pipeline_barrier2(self.raw, &dep) };
    }

    /// Scale-blit all of 2D image `src` (in [`Access::TransferRead`]) onto swapchain image
    /// `dst` (in [`Access::TransferWrite`]), linear filtering.
    pub fn blit_to_swapchain(&mut self, src: &Image, dst: &SwapchainImage) {
        self.count_command();
        let [w, h, _] = src.desc.extent;
        let layers = vk::ImageSubresourceLayers::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .layer_count(1);
        let region = [vk::ImageBlit::default()
            .src_subresource(layers)
            .src_offsets([
                vk::Offset3D::default(),
                vk::Offset3D {
                    x: w as i32,
                    y: h as i32,
                    z: 1,
                },
            ])
            .dst_subresource(layers)
            .dst_offsets([
                vk::Offset3D::default(),
                vk::Offset3D {
                    x: dst.extent[0] as i32,
                    y: dst.extent[1] as i32,
                    z: 1,
                },
            ])];
        // SAFETY: layouts as documented; both are colour images of blit-capable formats.
        unsafe {
            self.ctx.device.cmd_blit_image(
                self.raw,
                src.raw(),
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
                vk::Filter::LINEAR,
            )
        };
    }

    /// Fill `size` bytes at `offset` of `buffer` with the word `value`.
    pub fn fill_buffer(&mut self, buffer: &Buffer, offset: u64, size: u64, value: u32) {
        self.count_command();
        // SAFETY: recording outside rendering; range checked by validation (multiple of 4).
        unsafe {
            self.ctx
                .device
                .cmd_fill_buffer(self.raw, buffer.raw(), offset, size, value)
        };
    }

    /// Copy `size` bytes from `src` at `src_offset` to `dst` at `dst_offset`.
    pub fn copy_buffer(
        &mut self,
        src: &Buffer,
        src_offset: u64,
        dst: &Buffer,
        dst_offset: u64,
        size: u64,
    ) {
        self.count_command();
        let region = [vk::BufferCopy {
            src_offset,
            dst_offset,
            size,
        }];
        // SAFETY: recording outside rendering; ranges checked by validation.
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer(self.raw, src.raw(), dst.raw(), &region)
        };
    }

    /// Copy tightly packed texels from `src` into all of `dst` (in [`Access::TransferWrite`]).
    pub fn copy_buffer_to_image(&mut self, src: &Buffer, dst: &Image) {
        self.copy_buffer_to_image_at(src, 0, dst);
    }

    /// [`Self::copy_buffer_to_image`] with the texels from byte `offset` of `src`.
    pub fn copy_buffer_to_image_at(&mut self, src: &Buffer, offset: u64, dst: &Image) {
        self.count_command();
        let region = [whole_image_copy(dst).buffer_offset(offset)];
        // SAFETY: the image is in TRANSFER_DST_OPTIMAL; the buffer size is checked by the caller.
        unsafe {
            self.ctx.device.cmd_copy_buffer_to_image(
                self.raw,
                src.raw(),
                dst.raw(),
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
            )
        };
    }

    /// Copy all of 2D image `src` (in [`Access::TransferRead`]) into `dst`, tightly packed.
    pub fn copy_image_to_buffer(&mut self, src: &Image, dst: &Buffer) {
        self.copy_image_to_buffer_at(src, dst, 0);
    }

    /// Copy all of 2D image `src` (in [`Access::TransferRead`]) into `dst` from byte `offset`,
    /// tightly packed (depth images: their depth values).
    pub fn copy_image_to_buffer_at(&mut self, src: &Image, dst: &Buffer, offset: u64) {
        self.count_command();
        let region = [whole_image_copy(src).buffer_offset(offset)];
        // SAFETY: the image is in TRANSFER_SRC_OPTIMAL; the buffer size is checked by the caller.
        unsafe {
            self.ctx.device.cmd_copy_image_to_buffer(
                self.raw,
                src.raw(),
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw(),
                &region,
            )
        };
    }
}

impl Drop for CommandRecorder<'_> {
    fn drop(&mut self) {
        // A recorder dropped inside rendering (an error path) still leaves valid commands.
        self.end_rendering();
    }
}
