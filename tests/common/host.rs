//! A minimal host engine for the tests of the embedding API: the `embed` example's engine core
//! (`tools/embed/engine.rs`: its own instance with validation and synchronization validation,
//! a device made with `vk::create_host_device`, its own `gpu-allocator`), and one frame's
//! colour and depth images it fills itself, hands to `Renderer::record_host_frame` in its own
//! command buffer, and reads back.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

#[path = "../../tools/embed/engine.rs"]
mod engine;

pub use engine::{Buf, Engine, Img, Validation, barrier, copy};

/// The host: the engine core with synchronization validation.
pub struct Host(pub Engine);

impl Host {
    pub fn new() -> Host {
        Host(
            Engine::new(Validation::WithSync)
                .expect("a Vulkan host with validation (run tools/setup.sh)"),
        )
    }

    /// What the renderer borrows (validation on; the host's allocator when `share_allocator`).
    pub fn lend(&self, share_allocator: bool) -> hairmesh::vk::HostDevice {
        self.0.lend(true, share_allocator)
    }

    /// Use the device: create and destroy a buffer, wait idle.
    pub fn still_works(&self) {
        let place = (256, MemoryLocation::GpuOnly);
        let b = self
            .0
            .buffer(vk::BufferUsageFlags::STORAGE_BUFFER, place, &[])
            .unwrap();
        self.0.destroy_buffer(b);
        // SAFETY: the host's live device.
        unsafe { self.0.device.device_wait_idle().unwrap() };
    }
}

/// The host's frame: colour and depth images, a staging buffer for the depth it "draws", a
/// readback buffer for the colour.
pub struct HostFrame<'h> {
    host: &'h Host,
    pub size: (u32, u32),
    pub color: Img,
    pub depth: Img,
    staging: Buf,
    readback: Buf,
}

const COLOR_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::TRANSFER_SRC.as_raw()
        | vk::ImageUsageFlags::TRANSFER_DST.as_raw(),
);
const DEPTH_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::SAMPLED.as_raw()
        | vk::ImageUsageFlags::TRANSFER_DST.as_raw(),
);

impl<'h> HostFrame<'h> {
    pub fn new(host: &'h Host, size: (u32, u32), color: vk::Format, depth: vk::Format) -> Self {
        let e = &host.0;
        let bytes = size.0 as u64 * size.1 as u64 * 4;
        HostFrame {
            host,
            size,
            color: e.image(size, color, COLOR_USAGE).unwrap(),
            depth: e.image(size, depth, DEPTH_USAGE).unwrap(),
            staging: e
                .buffer(
                    vk::BufferUsageFlags::TRANSFER_SRC,
                    (bytes, MemoryLocation::CpuToGpu),
                    &[],
                )
                .unwrap(),
            readback: e
                .buffer(
                    vk::BufferUsageFlags::TRANSFER_DST,
                    (bytes, MemoryLocation::GpuToCpu),
                    &[],
                )
                .unwrap(),
        }
    }

    /// The renderer's wrappers of the host's images.
    pub fn images(
        &self,
        ctx: &Arc<hairmesh::vk::Context>,
    ) -> (hairmesh::vk::Image, hairmesh::vk::Image) {
        use hairmesh::vk::{Image, ImageDesc};
        let (w, h) = self.size;
        let c = ImageDesc::new_2d("host colour", self.color.format, w, h).usage(COLOR_USAGE);
        let z = ImageDesc::new_2d("host depth", self.depth.format, w, h).usage(DEPTH_USAGE);
        (
            Image::from_host(ctx, self.color.raw, &c).unwrap(),
            Image::from_host(ctx, self.depth.raw, &z).unwrap(),
        )
    }

    /// One host frame: clear the colour to `background`, copy `depth` (one float per pixel)
    /// into the depth image, let `renderer` record (both images left in transfer-write use;
    /// it returns whether it handed the colour back in transfer-read use, else the host moves
    /// it there), copy the colour out, submit and wait. Returns the colour's bytes (in its
    /// format's channel order).
    pub fn run(
        &mut self,
        background: [f32; 4],
        depth: &[f32],
        renderer: impl FnOnce(vk::CommandBuffer) -> bool,
    ) -> Vec<u8> {
        let e = &self.host.0;
        let d = &e.device;
        let pixels = (self.size.0 * self.size.1) as usize;
        assert_eq!(depth.len(), pixels);
        let staging = self
            .staging
            .memory
            .as_mut()
            .unwrap()
            .mapped_slice_mut()
            .unwrap();
        staging[..pixels * 4].copy_from_slice(bytemuck::cast_slice(depth));
        let (color, depth_image) = (&self.color, &self.depth);
        let (staging, readback) = (&self.staging, &self.readback);
        e.submit(|cmd| {
            use vk::ImageLayout as L;
            // SAFETY: the host's command buffer, recording; its objects outlive the submission.
            unsafe {
                barrier(d, cmd, color, (L::UNDEFINED, L::TRANSFER_DST_OPTIMAL));
                barrier(d, cmd, depth_image, (L::UNDEFINED, L::TRANSFER_DST_OPTIMAL));
                let clear = vk::ClearColorValue {
                    float32: background,
                };
                let range = engine::range(vk::ImageAspectFlags::COLOR);
                d.cmd_clear_color_image(cmd, color.raw, L::TRANSFER_DST_OPTIMAL, &clear, &[range]);
                copy(d, cmd, (depth_image, staging), true);
                if !renderer(cmd) {
                    barrier(
                        d,
                        cmd,
                        color,
                        (L::TRANSFER_DST_OPTIMAL, L::TRANSFER_SRC_OPTIMAL),
                    );
                }
                copy(d, cmd, (color, readback), false);
            }
            Ok(())
        })
        .unwrap();
        self.readback
            .memory
            .as_ref()
            .unwrap()
            .mapped_slice()
            .unwrap()[..pixels * 4]
            .to_vec()
    }
}

impl Drop for HostFrame<'_> {
    fn drop(&mut self) {
        // The frame's submissions were waited for.
        let e = &self.host.0;
        e.destroy_image(std::mem::replace(&mut self.color, Img::null()));
        e.destroy_image(std::mem::replace(&mut self.depth, Img::null()));
        e.destroy_buffer(std::mem::replace(&mut self.staging, Buf::null()));
        e.destroy_buffer(std::mem::replace(&mut self.readback, Buf::null()));
    }
}
