//! The core of a minimal engine in raw `ash`, as a real engine's would be: its own instance,
//! a device made with `hairmesh::vk::create_host_device`, its own `gpu-allocator` (lent to
//! the renderer), images, buffers, one command buffer and a fence. Used by the `embed`
//! example and, through `#[path]`, by the tests of the embedding API (`tests/common/host.rs`).

#![allow(dead_code)]

use std::sync::{Arc, Mutex};

use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use hairmesh::vk::{HostDevice, create_host_device};

/// Which validation the engine's instance runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validation {
    /// None.
    Off,
    /// The Khronos layer.
    On,
    /// The Khronos layer with synchronization validation.
    WithSync,
}

/// The engine: instance, device, queue, allocator, one command buffer and fence.
pub struct Engine {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub family: u32,
    pub queue: vk::Queue,
    pub allocator: Option<Arc<Mutex<Allocator>>>,
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

/// A buffer and its memory.
pub struct Buf {
    pub raw: vk::Buffer,
    pub memory: Option<Allocation>,
}

impl Buf {
    /// No buffer (what is left where one was taken out to be destroyed).
    pub fn null() -> Self {
        Buf {
            raw: vk::Buffer::null(),
            memory: None,
        }
    }
}

/// An image, a full view and its memory.
pub struct Img {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub memory: Option<Allocation>,
    pub aspect: vk::ImageAspectFlags,
    pub format: vk::Format,
    pub size: (u32, u32),
}

impl Img {
    /// No image (what is left where one was taken out to be destroyed).
    pub fn null() -> Self {
        Img {
            raw: vk::Image::null(),
            view: vk::ImageView::null(),
            memory: None,
            aspect: vk::ImageAspectFlags::COLOR,
            format: vk::Format::UNDEFINED,
            size: (0, 0),
        }
    }
}

/// The whole of one level and layer.
pub fn range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(aspect)
        .level_count(1)
        .layer_count(1)
}

/// A full barrier of `image` between two layouts (the engine is not the subject here).
///
/// # Safety
/// `cmd` is recording on `d`.
pub unsafe fn barrier(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &Img,
    (old, new): (vk::ImageLayout, vk::ImageLayout),
) {
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
        .old_layout(old)
        .new_layout(new)
        .image(image.raw)
        .subresource_range(range(image.aspect))];
    let info = vk::DependencyInfo::default().image_memory_barriers(&b);
    // SAFETY: per the caller.
    unsafe { d.cmd_pipeline_barrier2(cmd, &info) };
}

/// Copy all of `image` (one aspect: colour, or the depth of a depth image) from or to
/// `buffer`, tightly packed.
///
/// # Safety
/// `cmd` is recording on `d`; the image is in the transfer layout of the direction.
pub unsafe fn copy(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    (image, buffer): (&Img, &Buf),
    to_image: bool,
) {
    let aspect = match image.aspect.contains(vk::ImageAspectFlags::DEPTH) {
        true => vk::ImageAspectFlags::DEPTH,
        false => vk::ImageAspectFlags::COLOR,
    };
    let region = [vk::BufferImageCopy::default()
        .image_subresource(
            vk::ImageSubresourceLayers::default()
                .aspect_mask(aspect)
                .layer_count(1),
        )
        .image_extent(vk::Extent3D {
            width: image.size.0,
            height: image.size.1,
            depth: 1,
        })];
    // SAFETY: per the caller.
    unsafe {
        match to_image {
            true => d.cmd_copy_buffer_to_image(
                cmd,
                buffer.raw,
                image.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
            ),
            false => {
                d.cmd_copy_image_to_buffer(
                    cmd,
                    image.raw,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    buffer.raw,
                    &region,
                );
                let to_host = [vk::MemoryBarrier2::default()
                    .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
                    .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                    .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                    .dst_access_mask(vk::AccessFlags2::HOST_READ)];
                let info = vk::DependencyInfo::default().memory_barriers(&to_host);
                d.cmd_pipeline_barrier2(cmd, &info);
            }
        }
    }
}

