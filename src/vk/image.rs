//! 2D/3D images, views, samplers, uploads and readback.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::Allocation;

use super::buffer::{Buffer, BufferDesc};
use super::{Context, GpuError, GpuResult, VkContext};

/// How to create an [`Image`].
#[derive(Clone, Debug)]
pub struct ImageDesc {
    /// Debug name.
    pub name: String,
    /// `[width, height, depth]`; depth 1 and `dim_3d == false` for 2D.
    pub extent: [u32; 3],
    /// Texel format.
    pub format: vk::Format,
    /// Usage flags.
    pub usage: vk::ImageUsageFlags,
    /// A 3D image.
    pub dim_3d: bool,
}

impl ImageDesc {
    /// A 2D image.
    pub fn new_2d(name: &str, format: vk::Format, width: u32, height: u32) -> Self {
        ImageDesc {
            name: name.into(),
            extent: [width, height, 1],
            format,
            usage: vk::ImageUsageFlags::empty(),
            dim_3d: false,
        }
    }

    /// A 3D image.
    pub fn new_3d(name: &str, format: vk::Format, extent: [u32; 3]) -> Self {
        ImageDesc {
            name: name.into(),
            extent,
            format,
            usage: vk::ImageUsageFlags::empty(),
            dim_3d: true,
        }
    }

    /// Add usage flags.
    pub fn usage(mut self, usage: vk::ImageUsageFlags) -> Self {
        self.usage |= usage;
        self
    }
}

/// An image with one mip level and one layer, its memory and a full view.
pub struct Image {
    ctx: Arc<Context>,
    /// The raw image.
    pub raw: vk::Image,
    /// A view of the whole image.
    pub view: vk::ImageView,
    allocation: Option<Allocation>,
    /// Creation parameters.
    pub desc: ImageDesc,
}

