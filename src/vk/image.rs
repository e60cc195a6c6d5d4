//! 2D/3D images, views, samplers, uploads and readback.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::Allocation;

use super::access::Access;
use super::buffer::Buffer;
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
    /// Samples per pixel (1, or a count the device supports for attachments).
    pub samples: u32,
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
            samples: 1,
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
            samples: 1,
        }
    }

    /// Add usage flags.
    pub fn usage(mut self, usage: vk::ImageUsageFlags) -> Self {
        self.usage |= usage;
        self
    }

    /// Samples per pixel (multisampled attachments).
    pub fn samples(mut self, samples: u32) -> Self {
        self.samples = samples;
        self
    }
}

/// An image with one mip level and one layer, its memory and a full view.
pub struct Image {
    ctx: Arc<Context>,
    raw: vk::Image,
    view: vk::ImageView,
    allocation: Option<Allocation>,
    /// Created here (destroyed with this); else a host's image, of which only the view is ours.
    owned: bool,
    /// Creation parameters.
    pub desc: ImageDesc,
}

/// Every aspect of `format` (barriers name all of them): colour, depth, stencil, or depth and
/// stencil.
pub fn aspect(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM | vk::Format::X8_D24_UNORM_PACK32 => {
            vk::ImageAspectFlags::DEPTH
        }
        vk::Format::D16_UNORM_S8_UINT
        | vk::Format::D24_UNORM_S8_UINT
        | vk::Format::D32_SFLOAT_S8_UINT => {
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
        }
        vk::Format::S8_UINT => vk::ImageAspectFlags::STENCIL,
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// The aspect a view of `format` shows (depth alone for depth-stencil formats: sampled depth).
fn view_aspect(format: vk::Format) -> vk::ImageAspectFlags {
    let all = aspect(format);
    match all.contains(vk::ImageAspectFlags::DEPTH) {
        true => vk::ImageAspectFlags::DEPTH,
        false => all,
    }
}

/// Whether `format` has depth.
pub fn is_depth_format(format: vk::Format) -> bool {
    aspect(format).contains(vk::ImageAspectFlags::DEPTH)
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
            .samples(super::sample_flags(desc.samples))
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
        match Self::with_view(ctx, raw, desc, Some(allocation)) {
            Ok(image) => Ok(image),
            Err((e, allocation)) => {
                // SAFETY: the image is unused; its memory is freed after it.
                unsafe { ctx.device.destroy_image(raw, None) };
                if let Some(a) = allocation {
                    let _ = ctx.allocator().free(a);
                }
                Err(e)
            }
        }
    }

    /// A host's image, described by `desc` (its format, extent, samples and the usage it was
    /// created with): the renderer makes a view of its own and never destroys the image. The
    /// host keeps the image alive until this is dropped, and drops this only after the GPU is
    /// done with the frames that used it.
    pub fn from_host(ctx: &Arc<Context>, raw: vk::Image, desc: &ImageDesc) -> GpuResult<Self> {
        if raw == vk::Image::null() || desc.dim_3d || desc.extent[2] != 1 {
            return Err(GpuError::Unsupported(format!(
                "{}: a host image must be a non-null 2D image",
                desc.name
            )));
        }
        Self::with_view(ctx, raw, desc, None).map_err(|(e, _)| e)
    }

    /// `raw` with a full view; `allocation`: its memory, when the image is ours. On error the
    /// allocation comes back for the caller to free.
    #[allow(clippy::result_large_err)]
    fn with_view(
        ctx: &Arc<Context>,
        raw: vk::Image,
        desc: &ImageDesc,
        allocation: Option<Allocation>,
    ) -> Result<Self, (GpuError, Option<Allocation>)> {
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(if desc.dim_3d {
                vk::ImageViewType::TYPE_3D
            } else {
                vk::ImageViewType::TYPE_2D
            })
            .format(desc.format)
            .subresource_range(
                vk::ImageSubresourceRange::default()
                    .aspect_mask(view_aspect(desc.format))
                    .level_count(1)
                    .layer_count(1),
            );
        // SAFETY: view of a bound image (ours, or a host's on this device).
        let view = match unsafe { ctx.device.create_image_view(&view_info, None) } {
            Ok(v) => v,
            Err(result) => {
                let e = GpuError::Vk {
                    what: "create image view",
                    result,
                };
                return Err((e, allocation));
            }
        };
        let owned = allocation.is_some();
        if owned {
            ctx.name_object(raw, &desc.name);
        }
        ctx.name_object(view, &desc.name);
        Ok(Image {
            ctx: ctx.clone(),
            raw,
            view,
            allocation,
            owned,
            desc: desc.clone(),
        })
    }

    pub(crate) fn full_range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default()
            .aspect_mask(aspect(self.desc.format))
            .level_count(1)
            .layer_count(1)
    }

    pub(crate) fn raw(&self) -> vk::Image {
        self.raw
    }

    pub(crate) fn view(&self) -> vk::ImageView {
        self.view
    }

    /// Bytes of the image's texels, tightly packed.
    pub fn byte_size(&self) -> u64 {
        let [w, h, d] = self.desc.extent;
        w as u64 * h as u64 * d as u64 * texel_bytes(self.desc.format)
    }

    /// Create a sampled image holding `data` (tightly packed texels), left in
    /// [`Access::SampledRead`]. Blocks until uploaded.
    pub fn with_data(ctx: &Arc<Context>, desc: &ImageDesc, data: &[u8]) -> GpuResult<Self> {
        let desc = desc
            .clone()
            .usage(vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST);
        let image = Image::new(ctx, &desc)?;
        if image.byte_size() != data.len() as u64 || image.byte_size() == 0 {
            return Err(GpuError::Unsupported(format!(
                "{}: {} bytes for a {}-byte image",
                desc.name,
                data.len(),
                image.byte_size()
            )));
        }
        let staging = Buffer::with_data(ctx, "staging", vk::BufferUsageFlags::TRANSFER_SRC, data)?;
        ctx.submit_and_wait(|rec| {
            rec.image_barrier(&image, Access::Nothing, Access::TransferWrite);
            rec.copy_buffer_to_image(&staging, &image);
            rec.image_barrier(&image, Access::TransferWrite, Access::SampledRead);
        })?;
        Ok(image)
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: callers wait for the GPU before dropping images it uses.
        unsafe {
            self.ctx.device.destroy_image_view(self.view, None);
            if self.owned {
                self.ctx.device.destroy_image(self.raw, None);
            }
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.ctx.allocator().free(a);
        }
    }
}

/// A linear, clamp-to-edge sampler (the texture filtering the hair mesh texture relies on).
pub struct Sampler {
    ctx: Arc<Context>,
    raw: vk::Sampler,
}

impl Sampler {
    pub(crate) fn raw(&self) -> vk::Sampler {
        self.raw
    }
}

impl Sampler {
    /// Linear min/mag filtering, clamp to edge, no mips.
    pub fn linear_clamp(ctx: &Arc<Context>) -> GpuResult<Self> {
        Self::clamped(ctx, vk::Filter::LINEAR)
    }

    /// Nearest filtering, clamp to edge, no mips (shadow maps, read texel by texel).
    pub fn nearest_clamp(ctx: &Arc<Context>) -> GpuResult<Self> {
        Self::clamped(ctx, vk::Filter::NEAREST)
    }

    fn clamped(ctx: &Arc<Context>, filter: vk::Filter) -> GpuResult<Self> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter)
            .min_filter(filter)
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
