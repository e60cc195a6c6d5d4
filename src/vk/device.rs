//! Physical device selection, the features this project needs, logical device creation and
//! the device's capabilities ([`DeviceInfo`]). Used by [`Context`](super::Context).

use ash::vk;

use super::{GpuError, GpuResult};

/// Raw handles of a window to present to (from winit through `raw-window-handle`; feature
/// `window`).
#[cfg(feature = "window")]
#[derive(Clone, Copy, Debug)]
pub struct WindowHandles {
    /// The display connection.
    pub display: raw_window_handle::RawDisplayHandle,
    /// The window.
    pub window: raw_window_handle::RawWindowHandle,
}

/// How to create a [`Context`](super::Context).
#[derive(Clone, Debug, Default)]
pub struct ContextDesc {
    /// Present to this window: creates its surface, requires a queue that can present to it
    /// and enables `VK_KHR_swapchain` (feature `window`).
    #[cfg(feature = "window")]
    pub window: Option<WindowHandles>,
    /// Enable `VK_LAYER_KHRONOS_validation`; validation errors are counted and printed.
    pub validation: bool,
    /// With `validation`: also enable synchronization validation (hazards between commands
    /// that no barrier orders are reported as errors). Slow: for the test that covers every
    /// pass combination.
    pub sync_validation: bool,
    /// Pick the device whose name contains this string (case-insensitive).
    pub device: Option<String>,
}

impl ContextDesc {
    /// Validation on (tests, debug builds).
    pub fn validation(mut self, on: bool) -> Self {
        self.validation = on;
        self
    }

    /// Validation with synchronization validation.
    pub fn sync_validation(mut self, on: bool) -> Self {
        self.validation |= on;
        self.sync_validation = on;
        self
    }

    /// Choose a device by name substring.
    pub fn device(mut self, name: Option<String>) -> Self {
        self.device = name;
        self
    }

    /// Present to `window`.
    #[cfg(feature = "window")]
    pub fn window(mut self, window: WindowHandles) -> Self {
        self.window = Some(window);
        self
    }
}

/// What the chosen device can do.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    /// Device name, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    pub name: String,
    /// Driver name and version.
    pub driver: String,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period: f32,
    /// Whether VK_EXT_mesh_shader (task + mesh) is available and enabled.
    pub mesh_shader: bool,
    /// Whether VK_EXT_mesh_shader queries (`MESH_PRIMITIVES_GENERATED_EXT`) are enabled.
    pub mesh_queries: bool,
    /// Mesh shader limits, when available.
    pub mesh_limits: Option<vk::PhysicalDeviceMeshShaderPropertiesEXT<'static>>,
    /// `maxStorageBufferRange`: the largest storage buffer binding.
    pub max_storage_buffer_range: u64,
    /// Most sampled images one bindless set may hold (the smaller of the per-stage and
    /// per-set update-after-bind limits).
    pub max_bindless_sampled_images: u32,
    /// Sample counts usable for both colour and depth attachments (bit `n` set: `2^n`).
    pub attachment_sample_counts: u32,
    /// Whether 64-bit integers and 64-bit storage-buffer atomics are enabled (k-buffer OIT).
    pub int64_atomics: bool,
    /// Whether the device is a CPU (lavapipe): some passes pick other workgroup sizes.
    pub cpu_device: bool,
}

/// A window surface and its instance-level functions.
pub(crate) struct Surface {
    pub(crate) loader: ash::khr::surface::Instance,
    pub(crate) raw: vk::SurfaceKHR,
}

