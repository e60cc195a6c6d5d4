//! The window's swapchain: created for a size and present mode, recreated on resize or when
//! presentation reports `OUT_OF_DATE` / `SUBOPTIMAL`; one "render finished" semaphore per image.

use std::sync::Arc;

use ash::vk;

use super::device::Surface;
use super::sync::Semaphore;
use super::{Context, GpuError, GpuResult, VkContext};

/// How images are presented.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PresentMode {
    /// Wait for vertical blank (always available).
    Fifo,
    /// Replace the queued image (no tearing, no waiting) where offered.
    Mailbox,
    /// Present at once (may tear) where offered.
    Immediate,
}

impl PresentMode {
    fn raw(self) -> vk::PresentModeKHR {
        match self {
            PresentMode::Fifo => vk::PresentModeKHR::FIFO,
            PresentMode::Mailbox => vk::PresentModeKHR::MAILBOX,
            PresentMode::Immediate => vk::PresentModeKHR::IMMEDIATE,
        }
    }
}

/// A swapchain image to draw into this frame.
pub struct SwapchainImage {
    pub(crate) raw: vk::Image,
    /// Index for [`Swapchain::present`].
    pub index: u32,
    /// Size in pixels.
    pub extent: [u32; 2],
}

/// What acquiring an image gave.
pub enum Acquired {
    /// An image to draw; `suboptimal` asks for a recreate after presenting it.
    Image(SwapchainImage, bool),
    /// The swapchain no longer matches the window: recreate it.
    OutOfDate,
}

/// The swapchain.
pub struct Swapchain {
    ctx: Arc<Context>,
    raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    render_finished: Vec<Semaphore>,
    extent: [u32; 2],
    /// The present mode in use (FIFO when the requested one is not offered).
    pub present_mode: PresentMode,
}

/// What a swapchain on a surface is made with: an sRGB format where offered, the asked
/// present mode where supported (else FIFO), the surface's extent (or the asked size within
/// its limits), one image more than the least, and the surface's transform.
struct SurfaceChoice {
    format: vk::SurfaceFormatKHR,
    present_mode: PresentMode,
    extent: vk::Extent2D,
    count: u32,
    transform: vk::SurfaceTransformFlagsKHR,
}

impl SurfaceChoice {
    fn of(
        surface: &Surface,
        physical: vk::PhysicalDevice,
        (width, height): (u32, u32),
        present_mode: PresentMode,
    ) -> GpuResult<Self> {
        // SAFETY: plain surface queries on a valid physical device and surface.
        let (caps, formats, modes) = unsafe {
            (
                surface
                    .loader
                    .get_physical_device_surface_capabilities(physical, surface.raw)
                    .ctx("surface capabilities")?,
                surface
                    .loader
                    .get_physical_device_surface_formats(physical, surface.raw)
                    .ctx("surface formats")?,
                surface
                    .loader
                    .get_physical_device_surface_present_modes(physical, surface.raw)
                    .ctx("present modes")?,
            )
        };
        let format = formats
            .iter()
            .find(|f| {
                matches!(
                    f.format,
                    vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB
                )
            })
            .or(formats.first())
            .copied()
            .ok_or_else(|| GpuError::Unsupported("the surface offers no format".into()))?;
        let present_mode = if modes.contains(&present_mode.raw()) {
            present_mode
        } else {
            PresentMode::Fifo
        };
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        Ok(SurfaceChoice {
            format,
            present_mode,
            extent,
            count,
            transform: caps.current_transform,
        })
    }
}

impl Swapchain {
    /// A swapchain of `width x height` (clamped to what the surface allows) with
    /// `present_mode` where offered; `old` is retired by the new one.
    pub fn new(
        ctx: &Arc<Context>,
        width: u32,
        height: u32,
        present_mode: PresentMode,
        old: Option<Swapchain>,
    ) -> GpuResult<Self> {
        let (Some(surface), Some(ext)) = (&ctx.surface, &ctx.swapchain_ext) else {
            return Err(GpuError::Unsupported(
                "the context was created without a window".into(),
            ));
        };
        let SurfaceChoice {
            format,
            present_mode,
            extent,
            count,
            transform,
        } = SurfaceChoice::of(surface, ctx.physical(), (width, height), present_mode)?;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface.raw)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::COLOR_ATTACHMENT)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(present_mode.raw())
            .clipped(true)
            .old_swapchain(old.as_ref().map_or(vk::SwapchainKHR::null(), |o| o.raw));
        // SAFETY: valid create info; the old swapchain (if any) is retired by this call and
        // destroyed below once the device is idle.
        let raw = unsafe { ext.create_swapchain(&info, None) }.ctx("create swapchain")?;
        drop(old);
        // SAFETY: `raw` was just created.
        let images = match unsafe { ext.get_swapchain_images(raw) } {
            Ok(i) => i,
            Err(result) => {
                // SAFETY: no image of it is in use.
                unsafe { ext.destroy_swapchain(raw, None) };
                return Err(GpuError::Vk {
                    what: "swapchain images",
                    result,
                });
            }
        };
        let mut chain = Swapchain {
            ctx: ctx.clone(),
            raw,
            images,
            render_finished: Vec::new(),
            extent: [extent.width, extent.height],
            present_mode,
        };
        for _ in 0..chain.images.len() {
            chain.render_finished.push(Semaphore::new(ctx)?);
        }
        Ok(chain)
    }

    /// Size in pixels.
    pub fn extent(&self) -> [u32; 2] {
        self.extent
    }

    /// The semaphore a frame drawing into image `index` signals and presentation waits for.
    pub fn render_finished(&self, index: u32) -> &Semaphore {
        &self.render_finished[index as usize]
    }

    /// Acquire the next image; `signal` is signalled when it may be written.
    pub fn acquire(&self, signal: &Semaphore) -> GpuResult<Acquired> {
        let ext = self
            .ctx
            .swapchain_ext
            .as_ref()
            .expect("checked at creation");
        // SAFETY: valid swapchain; the semaphore has no pending operations (the caller waited
        // for the frame that last used it).
        match unsafe { ext.acquire_next_image(self.raw, u64::MAX, signal.raw(), vk::Fence::null()) }
        {
            Ok((index, suboptimal)) => Ok(Acquired::Image(
                SwapchainImage {
                    raw: self.images[index as usize],
                    index,
                    extent: self.extent,
                },
                suboptimal,
            )),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(Acquired::OutOfDate),
            Err(result) => Err(GpuError::Vk {
                what: "acquire swapchain image",
                result,
            }),
        }
    }

    /// Present image `index` once [`Swapchain::render_finished`] is signalled. Returns whether
    /// the swapchain should be recreated (`OUT_OF_DATE` or `SUBOPTIMAL`).
    pub fn present(&self, index: u32) -> GpuResult<bool> {
        let ext = self
            .ctx
            .swapchain_ext
            .as_ref()
            .expect("checked at creation");
        let waits = [self.render_finished[index as usize].raw()];
        let chains = [self.raw];
        let indices = [index];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&chains)
            .image_indices(&indices);
        // SAFETY: the image was acquired and the semaphore is signalled by the frame's submit.
        match unsafe { ext.queue_present(self.ctx.queue(), &info) } {
            Ok(suboptimal) => Ok(suboptimal),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(true),
            Err(result) => Err(GpuError::Vk {
                what: "present",
                result,
            }),
        }
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        self.ctx.wait_idle();
        if let Some(ext) = &self.ctx.swapchain_ext {
            // SAFETY: the device is idle; no image of this swapchain is in use.
            unsafe { ext.destroy_swapchain(self.raw, None) };
        }
    }
}
