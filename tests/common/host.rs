//! A minimal host engine in raw `ash`, for the tests of the embedding API: its own instance
//! (validation layer, synchronization validation, debug utils), a device made with
//! `vk::create_host_device`, its own `gpu-allocator` (lent to the renderer), and one frame's
//! colour and depth images it fills itself, hands to `Renderer::record_host_frame` in its own
//! command buffer, and reads back. The host code is raw `ash`, as an engine's would be; that
//! is why this file has `unsafe`.

use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use hairmesh::vk::{Context, HostDevice, create_host_device};

/// The host's instance, device, queue and allocator.
pub struct Host {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub family: u32,
    pub queue: vk::Queue,
    pub allocator: Option<Arc<Mutex<Allocator>>>,
}

impl Host {
    /// Instance (Vulkan 1.3, validation with synchronization validation), the first device
    /// with a graphics + compute queue, and the host's allocator on it.
    pub fn new() -> Host {
        // SAFETY: the host's own Vulkan setup; every handle is checked and destroyed in drop.
        unsafe {
            let entry = ash::Entry::load().expect("Vulkan loader (run tools/setup.sh)");
            let app = vk::ApplicationInfo::default()
                .application_name(c"host")
                .api_version(vk::API_VERSION_1_3);
            let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
            let extensions = [ash::ext::debug_utils::NAME.as_ptr()];
            let features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
            let mut validation =
                vk::ValidationFeaturesEXT::default().enabled_validation_features(&features);
            let info = vk::InstanceCreateInfo::default()
                .application_info(&app)
                .enabled_layer_names(&layers)
                .enabled_extension_names(&extensions)
                .push_next(&mut validation);
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
            let allocator = Allocator::new(&AllocatorCreateDesc {
                instance: instance.clone(),
                device: device.clone(),
                physical_device: physical,
                debug_settings: Default::default(),
                buffer_device_address: true,
                allocation_sizes: Default::default(),
            })
            .unwrap();
            Host {
                entry,
                instance,
                physical,
                device,
                family,
                queue,
                allocator: Some(Arc::new(Mutex::new(allocator))),
            }
        }
    }

    /// What the renderer borrows (with the host's allocator when `share_allocator`).
    pub fn lend(&self, share_allocator: bool) -> HostDevice {
        HostDevice {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical: self.physical,
            device: self.device.clone(),
            queue_family: self.family,
            queue: self.queue,
            validation: true,
            allocator: self.allocator.clone().filter(|_| share_allocator),
        }
    }

    /// Memory from the host's allocator, bound by `bind`.
    pub fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Allocation {
        let allocator = self.allocator.as_ref().unwrap();
        allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .unwrap()
    }

    /// Give `allocation` back.
    pub fn free(&self, allocation: Allocation) {
        let allocator = self.allocator.as_ref().unwrap();
        allocator.lock().unwrap().free(allocation).unwrap();
    }