fn aspect(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM => vk::ImageAspectFlags::DEPTH,
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// Bytes per texel of the formats this project uses.
pub fn texel_bytes(format: vk::Format) -> u64 {
    match format {
        vk::Format::R16_UNORM => 2,
        vk::Format::R16G16_UNORM
        | vk::Format::R8G8B8A8_UNORM
        | vk::Format::R8G8B8A8_SRGB
        | vk::Format::D32_SFLOAT => 4,
        vk::Format::R16G16B16A16_UNORM | vk::Format::R16G16B16A16_SNORM => 8,
        vk::Format::R32G32B32A32_SFLOAT => 16,
        _ => 0,
    }
}

impl Image {
    /// Create an image as described.
    pub fn new(ctx: &Arc<Context>, desc: &ImageDesc) -> GpuResult<Self> {
        let info = vk::ImageCreateInfo::default()
            .image_type(if desc.dim_3d {
                vk::ImageType::TYPE_3D
            } else {
                vk::ImageType::TYPE_2D
            })
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.extent[0],
                height: desc.extent[1],
                depth: desc.extent[2],
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid create info.
        let raw = unsafe { ctx.device.create_image(&info, None) }.ctx("create image")?;
        // SAFETY: `raw` belongs to this device.
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let allocation = ctx.allocate_bound(
            &desc.name,
            requirements,
            MemoryLocation::GpuOnly,
            false,
            |memory, offset| {
                // SAFETY: memory from the allocator matches the requirements of `raw`.
                unsafe { ctx.device.bind_image_memory(raw, memory, offset) }
            },
        );
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: unbound image, unused.
                unsafe { ctx.device.destroy_image(raw, None) };
                return Err(e);
            }
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(if desc.dim_3d {
                vk::ImageViewType::TYPE_3D
            } else {
                vk::ImageViewType::TYPE_2D
            })
            .format(desc.format)
            .subresource_range(Self::range(desc.format));
        // SAFETY: view of a bound image.
        let view =
            unsafe { ctx.device.create_image_view(&view_info, None) }.ctx("create image view")?;
        ctx.name_object(raw, &desc.name);
        ctx.name_object(view, &desc.name);
        Ok(Image {
            ctx: ctx.clone(),
            raw,
            view,
            allocation: Some(allocation),
            desc: desc.clone(),
        })
    }

    fn range(format: vk::Format) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default()
            .aspect_mask(aspect(format))
            .level_count(1)
            .layer_count(1)
    }

    /// Record a layout transition with full stage/access masks (simple and correct).
    pub fn transition(&self, cmd: vk::CommandBuffer, from: vk::ImageLayout, to: vk::ImageLayout) {
        let barrier = [vk::ImageMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
            .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
            .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
            .old_layout(from)
            .new_layout(to)
            .image(self.raw)
            .subresource_range(Self::range(self.desc.format))];
        let dep = vk::DependencyInfo::default().image_memory_barriers(&barrier);
        // SAFETY: recording into a command buffer in the recording state.
        unsafe { self.ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
    }

    /// Create a sampled image holding `data` (tightly packed texels), in
    /// `SHADER_READ_ONLY_OPTIMAL` layout.
    pub fn with_data(ctx: &Arc<Context>, desc: &ImageDesc, data: &[u8]) -> GpuResult<Self> {
        let [w, h, d] = desc.extent;
        let expected = w as u64 * h as u64 * d as u64 * texel_bytes(desc.format);
        if expected != data.len() as u64 {
            return Err(GpuError::Unsupported(format!(
                "{}: {} bytes for a {expected}-byte image",
                desc.name,
                data.len()
            )));
        }
        let desc = desc
            .clone()
            .usage(vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST);
        let image = Image::new(ctx, &desc)?;
        let staging = Buffer::with_data(ctx, "staging", vk::BufferUsageFlags::TRANSFER_SRC, data)?;
        ctx.submit_and_wait(|cmd| {
            image.transition(
                cmd,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            );
            let region = [vk::BufferImageCopy::default()
                .image_subresource(
                    vk::ImageSubresourceLayers::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .layer_count(1),
                )
                .image_extent(vk::Extent3D {
                    width: w,
                    height: h,
                    depth: d,
                })];
            // SAFETY: staging holds exactly the image's texels; layouts set above.
            unsafe {
                ctx.device.cmd_copy_buffer_to_image(
                    cmd,
                    staging.raw,
                    image.raw,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &region,
                )
            };
            image.transition(
                cmd,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            );
        })?;
        Ok(image)
    }

    /// Record a copy of this 2D image (in `TRANSFER_SRC_OPTIMAL`) into a new readback buffer.
    pub fn record_readback(&self, cmd: vk::CommandBuffer) -> GpuResult<Buffer> {
        let [w, h, _] = self.desc.extent;
        let size = w as u64 * h as u64 * texel_bytes(self.desc.format);
        let buffer = Buffer::new(
            &self.ctx,
            &BufferDesc::new("readback", size, vk::BufferUsageFlags::TRANSFER_DST).readback(),
        )?;
        let region = [vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(aspect(self.desc.format))
                    .layer_count(1),
            )
            .image_extent(vk::Extent3D {
                width: w,
                height: h,
                depth: 1,
            })];
        // SAFETY: buffer is large enough; image is in TRANSFER_SRC_OPTIMAL.
        unsafe {
            self.ctx.device.cmd_copy_image_to_buffer(
                cmd,
                self.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer.raw,
                &region,
            )
        };
        Ok(buffer)
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: callers wait for the GPU before dropping images it uses.
        unsafe {
            self.ctx.device.destroy_image_view(self.view, None);
            self.ctx.device.destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.ctx.allocator().free(a);
        }
    }
}

/// A linear, clamp-to-edge sampler (the texture filtering the hair mesh texture relies on).
pub struct Sampler {
    ctx: Arc<Context>,
    /// The raw handle.
    pub raw: vk::Sampler,
}

impl Sampler {
    /// Linear min/mag filtering, clamp to edge, no mips.
    pub fn linear_clamp(ctx: &Arc<Context>) -> GpuResult<Self> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        // SAFETY: valid create info.
        let raw = unsafe { ctx.device.create_sampler(&info, None) }.ctx("create sampler")?;
        Ok(Sampler {
            ctx: ctx.clone(),
            raw,
        })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        // SAFETY: not in use once dropped.
        unsafe { self.ctx.device.destroy_sampler(self.raw, None) };
    }
}
