//! The wgpu bridge (feature `wgpu`): a wgpu device on Vulkan made with the renderer's
//! extensions and features, the renderer's [`Context`] on that same device, wgpu textures as
//! host images and host frames recorded into a wgpu command encoder. With it an engine built
//! on wgpu (Bevy) shares one device, one queue and its own targets with the renderer: no
//! second device, no copy.
//!
//! wgpu enables a device's features through structures it keeps private, and a Vulkan chain
//! may hold each kind only once, so the device is made here: wgpu's adapter lists its
//! extensions and feature chain ([`wgpu::hal::vulkan::Adapter::physical_device_features`]),
//! the renderer's features are merged into that chain (`device::create_with_features`), and
//! wgpu takes the device over ([`wgpu::hal::vulkan::Adapter::device_from_raw`]).

pub use wgpu;

use std::future::Future;
use std::sync::Arc;

use ash::vk;
use wgpu::hal::api::Vulkan;

use super::context::{Context, HostDevice};
use super::device;
use super::image::{Image, ImageDesc};
use super::{GpuError, GpuResult};

/// What [`WgpuDevice::new`] makes.
#[derive(Clone, Debug, Default)]
pub struct WgpuDesc {
    /// The Vulkan validation layer on the instance (wgpu's `VALIDATION` flag), its messages
    /// counted by the renderer's context as in its own frames.
    pub validation: bool,
    /// A device whose name contains this (case-insensitive); `None`: the first adapter the
    /// renderer can use, in wgpu's order.
    pub device: Option<String>,
    /// wgpu features the host wants besides the adapter's own (`None`: every feature the
    /// adapter has except the experimental ones, as Bevy asks by default).
    pub features: Option<wgpu::Features>,
}

/// A wgpu device on Vulkan that the renderer can draw with: wgpu's instance, adapter, device
/// and queue, and the renderer's [`Context`] on the same `VkDevice` and `VkQueue`.
///
/// wgpu owns the device and destroys it when its last handle goes; every renderer made on
/// [`WgpuDevice::context`] must be dropped before that (keep a clone of
/// [`WgpuDevice::device`] beside them, declared after them).
pub struct WgpuDevice {
    /// The renderer's context on the device (its own memory allocator and pipelines).
    pub context: Arc<Context>,
    /// wgpu's device.
    pub device: wgpu::Device,
    /// wgpu's queue: the queue the renderer submits its uploads to. Both record into it
    /// from one thread at a time (Vulkan's rule for a queue): the host calls the renderer's
    /// loading functions where it submits nothing itself.
    pub queue: wgpu::Queue,
    /// wgpu's adapter.
    pub adapter: wgpu::Adapter,
    /// wgpu's instance.
    pub instance: wgpu::Instance,
}

impl WgpuDevice {
    /// A Vulkan instance and device through wgpu, with the renderer's features. Fails in one
    /// line naming the missing feature when no adapter has what the renderer needs.
    pub fn new(desc: &WgpuDesc) -> GpuResult<Self> {
        let flags = if desc.validation {
            wgpu::InstanceFlags::VALIDATION | wgpu::InstanceFlags::DEBUG
        } else {
            wgpu::InstanceFlags::empty()
        };
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN,
            flags,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapters = block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
        let mut refusals = Vec::new();
        for adapter in adapters {
            let name = adapter.get_info().name;
            if let Some(want) = &desc.device
                && !name.to_lowercase().contains(&want.to_lowercase())
            {
                continue;
            }
            match open(&adapter, desc) {
                Ok((context, device, queue)) => {
                    return Ok(WgpuDevice {
                        context,
                        device,
                        queue,
                        adapter,
                        instance,
                    });
                }
                Err(e) => refusals.push(e.to_string()),
            }
        }
        Err(GpuError::Unsupported(match refusals.is_empty() {
            true => match &desc.device {
                Some(d) => format!("wgpu: no Vulkan adapter matches '{d}'"),
                None => "wgpu: no Vulkan adapter (run tools/setup.sh for lavapipe)".into(),
            },
            false => format!("wgpu: {}", refusals.join("; ")),
        }))
    }
}

