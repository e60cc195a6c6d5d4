//! The render targets: colour and depth, kept across frames and recreated on resize only.

use std::sync::Arc;

use ash::vk;

use crate::vk::{Access, Context, GpuResult, Image, ImageDesc};

/// Colour target format (sRGB encoding on write).
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Depth target format.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Colour and depth images of one size, and how they were last used.
pub struct RenderTargets {
    /// Colour target.
    pub color: Image,
    /// Depth target.
    pub depth: Image,
    /// Last use of the colour target.
    pub color_access: Access,
    /// Last use of the depth target.
    pub depth_access: Access,
}

impl RenderTargets {
    /// Targets of `width x height` (1..=8192 each).
    pub fn new(ctx: &Arc<Context>, width: u32, height: u32) -> GpuResult<Self> {
        Ok(RenderTargets {
            color: Image::new(
                ctx,
                &ImageDesc::new_2d("color", COLOR_FORMAT, width, height).usage(
                    vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                ),
            )?,
            depth: Image::new(
                ctx,
                &ImageDesc::new_2d("depth", DEPTH_FORMAT, width, height)
                    .usage(vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT),
            )?,
            color_access: Access::Nothing,
            depth_access: Access::Nothing,
        })
    }

    /// `(width, height)`.
    pub fn size(&self) -> (u32, u32) {
        (self.color.desc.extent[0], self.color.desc.extent[1])
    }
}
