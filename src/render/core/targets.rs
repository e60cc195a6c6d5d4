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
    /// Last use of the MSAA resolve image.
    pub resolved_access: Access,
}

impl RenderTargets {
    /// Targets of `width x height` (1..=8192 each) with `samples` per pixel.
    pub fn new(ctx: &Arc<Context>, width: u32, height: u32, samples: u32) -> GpuResult<Self> {
        // Transfers both ways: read back and copied out and in by temporal accumulation;
        // sampled by a host frame's composite.
        let single = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::SAMPLED;
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
                    // Copied out by depth peeling (the opaque depth).
                    .usage(
                        vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                            | vk::ImageUsageFlags::TRANSFER_SRC,
                    )
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
            resolved_access: Access::Nothing,
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
}

/// Format of the deep opacity layers (one layer per channel, summed with additive blending).
pub const SHADOW_LAYERS_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// The bodies' map has this many times the hair maps' texels per side. Fitted to the camera's
/// view, it is fine enough at the hair maps' resolution (a portrait's shadow edge spans about
/// three texels, 5 mm); twice that cost the 100-people crowd 7% of its frame (the ground's
/// depth into 4x the texels) for edges a person does not see at crowd distance.
pub const BODY_MAP_SCALE: u32 = 1;

/// The light's maps (square, shared by the frames in flight; the frame graph orders each
/// frame's use after the previous frame's reads): hair depth, prop depth and deep opacity layers.
pub struct ShadowMaps {
    /// Depth of the hair nearest the light.
    pub hair_depth: Image,
    /// Depth of the props nearest the light, in the bodies' own view
    /// (`LightView::fit_bodies`), [`BODY_MAP_SCALE`] times the hair maps' resolution.
    pub prop_depth: Image,
    /// Hair opacity per layer behind `hair_depth` (deep opacity mode).
    pub layers: Image,
    /// Last use of each map (`hair_depth`, `prop_depth`, `layers`).
    pub access: [Access; 3],
    /// Nearest, clamped: lookups read texel by texel.
    pub sampler: crate::vk::Sampler,
}

impl ShadowMaps {
    /// Maps of `resolution` x `resolution` texels.
    pub fn new(ctx: &Arc<Context>, resolution: u32) -> GpuResult<Self> {
        // Transfers: the software shadow passes copy their results in.
        let depth_usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_DST;
        let depth = |name, side| {
            Image::new(
                ctx,
                &ImageDesc::new_2d(name, DEPTH_FORMAT, side, side).usage(depth_usage),
            )
        };
        Ok(ShadowMaps {
            hair_depth: depth("shadow hair depth", resolution)?,
            prop_depth: depth("shadow prop depth", resolution * BODY_MAP_SCALE)?,
            layers: Image::new(
                ctx,
                &ImageDesc::new_2d(
                    "shadow opacity layers",
                    SHADOW_LAYERS_FORMAT,
                    resolution,
                    resolution,
                )
                .usage(
                    vk::ImageUsageFlags::COLOR_ATTACHMENT
                        | vk::ImageUsageFlags::SAMPLED
                        | vk::ImageUsageFlags::TRANSFER_DST,
                ),
            )?,
            access: [Access::Nothing; 3],
            sampler: crate::vk::Sampler::nearest_clamp(ctx)?,
        })
    }

    /// Side of the hair maps in texels.
    pub fn resolution(&self) -> u32 {
        self.hair_depth.desc.extent[0]
    }

    /// Side of the bodies' map in texels.
    pub fn body_resolution(&self) -> u32 {
        self.prop_depth.desc.extent[0]
    }
}