/// The best Vulkan 1.3 device (discrete > integrated > virtual > CPU), optionally by name, and
/// its graphics + compute queue family with timestamps.
pub(super) fn pick_physical(
    instance: &ash::Instance,
    desc: &ContextDesc,
    surface: Option<&Surface>,
) -> GpuResult<(vk::PhysicalDevice, String, u32)> {
    // SAFETY: plain enumeration/query calls on a valid instance.
    let physicals = unsafe { instance.enumerate_physical_devices() }.unwrap_or_default();
    let mut candidates = Vec::new();
    for &pd in &physicals {
        // SAFETY: valid physical device handle.
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = props
            .device_name_as_c_str()
            .map(|c| c.to_string_lossy().into_owned())
            .unwrap_or_default();
        if props.api_version < vk::API_VERSION_1_3 {
            continue;
        }
        if let Some(want) = &desc.device
            && !name.to_lowercase().contains(&want.to_lowercase())
        {
            continue;
        }
        let rank = match props.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        };
        candidates.push((rank, pd, name));
    }
    candidates.sort_by_key(|c| c.0);
    let Some((_, physical, name)) = candidates.into_iter().next() else {
        return Err(GpuError::Unsupported(match &desc.device {
            Some(d) => format!("no Vulkan 1.3 device matches '{d}'"),
            None => "no Vulkan 1.3 device found (run tools/setup.sh for lavapipe)".into(),
        }));
    };
    let presents = surface.map(|s| {
        move |i: usize| {
            // SAFETY: valid physical device, family index and surface.
            unsafe {
                s.loader
                    .get_physical_device_surface_support(physical, i as u32, s.raw)
            }
            .unwrap_or(false)
        }
    });
    let window = presents.as_ref().map(|p| p as &dyn Fn(usize) -> bool);
    let queue_family = graphics_family(instance, physical, &name, window)?;
    Ok((physical, name, queue_family))
}

/// The first queue family of `physical` with graphics, compute and timestamps (and, given
/// `presents`, that it accepts: the window's surface can be presented from it).
pub(super) fn graphics_family(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    name: &str,
    presents: Option<&dyn Fn(usize) -> bool>,
) -> GpuResult<u32> {
    // SAFETY: valid physical device.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let family = families.iter().enumerate().position(|(i, f)| {
        f.queue_flags
            .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
            && f.timestamp_valid_bits > 0
            && presents.is_none_or(|p| p(i))
    });
    family.map(|i| i as u32).ok_or_else(|| {
        let window = match presents {
            Some(_) => " that can present to the window",
            None => "",
        };
        GpuError::Unsupported(format!(
            "{name}: no graphics+compute queue with timestamps{window}"
        ))
    })
}

/// Optional features found on the device (the required ones are checked).
pub(super) struct DeviceFeatures {
    mesh: bool,
    mesh_queries: bool,
    maintenance4: bool,
    host_query_reset: bool,
    pipeline_statistics: bool,
    fragment_stores: bool,
    /// `shaderInt64`, `shaderBufferInt64Atomics` and `shaderSharedInt64Atomics` (the
    /// k-buffer's and the software rasterizer's 64-bit `atomicMin`).
    int64_atomics: bool,
}

impl DeviceFeatures {
    /// Task and mesh shaders (`VK_EXT_mesh_shader`).
    #[cfg(feature = "wgpu")]
    pub(super) fn has_mesh(&self) -> bool {
        self.mesh
    }
}

/// Query features; fails with the name of the first missing required feature.
pub(super) fn query_features(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    name: &str,
) -> GpuResult<DeviceFeatures> {
    // SAFETY: valid physical device.
    let exts =
        unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
    let has_mesh = exts.iter().any(|e| {
        e.extension_name_as_c_str()
            .is_ok_and(|n| n == ash::ext::mesh_shader::NAME)
    });
    let mut mesh = vk::PhysicalDeviceMeshShaderFeaturesEXT::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut features2 = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut f13)
        .push_next(&mut f12);
    if has_mesh {
        features2 = features2.push_next(&mut mesh);
    }
    // SAFETY: feature chain structs live on this stack frame.
    unsafe { instance.get_physical_device_features2(physical, &mut features2) };
    let base = features2.features;
    // Dynamic rendering and sync2 for the passes; descriptor indexing: every character's
    // textures are one element of bindless arrays.
    let required = [
        ("dynamicRendering", f13.dynamic_rendering),
        ("synchronization2", f13.synchronization2),
        ("runtimeDescriptorArray", f12.runtime_descriptor_array),
        (
            "descriptorBindingPartiallyBound",
            f12.descriptor_binding_partially_bound,
        ),
        (
            "descriptorBindingSampledImageUpdateAfterBind",
            f12.descriptor_binding_sampled_image_update_after_bind,
        ),
        (
            "descriptorBindingUpdateUnusedWhilePending",
            f12.descriptor_binding_update_unused_while_pending,
        ),
        (
            "shaderSampledImageArrayNonUniformIndexing",
            f12.shader_sampled_image_array_non_uniform_indexing,
        ),
        // The hair dynamics reach each character's buffers by address.
        ("bufferDeviceAddress", f12.buffer_device_address),
    ];
    if let Some((missing, _)) = required.iter().find(|(_, on)| *on == 0) {
        return Err(GpuError::Unsupported(format!(
            "{name}: needs the Vulkan feature {missing}"
        )));
    }
    let mesh_ok = has_mesh && mesh.mesh_shader != 0 && mesh.task_shader != 0;
    Ok(DeviceFeatures {
        mesh: mesh_ok,
        mesh_queries: mesh_ok && mesh.mesh_shader_queries != 0,
        maintenance4: f13.maintenance4 != 0,
        host_query_reset: f12.host_query_reset != 0,
        pipeline_statistics: base.pipeline_statistics_query != 0,
        fragment_stores: base.fragment_stores_and_atomics != 0,
        int64_atomics: base.shader_int64 != 0
            && f12.shader_buffer_int64_atomics != 0
            && f12.shader_shared_int64_atomics != 0,
    })
}