/// The device on `adapter`: wgpu's extensions and features with the renderer's merged in.
fn open(
    adapter: &wgpu::Adapter,
    desc: &WgpuDesc,
) -> GpuResult<(Arc<Context>, wgpu::Device, wgpu::Queue)> {
    let mut features = adapter.features() - wgpu::Features::all_experimental_mask();
    if let Some(extra) = desc.features {
        features |= extra;
    }
    let limits = adapter.limits();
    // SAFETY: the hal adapter is used only while `adapter` lives, within this function.
    let hal = unsafe { adapter.as_hal::<Vulkan>() }
        .ok_or_else(|| GpuError::Unsupported("wgpu: the adapter is not a Vulkan one".into()))?;
    let shared = hal.shared_instance();
    let (entry, instance) = (shared.entry().clone(), shared.raw_instance().clone());
    let physical = hal.raw_physical_device();
    let name = adapter.get_info().name;
    let found = device::query_features(&instance, physical, &name)?;
    let family = device::graphics_family(&instance, physical, &name, None)?;
    let mut extensions = hal.required_device_extensions(features);
    if found.has_mesh() && !extensions.contains(&ash::ext::mesh_shader::NAME) {
        extensions.push(ash::ext::mesh_shader::NAME);
    }
    let mut wgpu_chain = hal.physical_device_features(&extensions, features);
    let names: Vec<_> = extensions.iter().map(|e| e.as_ptr()).collect();
    let priorities = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(family)
        .queue_priorities(&priorities)];
    let info = wgpu_chain.add_to_device_create(
        vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_extension_names(&names),
    );
    let raw = device::create_with_features(&instance, physical, info, &found)?;
    let hal_device = hand_to_wgpu(&hal, &raw, &extensions, features, &limits, family)?;
    let wgpu_desc = wgpu::DeviceDescriptor {
        label: Some("hairmesh"),
        required_features: features,
        required_limits: limits,
        ..Default::default()
    };
    // SAFETY: `hal_device` was opened on this adapter with `features` and `limits`.
    let (wgpu_device, queue) = unsafe { adapter.create_device_from_hal(hal_device, &wgpu_desc) }
        .map_err(|e| GpuError::Unsupported(format!("wgpu: {name}: {e}")))?;
    // SAFETY: the device and queue were created above with one queue of `family`.
    let raw_queue = unsafe { raw.get_device_queue(family, 0) };
    let context = Context::from_host(HostDevice {
        entry,
        instance,
        physical,
        device: raw,
        queue_family: family,
        queue: raw_queue,
        validation: desc.validation,
        allocator: None,
    })?;
    Ok((Arc::new(context), wgpu_device, queue))
}

