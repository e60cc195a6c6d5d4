//! The context: instance, device (chosen and created in `device.rs`), queue, memory allocator,
//! validation messages and submission.

use std::ffi::{CStr, CString, c_void};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use ash::ext::debug_utils;
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::device::{self, ContextDesc, DeviceInfo, Surface};
use super::{GpuError, GpuResult, VkContext};

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
    /// The memory allocator: the context's own, or one shared with a host.
    allocator: ManuallyDrop<Arc<Mutex<Allocator>>>,
    pub(crate) mesh_ext: Option<ash::ext::mesh_shader::Device>,
    pub(crate) surface: Option<Surface>,
    pub(crate) swapchain_ext: Option<ash::khr::swapchain::Device>,
    /// Whether the instance and device are this context's (else a host's, never destroyed
    /// here).
    owns_device: bool,
    /// Capabilities of the device.
    pub info: DeviceInfo,
}

/// A Vulkan device an engine created and keeps: [`Context::from_host`] borrows it. Create the
/// device with [`super::create_host_device`] (or enable at least what it enables) on an
/// instance of Vulkan 1.3.
pub struct HostDevice {
    /// The loader the instance came from.
    pub entry: ash::Entry,
    /// The host's instance.
    pub instance: ash::Instance,
    /// The physical device of `device`.
    pub physical: vk::PhysicalDevice,
    /// The host's device.
    pub device: ash::Device,
    /// A queue family with graphics and compute.
    pub queue_family: u32,
    /// A queue of that family the renderer submits to (the host orders its own submissions
    /// around the renderer's, or gives it a queue of its own).
    pub queue: vk::Queue,
    /// Count and print validation messages through a messenger of the renderer's own on the
    /// host's instance (which must have `VK_EXT_debug_utils` and the validation layer).
    pub validation: bool,
    /// The host's memory allocator (`gpu-allocator` 0.28, created on this device with buffer
    /// device addresses on) for the renderer to allocate from too; `None`: the renderer makes
    /// its own.
    pub allocator: Option<Arc<Mutex<Allocator>>>,
}

/// The instance extensions `desc`'s window needs (none without one).
#[cfg(feature = "window")]
fn window_extensions(desc: &ContextDesc) -> GpuResult<&'static [*const std::ffi::c_char]> {
    match &desc.window {
        Some(w) => {
            ash_window::enumerate_required_extensions(w.display).ctx("window surface extensions")
        }
        None => Ok(&[]),
    }
}

/// Without the `window` feature there are no windows.
#[cfg(not(feature = "window"))]
fn window_extensions(_desc: &ContextDesc) -> GpuResult<&'static [*const std::ffi::c_char]> {
    Ok(&[])
}

/// The surface of `desc`'s window, if it has one.
#[cfg(feature = "window")]
fn window_surface(
    entry: &ash::Entry,
    instance: &ash::Instance,
    desc: &ContextDesc,
) -> Result<Option<Surface>, vk::Result> {
    let Some(w) = &desc.window else {
        return Ok(None);
    };
    // SAFETY: the handles come from a live window that outlives the context (the caller keeps
    // the window until the context is dropped).
    let raw = unsafe { ash_window::create_surface(entry, instance, w.display, w.window, None)? };
    Ok(Some(Surface {
        loader: ash::khr::surface::Instance::new(entry, instance),
        raw,
    }))
}