/// Create the logical device with one queue of `queue_family` and the features.
pub(super) fn create_logical(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    queue_family: u32,
    f: &DeviceFeatures,
    swapchain: bool,
) -> GpuResult<ash::Device> {
    let extensions: &[&std::ffi::CStr] = if swapchain {
        &[ash::khr::swapchain::NAME]
    } else {
        &[]
    };
    create_device(instance, physical, queue_family, f, extensions)
}

/// The device with features `f` and the `extra` extensions.
fn create_device(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    queue_family: u32,
    f: &DeviceFeatures,
    extra: &[&std::ffi::CStr],
) -> GpuResult<ash::Device> {
    let priorities = [1.0f32];
    let queue_info = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(queue_family)
        .queue_priorities(&priorities)];
    let mut ext_names: Vec<*const std::ffi::c_char> = extra.iter().map(|e| e.as_ptr()).collect();
    if f.mesh && !extra.contains(&ash::ext::mesh_shader::NAME) {
        ext_names.push(ash::ext::mesh_shader::NAME.as_ptr());
    }
    let info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_info)
        .enabled_extension_names(&ext_names);
    create_with_features(instance, physical, info, f)
}

/// The feature structures the renderer adds to a device's create info, one per kind it may
/// have to append (kept here so that they outlive the create call).
#[derive(Default)]
struct FeatureChain {
    core: vk::PhysicalDeviceFeatures,
    indexing: vk::PhysicalDeviceDescriptorIndexingFeatures<'static>,
    address: vk::PhysicalDeviceBufferDeviceAddressFeatures<'static>,
    atomics: vk::PhysicalDeviceShaderAtomicInt64Features<'static>,
    query_reset: vk::PhysicalDeviceHostQueryResetFeatures<'static>,
    rendering: vk::PhysicalDeviceDynamicRenderingFeatures<'static>,
    sync2: vk::PhysicalDeviceSynchronization2Features<'static>,
    maintenance4: vk::PhysicalDeviceMaintenance4Features<'static>,
    mesh: vk::PhysicalDeviceMeshShaderFeaturesEXT<'static>,
}

