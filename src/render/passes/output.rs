//! The end of a frame: the overlay (the control panel) over the output image, the statistics
//! and image readbacks, the blit onto the swapchain image and its hand-over to presentation,
//! and the host's reads after the submission completes.

use super::FrameRes;
use crate::render::core::graph::{FrameGraph, Res};
use crate::render::core::shared::GenerateArgs;
use crate::vk::{Access, Buffer, CommandRecorder, GpuResult, Image, SwapchainImage};

/// Something drawn over a frame's output image before it is presented (the control panel):
/// called with the image in colour-attachment use.
pub type Overlay<'a> = dyn FnMut(&mut CommandRecorder, &Image) -> GpuResult<()> + 'a;

/// Where the frame's results go.
pub struct FrameOutputs<'a, 'o> {
    /// Drawn over the output image.
    pub overlay: Option<&'a mut Overlay<'o>>,
    /// `GenerateArgs` copied here for the frame report.
    pub stats_readback: &'a Buffer,
    /// The output image copied here (RGBA8), when asked for.
    pub image_readback: Option<&'a Buffer>,
    /// The swapchain image the output is blitted onto and presented.
    pub present: Option<&'a SwapchainImage>,
}

/// Add the output passes after the frame's drawing.
pub fn add_outputs<'a, 'o: 'a>(
    g: &mut FrameGraph<'a>,
    r: &FrameRes<'a>,
    out: FrameOutputs<'a, 'o>,
) {
    let output = r.images.output;
    if let Some(overlay) = out.overlay {
        g.pass("overlay")
            .write(r.output, Access::ColorAttachment)
            .record(move |rec, _| overlay(rec, output));
    }
    let stats = g.import_buffer("statistics readback", out.stats_readback);
    let args = r.args_buffer;
    let bytes = size_of::<GenerateArgs>() as u64;
    g.pass("statistics readback")
        .read(r.args, Access::TransferRead)
        .discard(stats, Access::TransferWrite)
        .record(move |rec, _| {
            rec.copy_buffer(args, 0, out.stats_readback, 0, bytes);
            Ok(())
        });
    let mut host = vec![stats];
    if let Some(buffer) = out.image_readback {
        host.push(add_image_readback(g, r, buffer));
    }
    if let Some(image) = out.present {
        let swapchain = g.import_swapchain("swapchain image", image);
        g.pass("blit to swapchain")
            .read(r.output, Access::TransferRead)
            .discard(swapchain, Access::TransferWrite)
            .record(move |rec, _| {
                rec.blit_to_swapchain(output, image);
                Ok(())
            });
        g.pass("present").read(swapchain, Access::Present).done();
    }
    g.pass("host reads")
        .read_all(&host, Access::HostRead)
        .done();
}

/// Add the copy of the frame's output image into `buffer` (RGBA8); returns the buffer's
/// resource, which the host reads once the frame completes.
pub fn add_image_readback<'a>(g: &mut FrameGraph<'a>, r: &FrameRes<'a>, buffer: &'a Buffer) -> Res {
    let output = r.images.output;
    let readback = g.import_buffer("image readback", buffer);
    g.pass("image readback")
        .read(r.output, Access::TransferRead)
        .discard(readback, Access::TransferWrite)
        .record(move |rec, _| {
            rec.copy_image_to_buffer(output, buffer);
            Ok(())
        });
    readback
}