/// Without the `window` feature there are no windows.
#[cfg(not(feature = "window"))]
fn window_surface(
    _entry: &ash::Entry,
    _instance: &ash::Instance,
    _desc: &ContextDesc,
) -> Result<Option<Surface>, vk::Result> {
    Ok(None)
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
        let mut extensions = vec![debug_utils::NAME.as_ptr()];
        let sync = desc.validation && desc.sync_validation;
        if sync {
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
        }
        let enabled = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled);
        extensions.extend_from_slice(window_extensions(desc)?);
        let debug_state = Arc::new(DebugState {
            errors: AtomicU32::new(0),
            messages: Mutex::new(Vec::new()),
        });
        let mut messenger_info = messenger_info(&debug_state);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if desc.validation {
            info = info.push_next(&mut messenger_info);
        }
        if sync {
            info = info.push_next(&mut features);
        }
        // SAFETY: all pointers in `info` live until the call returns.
        let instance = unsafe { entry.create_instance(&info, None) }.ctx("create instance")?;
        let debug = if desc.validation {
            let loader = debug_utils::Instance::new(&entry, &instance);
            // SAFETY: messenger info is valid; the DebugState outlives the messenger (dropped after it).
            let messenger =
                match unsafe { loader.create_debug_utils_messenger(&messenger_info, None) } {
                    Ok(m) => m,
                    Err(result) => {
                        destroy_instance(&instance, None);
                        return Err(GpuError::Vk {
                            what: "create messenger",
                            result,
                        });
                    }
                };
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
        let surface = match window_surface(&entry, &instance, desc) {
            Ok(surface) => surface,
            Err(result) => {
                destroy_instance(&instance, debug);
                return Err(GpuError::Vk {
                    what: "create window surface",
                    result,
                });
            }
        };
        let created = (|| {
            let (physical, name, queue_family) =
                device::pick_physical(&instance, desc, surface.as_ref())?;
            let features = device::query_features(&instance, physical, &name)?;
            let device = device::create_logical(
                &instance,
                physical,
                queue_family,
                &features,
                surface.is_some(),
            )?;
            let allocator = match new_allocator(&instance, &device, physical) {
                Ok(a) => Arc::new(Mutex::new(a)),
                Err(e) => {
                    // SAFETY: nothing was created on the device yet.
                    unsafe { device.destroy_device(None) };
                    return Err(GpuError::Alloc {
                        name: "the allocator".into(),
                        size: 0,
                        error: e,
                    });
                }
            };
            let info = device::query_info(&instance, physical, name, &features);
            Ok((physical, queue_family, device, allocator, info))
        })();
        let (physical, queue_family, device, allocator, info) = match created {
            Ok(v) => v,
            Err(e) => {
                if let Some(s) = &surface {
                    // SAFETY: no swapchain was created from the surface.
                    unsafe { s.loader.destroy_surface(s.raw, None) };
                }
                destroy_instance(&instance, debug);
                return Err(e);
            }
        };
        // SAFETY: the queue family/index were requested at device creation.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        Ok(Self::assemble(Parts {
            entry,
            instance,
            debug,
            debug_state,
            physical,
            device,
            queue,
            queue_family,
            allocator,
            surface,
            owns_device: true,
            info,
        }))
    }

    /// A context on a host's device: it makes its own memory allocator and (with
    /// `validation`) its own messenger on the device and instance, and destroys only those
    /// when dropped; the host keeps the instance and device, and must keep them until then.
    /// Fails when the device lacks a feature the renderer requires.
    pub fn from_host(host: HostDevice) -> GpuResult<Self> {
        let HostDevice {
            entry,
            instance,
            physical,
            device,
            queue_family,
            queue,
            validation,
            allocator: shared,
        } = host;
        // SAFETY: valid physical device of the host's instance.
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let name = props
            .device_name_as_c_str()
            .map(|c| c.to_string_lossy().into_owned())
            .unwrap_or_default();
        let features = device::query_features(&instance, physical, &name)?;
        let debug_state = Arc::new(DebugState {
            errors: AtomicU32::new(0),
            messages: Mutex::new(Vec::new()),
        });
        let debug = if validation {
            let loader = debug_utils::Instance::new(&entry, &instance);
            let info = messenger_info(&debug_state);
            // SAFETY: messenger info is valid; the DebugState outlives the messenger.
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .ctx("create messenger on the host's instance")?;
            Some((loader, messenger))
        } else {
            None
        };
        let made = match shared {
            Some(a) => Ok(a),
            None => new_allocator(&instance, &device, physical).map(|a| Arc::new(Mutex::new(a))),
        };
        let allocator = match made {
            Ok(a) => a,
            Err(error) => {
                if let Some((loader, messenger)) = debug {
                    // SAFETY: the messenger was created above and is used by nothing.
                    unsafe { loader.destroy_debug_utils_messenger(messenger, None) };
                }
                return Err(GpuError::Alloc {
                    name: "the allocator".into(),
                    size: 0,
                    error,
                });
            }
        };
        let info = device::query_info(&instance, physical, name, &features);
        Ok(Self::assemble(Parts {
            entry,
            instance,
            debug,
            debug_state,
            physical,
            device,
            queue,
            queue_family,
            allocator,
            surface: None,
            owns_device: false,
            info,
        }))
    }

    /// The context of `p`, with the device-level function tables it needs.
    fn assemble(p: Parts) -> Self {
        let debug_device = p
            .debug
            .as_ref()
            .map(|_| debug_utils::Device::new(&p.instance, &p.device));
        let mesh_ext = p
            .info
            .mesh_shader
            .then(|| ash::ext::mesh_shader::Device::new(&p.instance, &p.device));
        let swapchain_ext = p
            .surface
            .as_ref()
            .map(|_| ash::khr::swapchain::Device::new(&p.instance, &p.device));
        Context {
            _entry: p.entry,
            instance: p.instance,
            debug: p.debug,
            debug_device,
            debug_state: p.debug_state,
            physical: p.physical,
            device: p.device,
            queue: p.queue,
            queue_family: p.queue_family,
            allocator: ManuallyDrop::new(p.allocator),
            mesh_ext,
            surface: p.surface,
            swapchain_ext,
            owns_device: p.owns_device,
            info: p.info,
        }
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
        let allocation = self
            .allocator()
            .allocate(&gpu_allocator::vulkan::AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: gpu_allocator::vulkan::AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|error| GpuError::Alloc {
                name: name.to_string(),
                size: requirements.size,
                error,
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

    pub(crate) fn queue(&self) -> vk::Queue {
        self.queue
    }

    pub(crate) fn physical(&self) -> vk::PhysicalDevice {
        self.physical
    }

    #[cfg(feature = "window")]
    pub(crate) fn instance(&self) -> &ash::Instance {
        &self.instance
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
/// What a context is made of, before its device-level function tables.
struct Parts {
    entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    debug_state: Arc<DebugState>,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    queue: vk::Queue,
    queue_family: u32,
    allocator: Arc<Mutex<Allocator>>,
    surface: Option<Surface>,
    owns_device: bool,
    info: DeviceInfo,
}

/// A memory allocator on `device` (buffer device addresses on).
fn new_allocator(
    instance: &ash::Instance,
    device: &ash::Device,
    physical: vk::PhysicalDevice,
) -> Result<Allocator, gpu_allocator::AllocationError> {
    Allocator::new(&AllocatorCreateDesc {
        instance: instance.clone(),
        device: device.clone(),
        physical_device: physical,
        debug_settings: Default::default(),
        buffer_device_address: true,
        allocation_sizes: Default::default(),
    })
}

/// The messenger that counts errors into `state` and prints errors and warnings.
fn messenger_info(state: &Arc<DebugState>) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
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
        .user_data(Arc::as_ptr(state) as *mut c_void)
}

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
        // A host's instance and device stay: only what the context made on them goes.
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            if self.owns_device {
                self.device.destroy_device(None);
            }
            if let Some(s) = self.surface.take() {
                s.loader.destroy_surface(s.raw, None);
            }
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            if self.owns_device {
                self.instance.destroy_instance(None);
            }
        }
    }
}