/// Create the device of `info` with the renderer's features `f` turned on as well: every
/// feature structure already in `info`'s chain (a host's, e.g. wgpu's) gets the renderer's
/// bits of its kind, and the kinds it lacks are appended, so that no structure appears twice
/// and the Vulkan 1.2/1.3 aggregates never sit beside their parts (both invalid). Nothing the
/// host turned on is turned off.
pub(super) fn create_with_features(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    mut info: vk::DeviceCreateInfo<'_>,
    f: &DeviceFeatures,
) -> GpuResult<ash::Device> {
    let mut chain = FeatureChain::default();
    if !info.p_enabled_features.is_null() {
        // SAFETY: a non-null p_enabled_features points at the host's structure.
        chain.core = unsafe { *info.p_enabled_features };
    }
    let mut core_in_chain = false;
    let mut found = FoundKinds::default();
    let mut tail: *mut vk::BaseOutStructure = std::ptr::null_mut();
    let mut node = info.p_next as *mut vk::BaseOutStructure;
    while !node.is_null() {
        // SAFETY: every structure of a valid pNext chain starts with sType and pNext, and
        // the host's structures outlive this call; each is written through its own pointer.
        unsafe {
            core_in_chain |= enable_in(node, f, &mut found);
            tail = node;
            node = (*node).p_next;
        }
    }
    enable_core(&mut chain.core, f);
    let appended = append_missing(&mut chain, f, &found);
    if !appended.is_null() {
        if tail.is_null() {
            info.p_next = appended as *const std::ffi::c_void;
        } else {
            // SAFETY: `tail` is the chain's last structure (see above).
            unsafe { (*tail).p_next = appended };
        }
    }
    if !core_in_chain {
        info.p_enabled_features = &chain.core;
    }
    // SAFETY: every pointer in `info` (the host's and `chain`'s) lives until the call returns.
    unsafe { instance.create_device(physical, &info, None) }.map_err(|result| GpuError::Vk {
        what: "create device",
        result,
    })
}

/// Which kinds of feature structure a create info's chain already holds.
#[derive(Default)]
struct FoundKinds {
    vulkan12: bool,
    vulkan13: bool,
    indexing: bool,
    address: bool,
    atomics: bool,
    query_reset: bool,
    rendering: bool,
    sync2: bool,
    maintenance4: bool,
    mesh: bool,
}

/// Turn the renderer's bits on in the structure at `node` if it is a feature structure of a
/// kind the renderer uses, noting its kind in `found`; true for `PhysicalDeviceFeatures2`.
///
/// # Safety
/// `node` points at a live, writable structure of a pNext chain.
unsafe fn enable_in(
    node: *mut vk::BaseOutStructure,
    f: &DeviceFeatures,
    found: &mut FoundKinds,
) -> bool {
    use vk::StructureType as S;
    let on = vk::TRUE;
    let int64 = if f.int64_atomics { on } else { vk::FALSE };
    // SAFETY (each cast): the structure's sType names its type.
    unsafe {
        match (*node).s_type {
            S::PHYSICAL_DEVICE_FEATURES_2 => {
                enable_core(
                    &mut (*(node as *mut vk::PhysicalDeviceFeatures2)).features,
                    f,
                );
                return true;
            }
            S::PHYSICAL_DEVICE_VULKAN_1_2_FEATURES => {
                enable_vulkan12(&mut *(node as *mut vk::PhysicalDeviceVulkan12Features), f);
                found.vulkan12 = true;
            }
            S::PHYSICAL_DEVICE_VULKAN_1_3_FEATURES => {
                enable_vulkan13(&mut *(node as *mut vk::PhysicalDeviceVulkan13Features), f);
                found.vulkan13 = true;
            }
            S::PHYSICAL_DEVICE_DESCRIPTOR_INDEXING_FEATURES => {
                enable_indexing(&mut *(node as *mut vk::PhysicalDeviceDescriptorIndexingFeatures));
                found.indexing = true;
            }
            S::PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES => {
                (*(node as *mut vk::PhysicalDeviceBufferDeviceAddressFeatures))
                    .buffer_device_address = on;
                found.address = true;
            }
            S::PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES => {
                let v = &mut *(node as *mut vk::PhysicalDeviceShaderAtomicInt64Features);
                v.shader_buffer_int64_atomics |= int64;
                v.shader_shared_int64_atomics |= int64;
                found.atomics = true;
            }
            S::PHYSICAL_DEVICE_HOST_QUERY_RESET_FEATURES => {
                (*(node as *mut vk::PhysicalDeviceHostQueryResetFeatures)).host_query_reset |=
                    f.host_query_reset as u32;
                found.query_reset = true;
            }
            S::PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES => {
                (*(node as *mut vk::PhysicalDeviceDynamicRenderingFeatures)).dynamic_rendering = on;
                found.rendering = true;
            }
            S::PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES => {
                (*(node as *mut vk::PhysicalDeviceSynchronization2Features)).synchronization2 = on;
                found.sync2 = true;
            }
            S::PHYSICAL_DEVICE_MAINTENANCE_4_FEATURES => {
                (*(node as *mut vk::PhysicalDeviceMaintenance4Features)).maintenance4 |=
                    f.maintenance4 as u32;
                found.maintenance4 = true;
            }
            S::PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT if f.mesh => {
                enable_mesh(
                    &mut *(node as *mut vk::PhysicalDeviceMeshShaderFeaturesEXT),
                    f,
                );
                found.mesh = true;
            }
            _ => {}
        }
    }
    false
}

