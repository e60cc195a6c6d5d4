//! The renderer on a host's Vulkan device (issue 27's first step): a minimal host (this test,
//! playing an engine) creates its own instance with the validation layer, picks a device,
//! creates it with `vk::create_host_device` and hands it to `Context::from_host`. The
//! renderer draws the same image as on a device of its own, validation stays clean, and when
//! the renderer and its context are dropped the host's device is still alive: the host uses
//! it, then destroys it and its instance itself.
//!
//! The host code is raw `ash`, as an engine's would be; that is why this test has `unsafe`.

mod common;

use std::sync::Arc;

use ash::vk;
use common::*;
use hairmesh::render::{Renderer, RendererDesc};
use hairmesh::vk::{Context, HostDevice, create_host_device};

const SIZE: u32 = 96;

/// The host's instance (Vulkan 1.3, validation layer, debug utils), a device on the first
/// physical device with a graphics + compute queue, and that queue.
struct Host {
    entry: ash::Entry,
    instance: ash::Instance,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    family: u32,
    queue: vk::Queue,
}

impl Host {
    fn new() -> Host {
        // SAFETY: the host's own Vulkan setup; every handle is checked and destroyed in drop.
        unsafe {
            let entry = ash::Entry::load().expect("Vulkan loader (run tools/setup.sh)");
            let app = vk::ApplicationInfo::default()
                .application_name(c"host")
                .api_version(vk::API_VERSION_1_3);
            let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
            let extensions = [ash::ext::debug_utils::NAME.as_ptr()];
            let info = vk::InstanceCreateInfo::default()
                .application_info(&app)
                .enabled_layer_names(&layers)
                .enabled_extension_names(&extensions);
            let instance = entry
                .create_instance(&info, None)
                .expect("host instance with validation (run tools/setup.sh)");
            let (physical, family) = instance
                .enumerate_physical_devices()
                .unwrap()
                .into_iter()
                .find_map(|p| {
                    let families = instance.get_physical_device_queue_family_properties(p);
                    let wanted = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
                    families
                        .iter()
                        .position(|f| f.queue_flags.contains(wanted))
                        .map(|i| (p, i as u32))
                })
                .expect("a device with a graphics and compute queue");
            let device = create_host_device(&instance, physical, family, &[]).unwrap();
            let queue = device.get_device_queue(family, 0);
            Host {
                entry,
                instance,
                physical,
                device,
                family,
                queue,
            }
        }
    }

    /// What the renderer borrows.
    fn lend(&self) -> HostDevice {
        HostDevice {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical: self.physical,
            device: self.device.clone(),
            queue_family: self.family,
            queue: self.queue,
            validation: true,
            allocator: None,
        }
    }

    /// Use the device: create and destroy a buffer, wait idle.
    fn still_works(&self) {
        // SAFETY: the host's live device; the buffer is destroyed before returning.
        unsafe {
            let info = vk::BufferCreateInfo::default()
                .size(256)
                .usage(vk::BufferUsageFlags::STORAGE_BUFFER);
            let buffer = self.device.create_buffer(&info, None).unwrap();
            let req = self.device.get_buffer_memory_requirements(buffer);
            assert!(req.size >= 256);
            self.device.destroy_buffer(buffer, None);
            self.device.device_wait_idle().unwrap();
        }
    }
}

impl Drop for Host {
    fn drop(&mut self) {
        // SAFETY: nothing else uses the device or instance any more.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

/// head_long drawn on the compute path at full detail on `ctx`.
fn draw(ctx: &Arc<Context>) -> Vec<u8> {
    let (baked, style) = sample("head_long.obj");
    let mut r = Renderer::new(ctx, &RendererDesc::default().size(SIZE, SIZE)).unwrap();
    upload(&mut r, &baked, &style, 16, 4);
    render(&mut r, &framing(&baked), &compute_full()).rgba
}

#[test]
fn the_renderer_draws_on_a_host_device_and_leaves_it_alive() {
    let own = draw(&context());
    let host = Host::new();
    {
        let ctx = Arc::new(Context::from_host(host.lend()).unwrap());
        let drawn = draw(&ctx);
        let bg = &drawn[..4];
        let covered = drawn.chunks(4).filter(|p| p != &bg).count();
        let diff = mean_abs_diff(&own, &drawn);
        println!("host device: {covered} hair pixels, mean difference to its own device {diff:e}");
        assert!(covered > 200, "only {covered} pixels drawn");
        assert!(diff < 1e-3, "the host device's image differs by {diff}");
        assert_no_validation_errors(&ctx);
    }
    // The renderer and its context are gone; the host's device is not.
    host.still_works();
}
