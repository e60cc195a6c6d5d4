//! Physical device selection, the features this project needs, logical device creation and
//! the device's capabilities ([`DeviceInfo`]). Used by [`Context`](super::Context).

use ash::vk;

use super::context::{ContextDesc, DeviceInfo, Surface};
use super::{GpuError, GpuResult};

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
    // SAFETY: valid physical device.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let presents = |i: usize| {
        surface.is_none_or(|s| {
            // SAFETY: valid physical device, family index and surface.
            unsafe {
                s.loader
                    .get_physical_device_surface_support(physical, i as u32, s.raw)
            }
            .unwrap_or(false)
        })
    };
    let queue_family = families
        .iter()
        .enumerate()
        .position(|(i, f)| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
                && f.timestamp_valid_bits > 0
                && presents(i)
        })
        .ok_or_else(|| {
            GpuError::Unsupported(format!(
                "{name}: no graphics+compute queue with timestamps{}",
                if surface.is_some() {
                    " that can present to the window"
                } else {
                    ""
                }
            ))
        })?;
    Ok((physical, name, queue_family as u32))
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
    let mut enable13 = vk::PhysicalDeviceVulkan13Features::default()
        .dynamic_rendering(true)
        .synchronization2(true)
        .maintenance4(f.maintenance4);
    let mut enable12 = vk::PhysicalDeviceVulkan12Features::default()
        .host_query_reset(f.host_query_reset)
        .runtime_descriptor_array(true)
        .descriptor_binding_partially_bound(true)
        .descriptor_binding_sampled_image_update_after_bind(true)
        .descriptor_binding_update_unused_while_pending(true)
        .shader_sampled_image_array_non_uniform_indexing(true)
        .buffer_device_address(true)
        .shader_buffer_int64_atomics(f.int64_atomics)
        .shader_shared_int64_atomics(f.int64_atomics);
    let mut enable_mesh = vk::PhysicalDeviceMeshShaderFeaturesEXT::default()
        .mesh_shader(true)
        .task_shader(true)
        .mesh_shader_queries(f.mesh_queries);
    let enable_base = vk::PhysicalDeviceFeatures::default()
        .pipeline_statistics_query(f.pipeline_statistics)
        .fragment_stores_and_atomics(f.fragment_stores)
        .shader_int64(f.int64_atomics);
    let mut device_info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_info)
        .enabled_extension_names(&ext_names)
        .enabled_features(&enable_base)
        .push_next(&mut enable13)
        .push_next(&mut enable12);
    if f.mesh {
        device_info = device_info.push_next(&mut enable_mesh);
    }
    // SAFETY: every pointer in device_info lives until the call returns.
    unsafe { instance.create_device(physical, &device_info, None) }.map_err(|result| GpuError::Vk {
        what: "create device",
        result,
    })
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