/// wgpu takes `raw` over (and destroys it when its device goes).
fn hand_to_wgpu(
    hal: &wgpu::hal::vulkan::Adapter,
    raw: &ash::Device,
    extensions: &[&'static std::ffi::CStr],
    features: wgpu::Features,
    limits: &wgpu::Limits,
    family: u32,
) -> GpuResult<wgpu::hal::OpenDevice<Vulkan>> {
    // SAFETY: `raw` was created from `hal`'s physical device with `extensions` and (a
    // superset of) the chain `physical_device_features(extensions, features)` gave, one
    // queue of `family`; wgpu owns it from here (no drop callback).
    let opened = unsafe {
        hal.device_from_raw(
            raw.clone(),
            None,
            extensions,
            features,
            limits,
            &wgpu::MemoryHints::Performance,
            family,
            0,
        )
    };
    opened.map_err(|e| {
        // SAFETY: wgpu refused the device, so it is still ours and used by nothing.
        unsafe { raw.destroy_device(None) };
        GpuError::Unsupported(format!("wgpu: device_from_raw: {e}"))
    })
}

/// Run a future that completes without waiting (wgpu's native adapter enumeration).
fn block_on<F: Future>(future: F) -> F::Output {
    let mut future = std::pin::pin!(future);
    let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
    loop {
        if let std::task::Poll::Ready(out) = future.as_mut().poll(&mut cx) {
            return out;
        }
        std::thread::yield_now();
    }
}

/// The Vulkan usage a wgpu texture was created with (what the renderer may do with it).
fn vk_usage(usage: wgpu::TextureUsages, depth: bool) -> vk::ImageUsageFlags {
    let mut out = vk::ImageUsageFlags::empty();
    let pairs = [
        (
            wgpu::TextureUsages::COPY_SRC,
            vk::ImageUsageFlags::TRANSFER_SRC,
        ),
        (
            wgpu::TextureUsages::COPY_DST,
            vk::ImageUsageFlags::TRANSFER_DST,
        ),
        (
            wgpu::TextureUsages::TEXTURE_BINDING,
            vk::ImageUsageFlags::SAMPLED,
        ),
        (
            wgpu::TextureUsages::STORAGE_BINDING,
            vk::ImageUsageFlags::STORAGE,
        ),
    ];
    for (from, to) in pairs {
        if usage.contains(from) {
            out |= to;
        }
    }
    if usage.contains(wgpu::TextureUsages::RENDER_ATTACHMENT) {
        out |= match depth {
            true => vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            false => vk::ImageUsageFlags::COLOR_ATTACHMENT,
        };
    }
    out
}

impl Image {
    /// A wgpu texture of `wgpu`'s device as a host image (see [`Image::from_host`]): 2D, one
    /// mip level and layer. The texture must outlive this and every frame that used it.
    pub fn from_wgpu(
        ctx: &Arc<Context>,
        wgpu: &WgpuDevice,
        texture: &wgpu::Texture,
        name: &str,
    ) -> GpuResult<Self> {
        let size = texture.size();
        if texture.dimension() != wgpu::TextureDimension::D2
            || size.depth_or_array_layers != 1
            || texture.mip_level_count() != 1
        {
            return Err(GpuError::Unsupported(format!(
                "{name}: a wgpu host texture must be 2D with one layer and one mip level"
            )));
        }
        let format = texture.format();
        // SAFETY: the hal objects are read here only, while `wgpu` and `texture` live.
        let (raw, vk_format) = unsafe {
            let adapter = wgpu.adapter.as_hal::<Vulkan>();
            let hal_texture = texture.as_hal::<Vulkan>();
            match (adapter, hal_texture) {
                (Some(a), Some(t)) => (t.raw_handle(), a.texture_format_as_raw(format)),
                _ => {
                    return Err(GpuError::Unsupported(format!(
                        "{name}: not a Vulkan texture"
                    )));
                }
            }
        };
        let depth = format.is_depth_stencil_format();
        let desc = ImageDesc::new_2d(name, vk_format, size.width, size.height)
            .usage(vk_usage(texture.usage(), depth))
            .samples(texture.sample_count());
        Image::from_host(ctx, raw, &desc)
    }
}

/// Record into a wgpu command encoder of `wgpu`'s device: `record` gets its Vulkan command
/// buffer, recording and outside a render pass. wgpu does not track what `record` does, so
/// it must leave every wgpu texture in the layout it found it in (a host frame's `before` and
/// `after` do), and the encoder must be one of its own: wgpu refuses to mix its own commands
/// with raw ones in an encoder.
pub fn record_into<R>(
    encoder: &mut wgpu::CommandEncoder,
    record: impl FnOnce(vk::CommandBuffer) -> R,
) -> GpuResult<R> {
    // SAFETY: the command buffer is used only inside `record`, while wgpu's encoder is not;
    // wgpu ends it at `finish`.
    let cmd = unsafe { encoder.as_hal_mut::<Vulkan, _, _>(|e| e.map(|e| e.raw_handle())) };
    match cmd {
        Some(cmd) if cmd != vk::CommandBuffer::null() => Ok(record(cmd)),
        _ => Err(GpuError::Unsupported(
            "wgpu: the encoder has no open Vulkan command buffer".into(),
        )),
    }
}
