//! The control panel's renderer: egui meshes drawn with `egui-ash-renderer` into a colour
//! image, behind a safe interface (the crate takes raw handles; they stay inside `vk/`).

use std::sync::Arc;

use ash::vk;

use super::command::{Attachment, CommandRecorder};
use super::image::Image;
use super::{Context, GpuError, GpuResult, VkContext};

fn ui_error(e: egui_ash_renderer::RendererError) -> GpuError {
    GpuError::Unsupported(format!("control panel renderer: {e}"))
}

/// Draws egui output.
pub struct UiRenderer {
    renderer: Option<egui_ash_renderer::Renderer<egui_ash_renderer::allocator::DefaultAllocator>>,
    ctx: Arc<Context>,
    pool: vk::CommandPool,
}

impl UiRenderer {
    /// A renderer for colour targets of `format` (sRGB formats get linear output),
    /// `frames_in_flight` frames recorded ahead.
    pub fn new(ctx: &Arc<Context>, format: vk::Format, frames_in_flight: usize) -> GpuResult<Self> {
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create info.
        let pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }
            .ctx("create command pool")?;
        let srgb = matches!(
            format,
            vk::Format::R8G8B8A8_SRGB | vk::Format::B8G8R8A8_SRGB
        );
        let renderer = egui_ash_renderer::Renderer::with_default_allocator(
            ctx.instance(),
            ctx.physical(),
            ctx.device.clone(),
            egui_ash_renderer::RenderMode::DynamicRendering(egui_ash_renderer::DynamicRendering {
                color_attachment_format: format,
                depth_attachment_format: None,
                stencil_attachment_format: None,
            }),
            egui_ash_renderer::Options {
                in_flight_frames: frames_in_flight,
                srgb_framebuffer: srgb,
                ..Default::default()
            },
        );
        let renderer = match renderer {
            Ok(r) => r,
            Err(e) => {
                // SAFETY: nothing was allocated from the pool.
                unsafe { ctx.device.destroy_command_pool(pool, None) };
                return Err(ui_error(e));
            }
        };
        Ok(UiRenderer {
            renderer: Some(renderer),
            ctx: ctx.clone(),
            pool,
        })
    }

    /// Apply egui's texture updates (before the frame that uses them is recorded; blocks on
    /// its own upload).
    pub fn set_textures(&mut self, delta: &egui::TexturesDelta) -> GpuResult<()> {
        let r = self.renderer.as_mut().expect("alive until drop");
        for (id, deltas) in &delta.set {
            for d in deltas {
                r.set_texture(self.ctx.queue(), self.pool, *id, d)
                    .map_err(ui_error)?;
            }
        }
        Ok(())
    }

    /// Free textures egui no longer uses (after the frames that drew with them completed).
    pub fn free_textures(&mut self, ids: &[egui::TextureId]) -> GpuResult<()> {
        let r = self.renderer.as_mut().expect("alive until drop");
        for id in ids {
            r.free_texture(*id).map_err(ui_error)?;
        }
        Ok(())
    }

    /// Draw `primitives` over `target` (in colour-attachment use; its contents are kept).
    pub fn draw(
        &mut self,
        rec: &mut CommandRecorder,
        target: &Image,
        pixels_per_point: f32,
        primitives: &[egui::ClippedPrimitive],
    ) -> GpuResult<()> {
        let [w, h, _] = target.desc.extent;
        rec.begin_rendering_color(Attachment {
            image: target,
            clear: None,
            resolve: None,
        });
        let r = self.renderer.as_mut().expect("alive until drop");
        let result = r.cmd_draw(
            rec.raw(),
            vk::Extent2D {
                width: w,
                height: h,
            },
            pixels_per_point,
            primitives,
        );
        rec.end_rendering();
        result.map_err(ui_error)
    }
}

impl Drop for UiRenderer {
    fn drop(&mut self) {
        self.ctx.wait_idle();
        drop(self.renderer.take());
        // SAFETY: the device is idle; the pool's command buffers are not in use.
        unsafe { self.ctx.device.destroy_command_pool(self.pool, None) };
    }
}
