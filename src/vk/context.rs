//! Instance, device selection, queue, memory allocator, validation and one-shot submission.

use std::ffi::{CStr, CString, c_void};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use ash::ext::debug_utils;
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::command::{CommandBuffer, CommandRecorder};
use super::sync::Fence;
use super::{GpuError, GpuResult, VkContext};

/// How to create a [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextDesc {
    /// Enable `VK_LAYER_KHRONOS_validation`; validation errors are counted and printed.
    pub validation: bool,
    /// Pick the device whose name contains this string (case-insensitive).
    pub device: Option<String>,
}

impl ContextDesc {
    /// Validation on (tests, debug builds).
    pub fn validation(mut self, on: bool) -> Self {
        self.validation = on;
        self
    }

    /// Choose a device by name substring.
    pub fn device(mut self, name: Option<String>) -> Self {
        self.device = name;
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
    /// `maxComputeWorkGroupCount[0]`.
    pub max_compute_groups_x: u32,
}

/// GPU memory the allocator holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryReport {
    /// Bytes of live allocations.
    pub allocated_bytes: u64,
    /// Bytes of memory blocks (allocated + free space inside them).
    pub capacity_bytes: u64,
    /// Number of live allocations.
    pub allocations: usize,
}

struct DebugState {
    errors: AtomicU32,
    messages: Mutex<Vec<String>>,
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the loader passes valid callback data; `user` is the DebugState we registered,
    // which outlives the messenger.
    let (msg, state) = unsafe {
        let msg = if data.is_null() || (*data).p_message.is_null() {
            String::from("(no message)")
        } else {
            CStr::from_ptr((*data).p_message)
                .to_string_lossy()
                .into_owned()
        };
        (msg, &*(user as *const DebugState))
    };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        state.errors.fetch_add(1, Ordering::SeqCst);
        eprintln!("[vulkan validation error] {msg}");
        if let Ok(mut m) = state.messages.lock() {
            m.push(msg);
        }
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        eprintln!("[vulkan validation warning] {msg}");
    }
    vk::FALSE
}

/// The Vulkan device and everything created once per process.
pub struct Context {
    _entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    debug_device: Option<debug_utils::Device>,
    debug_state: Arc<DebugState>,
    physical: vk::PhysicalDevice,
    pub(crate) device: ash::Device,
    queue: vk::Queue,
    pub(crate) queue_family: u32,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    pub(crate) mesh_ext: Option<ash::ext::mesh_shader::Device>,
    /// Capabilities of the device.
    pub info: DeviceInfo,
}

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