    /// Use the device: create and destroy a buffer, wait idle.
    pub fn still_works(&self) {
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
        // SAFETY: nothing else uses the device or instance any more; the renderer's context
        // (which may hold the allocator too) is gone.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.allocator.take();
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

/// An image or buffer of the host with its memory.
pub struct Owned<T> {
    pub raw: T,
    pub memory: Option<Allocation>,
}

/// The host's frame: colour and depth images, a staging buffer for the depth it "draws", a
/// readback buffer for the colour, a command pool and buffer, a fence.
pub struct HostFrame<'h> {
    host: &'h Host,
    pub size: (u32, u32),
    pub color_format: vk::Format,
    pub depth_format: vk::Format,
    pub color: Owned<vk::Image>,
    pub depth: Owned<vk::Image>,
    staging: Owned<vk::Buffer>,
    readback: Owned<vk::Buffer>,
    pool: vk::CommandPool,
    pub cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

impl<'h> HostFrame<'h> {
    pub fn new(
        host: &'h Host,
        size: (u32, u32),
        color_format: vk::Format,
        depth_format: vk::Format,
    ) -> Self {
        let d = &host.device;
        let pixels = size.0 as u64 * size.1 as u64;
        // SAFETY: the host's objects on its live device, destroyed in drop.
        unsafe {
            let image = |format, usage, name: &str| {
                let info = vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(format)
                    .extent(vk::Extent3D {
                        width: size.0,
                        height: size.1,
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .tiling(vk::ImageTiling::OPTIMAL)
                    .usage(usage);
                let raw = d.create_image(&info, None).unwrap();
                let m = host.allocate(
                    name,
                    d.get_image_memory_requirements(raw),
                    MemoryLocation::GpuOnly,
                    false,
                );
                d.bind_image_memory(raw, m.memory(), m.offset()).unwrap();
                Owned {
                    raw,
                    memory: Some(m),
                }
            };
            let buffer = |bytes, usage, location, name: &str| {
                let info = vk::BufferCreateInfo::default().size(bytes).usage(usage);
                let raw = d.create_buffer(&info, None).unwrap();
                let m = host.allocate(name, d.get_buffer_memory_requirements(raw), location, true);
                d.bind_buffer_memory(raw, m.memory(), m.offset()).unwrap();
                Owned {
                    raw,
                    memory: Some(m),
                }
            };
            use vk::ImageUsageFlags as U;
            let color = image(
                color_format,
                U::COLOR_ATTACHMENT | U::TRANSFER_SRC | U::TRANSFER_DST,
                "host colour",
            );
            let depth = image(
                depth_format,
                U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED | U::TRANSFER_DST,
                "host depth",
            );
            let staging = buffer(
                pixels * 4,
                vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::CpuToGpu,
                "host staging",
            );
            let readback = buffer(
                pixels * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
                "host readback",
            );
            let pool = d
                .create_command_pool(
                    &vk::CommandPoolCreateInfo::default().queue_family_index(host.family),
                    None,
                )
                .unwrap();
            let cmd = d
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(pool)
                        .command_buffer_count(1),
                )
                .unwrap()[0];
            let fence = d
                .create_fence(&vk::FenceCreateInfo::default(), None)
                .unwrap();
            HostFrame {
                host,
                size,
                color_format,
                depth_format,
                color,
                depth,
                staging,
                readback,
                pool,
                cmd,
                fence,
            }
        }
    }

    /// The renderer's wrappers of the host's images.
    pub fn images(&self, ctx: &Arc<Context>) -> (hairmesh::vk::Image, hairmesh::vk::Image) {
        use hairmesh::vk::{Image, ImageDesc};
        use vk::ImageUsageFlags as U;
        let (w, h) = self.size;
        let c = ImageDesc::new_2d("host colour", self.color_format, w, h)
            .usage(U::COLOR_ATTACHMENT | U::TRANSFER_SRC | U::TRANSFER_DST);
        let z = ImageDesc::new_2d("host depth", self.depth_format, w, h)
            .usage(U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED | U::TRANSFER_DST);
        (
            Image::from_host(ctx, self.color.raw, &c).unwrap(),
            Image::from_host(ctx, self.depth.raw, &z).unwrap(),
        )
    }

    /// One host frame: clear the colour to `background`, copy `depth` (one float per pixel)
    /// into the depth image, let `renderer` record (both images left in transfer-write use; it
    /// hands the colour back in transfer-read use), copy the colour out, submit and wait.
    /// Returns the colour's bytes (in its format's channel order).
    pub fn run(
        &mut self,
        background: [f32; 4],
        depth: &[f32],
        renderer: impl FnOnce(vk::CommandBuffer),
    ) -> Vec<u8> {
        let d = &self.host.device;
        let (w, h) = self.size;
        let pixels = (w * h) as usize;
        assert_eq!(depth.len(), pixels);
        let staging = self
            .staging
            .memory
            .as_mut()
            .unwrap()
            .mapped_slice_mut()
            .unwrap();
        staging[..pixels * 4].copy_from_slice(bytemuck::cast_slice(depth));
        let depth_aspect = match self.depth_format {
            vk::Format::D32_SFLOAT | vk::Format::D16_UNORM => vk::ImageAspectFlags::DEPTH,
            _ => vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
        };
        let range = |aspect| {
            vk::ImageSubresourceRange::default()
                .aspect_mask(aspect)
                .level_count(1)
                .layer_count(1)
        };
        // SAFETY: the host's command buffer and objects; the submission is waited for.
        unsafe {
            d.begin_command_buffer(self.cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            let to_transfer = [
                (self.color.raw, range(vk::ImageAspectFlags::COLOR)),
                (self.depth.raw, range(depth_aspect)),
            ]
            .map(|(image, r)| {
                vk::ImageMemoryBarrier2::default()
                    .dst_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
                    .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                    .old_layout(vk::ImageLayout::UNDEFINED)
                    .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                    .image(image)
                    .subresource_range(r)
            });
            d.cmd_pipeline_barrier2(
                self.cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&to_transfer),
            );
            let clear = vk::ClearColorValue {
                float32: background,
            };
            d.cmd_clear_color_image(
                self.cmd,
                self.color.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &clear,
                &[range(vk::ImageAspectFlags::COLOR)],
            );
            let copy = vk::BufferImageCopy::default()
                .image_subresource(
                    vk::ImageSubresourceLayers::default()
                        .aspect_mask(vk::ImageAspectFlags::DEPTH)
                        .layer_count(1),
                )
                .image_extent(vk::Extent3D {
                    width: w,
                    height: h,
                    depth: 1,
                });
            d.cmd_copy_buffer_to_image(
                self.cmd,
                self.staging.raw,
                self.depth.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[copy],
            );
            renderer(self.cmd);
            // The renderer handed the colour back in transfer-read use (after its last write).
            let copy = vk::BufferImageCopy::default()
                .image_subresource(
                    vk::ImageSubresourceLayers::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .layer_count(1),
                )
                .image_extent(vk::Extent3D {
                    width: w,
                    height: h,
                    depth: 1,
                });
            d.cmd_copy_image_to_buffer(
                self.cmd,
                self.color.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                self.readback.raw,
                &[copy],
            );
            let to_host = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                .dst_access_mask(vk::AccessFlags2::HOST_READ)];
            d.cmd_pipeline_barrier2(
                self.cmd,
                &vk::DependencyInfo::default().memory_barriers(&to_host),
            );
            d.end_command_buffer(self.cmd).unwrap();
            let cmds = [self.cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            d.queue_submit(self.host.queue, &[submit], self.fence)
                .unwrap();
            d.wait_for_fences(&[self.fence], true, u64::MAX).unwrap();
            d.reset_fences(&[self.fence]).unwrap();
            d.reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty())
                .unwrap();
        }
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
        let d = &self.host.device;
        // SAFETY: the frame's submissions were waited for.
        unsafe {
            d.destroy_fence(self.fence, None);
            d.destroy_command_pool(self.pool, None);
            d.destroy_image(self.color.raw, None);
            d.destroy_image(self.depth.raw, None);
            d.destroy_buffer(self.staging.raw, None);
            d.destroy_buffer(self.readback.raw, None);
        }
        for m in [
            &mut self.color.memory,
            &mut self.depth.memory,
            &mut self.staging.memory,
            &mut self.readback.memory,
        ] {
            if let Some(m) = m.take() {
                self.host.free(m);
            }
        }
    }
}