impl Engine {
    /// Instance (Vulkan 1.3, with `validation`), the first device with a graphics + compute
    /// queue made with what the renderer needs, its allocator, a command buffer and a fence.
    pub fn new(validation: Validation) -> Result<Self> {
        // SAFETY: the engine's own Vulkan setup; every handle is destroyed in drop.
        unsafe {
            let entry = ash::Entry::load().context("Vulkan loader (run tools/setup.sh)")?;
            let app = vk::ApplicationInfo::default()
                .application_name(c"engine")
                .api_version(vk::API_VERSION_1_3);
            let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
            let extensions = [ash::ext::debug_utils::NAME.as_ptr()];
            let n = (validation != Validation::Off) as usize;
            let sync = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
            let mut features =
                vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync);
            let mut info = vk::InstanceCreateInfo::default()
                .application_info(&app)
                .enabled_layer_names(&layers[..n])
                .enabled_extension_names(&extensions[..n]);
            if validation == Validation::WithSync {
                info = info.push_next(&mut features);
            }
            let instance = entry
                .create_instance(&info, None)
                .context("instance (validation: run tools/setup.sh)")?;
            let (physical, family) = instance
                .enumerate_physical_devices()?
                .into_iter()
                .find_map(|p| {
                    let wanted = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
                    instance
                        .get_physical_device_queue_family_properties(p)
                        .iter()
                        .position(|f| f.queue_flags.contains(wanted))
                        .map(|i| (p, i as u32))
                })
                .context("no device with a graphics and compute queue")?;
            // What the renderer needs; an engine adds its own extensions here.
            let device = create_host_device(&instance, physical, family, &[])?;
            let queue = device.get_device_queue(family, 0);
            let allocator = Allocator::new(&AllocatorCreateDesc {
                instance: instance.clone(),
                device: device.clone(),
                physical_device: physical,
                debug_settings: Default::default(),
                buffer_device_address: true,
                allocation_sizes: Default::default(),
            })?;
            let pool_info = vk::CommandPoolCreateInfo::default()
                .queue_family_index(family)
                .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
            let pool = device.create_command_pool(&pool_info, None)?;
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(pool)
                .command_buffer_count(1);
            let cmd = device.allocate_command_buffers(&alloc)?[0];
            let fence = device.create_fence(&vk::FenceCreateInfo::default(), None)?;
            Ok(Engine {
                entry,
                instance,
                physical,
                device,
                family,
                queue,
                allocator: Some(Arc::new(Mutex::new(allocator))),
                pool,
                cmd,
                fence,
            })
        }
    }

    /// What the renderer borrows: device and queue, and the allocator when `share_allocator`.
    pub fn lend(&self, validation: bool, share_allocator: bool) -> HostDevice {
        HostDevice {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical: self.physical,
            device: self.device.clone(),
            queue_family: self.family,
            queue: self.queue,
            validation,
            allocator: self.allocator.clone().filter(|_| share_allocator),
        }
    }

    fn allocate(
        &self,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Result<Allocation> {
        let desc = AllocationCreateDesc {
            name: "engine",
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        };
        let allocator = self.allocator.as_ref().context("allocator")?;
        let mut allocator = allocator
            .lock()
            .map_err(|_| anyhow::anyhow!("allocator lock"))?;
        Ok(allocator.allocate(&desc)?)
    }

    /// Give `memory` back to the allocator.
    pub fn free(&self, memory: Option<Allocation>) {
        if let (Some(m), Some(a)) = (memory, self.allocator.as_ref())
            && let Ok(mut a) = a.lock()
        {
            let _ = a.free(m);
        }
    }

    /// A buffer of `bytes` in `location` (host-visible ones are mapped), holding `data`.
    pub fn buffer(
        &self,
        usage: vk::BufferUsageFlags,
        (bytes, location): (u64, MemoryLocation),
        data: &[u8],
    ) -> Result<Buf> {
        let d = &self.device;
        // SAFETY: the engine's device; the buffer is destroyed by `destroy_buffer`.
        unsafe {
            let info = vk::BufferCreateInfo::default()
                .size(bytes.max(data.len() as u64))
                .usage(usage);
            let raw = d.create_buffer(&info, None)?;
            let mut memory =
                self.allocate(d.get_buffer_memory_requirements(raw), location, true)?;
            d.bind_buffer_memory(raw, memory.memory(), memory.offset())?;
            if !data.is_empty() {
                memory.mapped_slice_mut().context("mapped")?[..data.len()].copy_from_slice(data);
            }
            Ok(Buf {
                raw,
                memory: Some(memory),
            })
        }
    }

    /// A 2D image of `format` and `usage` with a view of all its aspects.
    pub fn image(
        &self,
        size: (u32, u32),
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Result<Img> {
        let d = &self.device;
        // SAFETY: the engine's device; the image is destroyed by `destroy_image`.
        unsafe {
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
            let raw = d.create_image(&info, None)?;
            let memory = self.allocate(
                d.get_image_memory_requirements(raw),
                MemoryLocation::GpuOnly,
                false,
            )?;
            d.bind_image_memory(raw, memory.memory(), memory.offset())?;
            let aspect = hairmesh::vk::image::aspect(format);
            let view_info = vk::ImageViewCreateInfo::default()
                .image(raw)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format)
                .subresource_range(range(aspect));
            let view = d.create_image_view(&view_info, None)?;
            Ok(Img {
                raw,
                view,
                memory: Some(memory),
                aspect,
                format,
                size,
            })
        }
    }

    /// Destroy `image` (its frames have completed).
    pub fn destroy_image(&self, mut image: Img) {
        // SAFETY: the engine's image, no longer used by the GPU.
        unsafe {
            self.device.destroy_image_view(image.view, None);
            self.device.destroy_image(image.raw, None);
        }
        self.free(image.memory.take());
    }

    /// Destroy `buffer` (its frames have completed).
    pub fn destroy_buffer(&self, mut buffer: Buf) {
        // SAFETY: the engine's buffer, no longer used by the GPU.
        unsafe { self.device.destroy_buffer(buffer.raw, None) };
        self.free(buffer.memory.take());
    }

    /// Record the engine's command buffer with `record`, submit it and wait for it.
    pub fn submit<T>(&self, record: impl FnOnce(vk::CommandBuffer) -> Result<T>) -> Result<T> {
        let d = &self.device;
        // SAFETY: the engine's command buffer; its last submission was waited for.
        unsafe {
            d.begin_command_buffer(self.cmd, &vk::CommandBufferBeginInfo::default())?;
            let result = record(self.cmd);
            d.end_command_buffer(self.cmd)?;
            let value = result?;
            let cmds = [self.cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            d.queue_submit(self.queue, &submit, self.fence)?;
            d.wait_for_fences(&[self.fence], true, u64::MAX)?;
            d.reset_fences(&[self.fence])?;
            Ok(value)
        }
    }
}

impl Drop for Engine {
    fn drop(&mut self) {
        // SAFETY: everything made on the device is gone (the renderer's context too).
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_fence(self.fence, None);
            self.device.destroy_command_pool(self.pool, None);
            self.allocator.take();
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}