/// The renderer's Vulkan 1.2 features: bindless textures, device addresses, 64-bit atomics
/// where wanted, host query reset where the device has it.
fn enable_vulkan12(v: &mut vk::PhysicalDeviceVulkan12Features, f: &DeviceFeatures) {
    let int64 = if f.int64_atomics { vk::TRUE } else { vk::FALSE };
    v.runtime_descriptor_array = vk::TRUE;
    v.descriptor_binding_partially_bound = vk::TRUE;
    v.descriptor_binding_sampled_image_update_after_bind = vk::TRUE;
    v.descriptor_binding_update_unused_while_pending = vk::TRUE;
    v.shader_sampled_image_array_non_uniform_indexing = vk::TRUE;
    v.buffer_device_address = vk::TRUE;
    v.shader_buffer_int64_atomics |= int64;
    v.shader_shared_int64_atomics |= int64;
    v.host_query_reset |= f.host_query_reset as u32;
}

/// The renderer's Vulkan 1.3 features: dynamic rendering, synchronization2, maintenance4
/// where the device has it.
fn enable_vulkan13(v: &mut vk::PhysicalDeviceVulkan13Features, f: &DeviceFeatures) {
    v.dynamic_rendering = vk::TRUE;
    v.synchronization2 = vk::TRUE;
    v.maintenance4 |= f.maintenance4 as u32;
}

/// The renderer's Vulkan 1.0 features, on top of what `core` has.
fn enable_core(core: &mut vk::PhysicalDeviceFeatures, f: &DeviceFeatures) {
    core.pipeline_statistics_query |= f.pipeline_statistics as u32;
    core.fragment_stores_and_atomics |= f.fragment_stores as u32;
    core.shader_int64 |= f.int64_atomics as u32;
}

/// Dynamic indexing of every character's textures in bindless arrays.
fn enable_indexing(v: &mut vk::PhysicalDeviceDescriptorIndexingFeatures) {
    v.runtime_descriptor_array = vk::TRUE;
    v.descriptor_binding_partially_bound = vk::TRUE;
    v.descriptor_binding_sampled_image_update_after_bind = vk::TRUE;
    v.descriptor_binding_update_unused_while_pending = vk::TRUE;
    v.shader_sampled_image_array_non_uniform_indexing = vk::TRUE;
}

/// Task and mesh shaders (and their statistics where the device counts them).
fn enable_mesh(v: &mut vk::PhysicalDeviceMeshShaderFeaturesEXT, f: &DeviceFeatures) {
    v.mesh_shader = vk::TRUE;
    v.task_shader = vk::TRUE;
    v.mesh_shader_queries |= f.mesh_queries as u32;
}