impl Context {
    /// Create instance and device: a discrete GPU if present, else integrated, else lavapipe.
    pub fn new(desc: &ContextDesc) -> GpuResult<Self> {
        // SAFETY: loading the system Vulkan loader; failure is reported, not assumed.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| GpuError::Loader(e.to_string()))?;
        let app = vk::ApplicationInfo::default()
            .application_name(c"hairmesh")
            .api_version(vk::API_VERSION_1_3);
        let mut layers: Vec<*const i8> = Vec::new();
        if desc.validation {
            // SAFETY: plain enumeration call.
            let available =
                unsafe { entry.enumerate_instance_layer_properties() }.ctx("enumerate layers")?;
            let found = available
                .iter()
                .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
            if !found {
                return Err(GpuError::Unsupported(
                    "validation requested but VK_LAYER_KHRONOS_validation is not installed (run tools/setup.sh)".into(),
                ));
            }
            layers.push(VALIDATION_LAYER.as_ptr());
        }
        let extensions = [debug_utils::NAME.as_ptr()];
        let debug_state = Arc::new(DebugState {
            errors: AtomicU32::new(0),
            messages: Mutex::new(Vec::new()),
        });
        let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(debug_callback))
            .user_data(Arc::as_ptr(&debug_state) as *mut c_void);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if desc.validation {
            info = info.push_next(&mut messenger_info);
        }
        // SAFETY: all pointers in `info` live until the call returns.
        let instance = unsafe { entry.create_instance(&info, None) }.ctx("create instance")?;
        let debug = if desc.validation {
            let loader = debug_utils::Instance::new(&entry, &instance);
            // SAFETY: messenger info is valid; the DebugState outlives the messenger (dropped after it).
            let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_info, None) }
                .ctx("create messenger")?;
            Some((loader, messenger))
        } else {
            None
        };
        Self::create_device(entry, instance, debug, debug_state, desc)
    }

    fn create_device(
        entry: ash::Entry,
        instance: ash::Instance,
        debug: Option<(debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
        debug_state: Arc<DebugState>,
        desc: &ContextDesc,
    ) -> GpuResult<Self> {
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
            destroy_instance(&instance, debug);
            return Err(GpuError::Unsupported(match &desc.device {
                Some(d) => format!("no Vulkan 1.3 device matches '{d}'"),
                None => "no Vulkan 1.3 device found (run tools/setup.sh for lavapipe)".into(),
            }));
        };
        // SAFETY: valid physical device.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let Some(queue_family) = families.iter().position(|f| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
                && f.timestamp_valid_bits > 0
        }) else {
            destroy_instance(&instance, debug);
            return Err(GpuError::Unsupported(format!(
                "{name}: no graphics+compute queue with timestamps"
            )));
        };
        let queue_family = queue_family as u32;
        // SAFETY: valid physical device.
        let exts =
            unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
        let has_mesh = exts.iter().any(|e| {
            e.extension_name_as_c_str()
                .is_ok_and(|n| n == ash::ext::mesh_shader::NAME)
        });

        let mut mesh_features = vk::PhysicalDeviceMeshShaderFeaturesEXT::default();
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut features2 = vk::PhysicalDeviceFeatures2::default()
            .push_next(&mut f13)
            .push_next(&mut f12);
        if has_mesh {
            features2 = features2.push_next(&mut mesh_features);
        }
        // SAFETY: feature chain structs live on this stack frame.
        unsafe { instance.get_physical_device_features2(physical, &mut features2) };
        let base = features2.features;
        if f13.dynamic_rendering == 0 || f13.synchronization2 == 0 {
            destroy_instance(&instance, debug);
            return Err(GpuError::Unsupported(format!(
                "{name}: needs dynamicRendering and synchronization2"
            )));
        }
        // Descriptor indexing: every character's textures are one bindless array element.
        let indexing = [
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
        ];
        if let Some((missing, _)) = indexing.iter().find(|(_, on)| *on == 0) {
            destroy_instance(&instance, debug);
            return Err(GpuError::Unsupported(format!(
                "{name}: needs descriptor indexing feature {missing}"
            )));
        }
        let mesh_ok = has_mesh && mesh_features.mesh_shader != 0 && mesh_features.task_shader != 0;

        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut ext_names = Vec::new();
        if mesh_ok {
            ext_names.push(ash::ext::mesh_shader::NAME.as_ptr());
        }
        let mut enable13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true)
            .maintenance4(f13.maintenance4 != 0);
        let mut enable12 = vk::PhysicalDeviceVulkan12Features::default()
            .host_query_reset(f12.host_query_reset != 0)
            .runtime_descriptor_array(true)
            .descriptor_binding_partially_bound(true)
            .descriptor_binding_sampled_image_update_after_bind(true)
            .descriptor_binding_update_unused_while_pending(true)
            .shader_sampled_image_array_non_uniform_indexing(true);
        let mut enable_mesh = vk::PhysicalDeviceMeshShaderFeaturesEXT::default()
            .mesh_shader(true)
            .task_shader(true)
            .mesh_shader_queries(mesh_features.mesh_shader_queries != 0);
        let enable_base = vk::PhysicalDeviceFeatures::default()
            .pipeline_statistics_query(base.pipeline_statistics_query != 0)
            .fragment_stores_and_atomics(base.fragment_stores_and_atomics != 0);
        let mut device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&ext_names)
            .enabled_features(&enable_base)
            .push_next(&mut enable13)
            .push_next(&mut enable12);
        if mesh_ok {
            device_info = device_info.push_next(&mut enable_mesh);
        }
        // SAFETY: every pointer in device_info lives until the call returns.
        let device = match unsafe { instance.create_device(physical, &device_info, None) } {
            Ok(d) => d,
            Err(result) => {
                destroy_instance(&instance, debug);
                return Err(GpuError::Vk {
                    what: "create device",
                    result,
                });
            }
        };
        // SAFETY: the queue family/index were requested above.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let allocator = match Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        }) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: nothing was created on the device yet.
                unsafe { device.destroy_device(None) };
                destroy_instance(&instance, debug);
                return Err(e.into());
            }
        };

        // SAFETY: property queries with a chain living on this frame.
        let (props, driver, mesh_limits, indexing) = unsafe {
            let mut driver = vk::PhysicalDeviceDriverProperties::default();
            let mut mesh_props = vk::PhysicalDeviceMeshShaderPropertiesEXT::default();
            let mut indexing = vk::PhysicalDeviceDescriptorIndexingProperties::default();
            let mut p2 = vk::PhysicalDeviceProperties2::default()
                .push_next(&mut driver)
                .push_next(&mut indexing);
            if mesh_ok {
                p2 = p2.push_next(&mut mesh_props);
            }
            instance.get_physical_device_properties2(physical, &mut p2);
            let props = p2.properties;
            let driver_name = format!(
                "{} {}",
                driver
                    .driver_name_as_c_str()
                    .map(|c| c.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                driver
                    .driver_info_as_c_str()
                    .map(|c| c.to_string_lossy().into_owned())
                    .unwrap_or_default()
            );
            mesh_props.p_next = std::ptr::null_mut();
            let bindless = indexing
                .max_per_stage_descriptor_update_after_bind_sampled_images
                .min(indexing.max_descriptor_set_update_after_bind_sampled_images)
                .min(indexing.max_update_after_bind_descriptors_in_all_pools);
            (props, driver_name, mesh_ok.then_some(mesh_props), bindless)
        };
        let debug_device = debug
            .as_ref()
            .map(|_| debug_utils::Device::new(&instance, &device));
        let mesh_ext = mesh_ok.then(|| ash::ext::mesh_shader::Device::new(&instance, &device));
        Ok(Context {
            _entry: entry,
            instance,
            debug,
            debug_device,
            debug_state,
            physical,
            device,
            queue,
            queue_family,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            mesh_ext,
            info: DeviceInfo {
                name,
                driver,
                timestamp_period: props.limits.timestamp_period,
                mesh_shader: mesh_ok,
                mesh_queries: mesh_ok && mesh_features.mesh_shader_queries != 0,
                mesh_limits,
                max_storage_buffer_range: props.limits.max_storage_buffer_range as u64,
                max_bindless_sampled_images: indexing,
                max_compute_groups_x: props.limits.max_compute_work_group_count[0],
            },
        })
    }

    pub(crate) fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// What the memory allocator holds now.
    pub fn memory_report(&self) -> MemoryReport {
        let r = self.allocator().generate_report();
        MemoryReport {
            allocated_bytes: r.total_allocated_bytes,
            capacity_bytes: r.total_capacity_bytes,
            allocations: r.allocations.len(),
        }
    }

    /// Allocate memory for `requirements` and bind it with `bind(memory, offset)`; the
    /// allocation is freed again if binding fails. Callers destroy their object on error.
    pub(crate) fn allocate_bound(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: gpu_allocator::MemoryLocation,
        linear: bool,
        bind: impl FnOnce(vk::DeviceMemory, u64) -> Result<(), vk::Result>,
    ) -> GpuResult<gpu_allocator::vulkan::Allocation> {
        let allocation =
            self.allocator()
                .allocate(&gpu_allocator::vulkan::AllocationCreateDesc {
                    name,
                    requirements,
                    location,
                    linear,
                    allocation_scheme: gpu_allocator::vulkan::AllocationScheme::GpuAllocatorManaged,
                })?;
        // SAFETY: the memory handle is only passed to `bind`, while the allocation is alive.
        let memory = unsafe { allocation.memory() };
        if let Err(result) = bind(memory, allocation.offset()) {
            let _ = self.allocator().free(allocation);
            return Err(GpuError::Vk {
                what: "bind memory",
                result,
            });
        }
        Ok(allocation)
    }

    /// Number of validation errors reported so far (0 when validation is off).
    pub fn validation_errors(&self) -> u32 {
        self.debug_state.errors.load(Ordering::SeqCst)
    }

    /// The validation error messages reported so far.
    pub fn validation_messages(&self) -> Vec<String> {
        self.debug_state
            .messages
            .lock()
            .map(|m| m.clone())
            .unwrap_or_default()
    }

    /// Attach a debug name to a Vulkan object (no-op without validation).
    pub fn name_object<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(d) = &self.debug_device {
            let Ok(cname) = CString::new(name) else {
                return;
            };
            let info = vk::DebugUtilsObjectNameInfoEXT::default()
                .object_handle(handle)
                .object_name(&cname);
            // SAFETY: handle belongs to this device; the name lives for the call.
            let _ = unsafe { d.set_debug_utils_object_name(&info) };
        }
    }

    /// Record commands with `record`, submit them and wait for completion (uploads).
    pub fn submit_and_wait<R>(
        self: &Arc<Self>,
        record: impl FnOnce(&mut CommandRecorder) -> R,
    ) -> GpuResult<R> {
        let mut cmd = CommandBuffer::new(self, "one-shot")?;
        let fence = Fence::new(self, false)?;
        let out = {
            let mut rec = cmd.begin()?;
            record(&mut rec)
        };
        cmd.end()?;
        self.submit(&cmd, &fence)?;
        fence.wait()?;
        Ok(out)
    }

    /// Submit `cmd` to the queue; `fence` is signalled when it completes.
    pub fn submit(&self, cmd: &CommandBuffer, fence: &Fence) -> GpuResult<()> {
        let cmds = [cmd.raw()];
        let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
        // SAFETY: the command buffer finished recording; the fence is unsignalled.
        unsafe { self.device.queue_submit(self.queue, &submit, fence.raw()) }.ctx("queue submit")
    }

    /// Wait until the device is idle.
    pub fn wait_idle(&self) {
        // SAFETY: valid device.
        let _ = unsafe { self.device.device_wait_idle() };
    }

    /// Whether `format` supports linear-filtered sampling with optimal tiling.
    pub fn supports_linear_filter(&self, format: vk::Format) -> bool {
        // SAFETY: plain query.
        let props = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical, format)
        };
        props.optimal_tiling_features.contains(
            vk::FormatFeatureFlags::SAMPLED_IMAGE
                | vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR,
        )
    }
}

/// Destroy an instance (and its messenger) when device creation fails half-way.
fn destroy_instance(
    instance: &ash::Instance,
    debug: Option<(debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
) {
    // SAFETY: no device was created from this instance.
    unsafe {
        if let Some((loader, messenger)) = debug {
            loader.destroy_debug_utils_messenger(messenger, None);
        }
        instance.destroy_instance(None);
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // SAFETY: tear down in reverse creation order after the device is idle; every object
        // created from this context must already be destroyed (they borrow it).
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
