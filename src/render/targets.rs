//! The render targets: colour and depth (multisampled when MSAA is on, with a single-sample
//! resolve image), kept across frames and recreated on resize only.

use std::sync::Arc;

use ash::vk;

use crate::vk::{Access, Context, GpuResult, Image, ImageDesc};

/// Colour target format (sRGB encoding on write).
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Depth target format.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Colour and depth images of one size, and how they were last used.
pub struct RenderTargets {
    /// Colour target (multisampled with MSAA).
    pub color: Image,
    /// Depth target (multisampled with MSAA).
    pub depth: Image,
    /// With MSAA: the single-sample image the colour samples resolve into.
    pub resolved: Option<Image>,
    /// Last use of the colour target.
    pub color_access: Access,
    /// Last use of the depth target.
    pub depth_access: Access,
    /// Last use of the output image ([`RenderTargets::output`]).
    pub output_access: Access,
}

impl RenderTargets {
    /// Targets of `width x height` (1..=8192 each) with `samples` per pixel.
    pub fn new(ctx: &Arc<Context>, width: u32, height: u32, samples: u32) -> GpuResult<Self> {
        let single = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        let color_usage = if samples > 1 {
            vk::ImageUsageFlags::COLOR_ATTACHMENT
        } else {
            single
        };
        Ok(RenderTargets {
            color: Image::new(
                ctx,
                &ImageDesc::new_2d("color", COLOR_FORMAT, width, height)
                    .usage(color_usage)
                    .samples(samples),
            )?,
            depth: Image::new(
                ctx,
                &ImageDesc::new_2d("depth", DEPTH_FORMAT, width, height)
                    .usage(vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT)
                    .samples(samples),
            )?,
            resolved: if samples > 1 {
                Some(Image::new(
                    ctx,
                    &ImageDesc::new_2d("color resolved", COLOR_FORMAT, width, height).usage(single),
                )?)
            } else {
                None
            },
            color_access: Access::Nothing,
            depth_access: Access::Nothing,
            output_access: Access::Nothing,
        })
    }

    /// `(width, height)`.
    pub fn size(&self) -> (u32, u32) {
        (self.color.desc.extent[0], self.color.desc.extent[1])
    }

    /// The single-sample image of the frame (read back, presented, drawn over by overlays).
    pub fn output(&self) -> &Image {
        self.resolved.as_ref().unwrap_or(&self.color)
    }

    /// Record a new use of the output image (also of the colour target when they are one).
    pub fn set_output_access(&mut self, access: Access) {
        self.output_access = access;
        if self.resolved.is_none() {
            self.color_access = access;
        }
    }
}