/// Link the structures of `chain` whose kinds `found` lacks; the first of them (null: none).
fn append_missing(
    chain: &mut FeatureChain,
    f: &DeviceFeatures,
    found: &FoundKinds,
) -> *mut vk::BaseOutStructure<'static> {
    let mut list: Vec<*mut vk::BaseOutStructure<'static>> = Vec::new();
    let mut push = |p: *mut vk::BaseOutStructure<'static>| list.push(p);
    if !found.vulkan12 {
        if !found.indexing {
            enable_indexing(&mut chain.indexing);
            push(&mut chain.indexing as *mut _ as *mut _);
        }
        if !found.address {
            chain.address.buffer_device_address = vk::TRUE;
            push(&mut chain.address as *mut _ as *mut _);
        }
        if f.int64_atomics && !found.atomics {
            chain.atomics.shader_buffer_int64_atomics = vk::TRUE;
            chain.atomics.shader_shared_int64_atomics = vk::TRUE;
            push(&mut chain.atomics as *mut _ as *mut _);
        }
        if f.host_query_reset && !found.query_reset {
            chain.query_reset.host_query_reset = vk::TRUE;
            push(&mut chain.query_reset as *mut _ as *mut _);
        }
    }
    if !found.vulkan13 {
        if !found.rendering {
            chain.rendering.dynamic_rendering = vk::TRUE;
            push(&mut chain.rendering as *mut _ as *mut _);
        }
        if !found.sync2 {
            chain.sync2.synchronization2 = vk::TRUE;
            push(&mut chain.sync2 as *mut _ as *mut _);
        }
        if f.maintenance4 && !found.maintenance4 {
            chain.maintenance4.maintenance4 = vk::TRUE;
            push(&mut chain.maintenance4 as *mut _ as *mut _);
        }
    }
    if f.mesh && !found.mesh {
        enable_mesh(&mut chain.mesh, f);
        push(&mut chain.mesh as *mut _ as *mut _);
    }
    for pair in list.windows(2) {
        // SAFETY: both point into `chain`, alive for the caller's create call.
        unsafe { (*pair[0]).p_next = pair[1] };
    }
    list.first().copied().unwrap_or(std::ptr::null_mut())
}

/// Create a device for a host ([`super::HostDevice`]) on `physical` with one queue of
/// `queue_family`: the extensions and features the renderer uses where the device has them,
/// plus the host's `extensions` (e.g. `VK_KHR_swapchain`). The host owns the device and
/// destroys it after every renderer on it is dropped. Fails with the name of a missing
/// required feature.
pub fn create_host_device(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    queue_family: u32,
    extensions: &[&std::ffi::CStr],
) -> GpuResult<ash::Device> {
    // SAFETY: valid physical device of `instance`.
    let props = unsafe { instance.get_physical_device_properties(physical) };
    let name = props
        .device_name_as_c_str()
        .map(|c| c.to_string_lossy().into_owned())
        .unwrap_or_default();
    let features = query_features(instance, physical, &name)?;
    create_device(instance, physical, queue_family, &features, extensions)
}

/// What the device can do, for the features enabled.
pub(super) fn query_info(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    name: String,
    f: &DeviceFeatures,
) -> DeviceInfo {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut mesh_props = vk::PhysicalDeviceMeshShaderPropertiesEXT::default();
    let mut indexing = vk::PhysicalDeviceDescriptorIndexingProperties::default();
    let mut p2 = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut driver)
        .push_next(&mut indexing);
    if f.mesh {
        p2 = p2.push_next(&mut mesh_props);
    }
    // SAFETY: property query with a chain living on this frame.
    unsafe { instance.get_physical_device_properties2(physical, &mut p2) };
    let limits = p2.properties.limits;
    let cpu_device = p2.properties.device_type == vk::PhysicalDeviceType::CPU;
    let text = |s: Result<&std::ffi::CStr, _>| {
        s.map(|c| c.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let driver = format!(
        "{} {}",
        text(driver.driver_name_as_c_str()),
        text(driver.driver_info_as_c_str())
    );
    mesh_props.p_next = std::ptr::null_mut();
    DeviceInfo {
        name,
        driver,
        timestamp_period: limits.timestamp_period,
        mesh_shader: f.mesh,
        mesh_queries: f.mesh_queries,
        mesh_limits: f.mesh.then_some(mesh_props),
        max_storage_buffer_range: limits.max_storage_buffer_range as u64,
        max_bindless_sampled_images: indexing
            .max_per_stage_descriptor_update_after_bind_sampled_images
            .min(indexing.max_descriptor_set_update_after_bind_sampled_images)
            .min(indexing.max_update_after_bind_descriptors_in_all_pools),
        attachment_sample_counts: (limits.framebuffer_color_sample_counts
            & limits.framebuffer_depth_sample_counts)
            .as_raw(),
        int64_atomics: f.int64_atomics,
        cpu_device,
    }
}
