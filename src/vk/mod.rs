//! Thin Vulkan layer: one file per object kind, every `unsafe` ash call behind a small safe
//! function. Objects are described by small `*Desc` values.

pub mod access;
pub mod buffer;
pub mod command;
pub mod context;
pub mod descriptor;
mod device;
pub mod image;
pub mod pipeline;
pub mod profiler;
mod queue;
pub mod shader;
pub mod swapchain;
pub mod sync;
#[cfg(feature = "window")]
pub mod ui;
#[cfg(feature = "wgpu")]
pub mod wgpu_host;

pub use access::Access;
pub use buffer::{Buffer, BufferDesc};
pub use command::{Attachment, BarrierImage, CommandBuffer, CommandRecorder, ImageBarrier};
pub use context::{Context, HostDevice, MemoryReport};
pub use descriptor::{BindingDesc, DescriptorKind, DescriptorSet, DescriptorSetLayout};
#[cfg(feature = "window")]
pub use device::WindowHandles;
pub use device::create_host_device;
pub use device::{ContextDesc, DeviceInfo};
pub use image::{Image, ImageDesc, Sampler};
pub use pipeline::{BlendMode, CullMode, DepthMode, GraphicsDesc, Pipeline, PipelineLayout};
pub use profiler::{FrameTimes, MeshPrimitivesQuery, Profiler};
pub use swapchain::{Acquired, PresentMode, Swapchain, SwapchainImage};
pub use sync::{Fence, Semaphore};
#[cfg(feature = "window")]
pub use ui::UiRenderer;
#[cfg(feature = "wgpu")]
pub use wgpu_host::{WgpuDesc, WgpuDevice};

/// Errors of the GPU layer.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// A Vulkan call failed.
    #[error("Vulkan: {what}: {result}")]
    Vk {
        /// What was being done.
        what: &'static str,
        /// The result code.
        result: ash::vk::Result,
    },
    /// The Vulkan loader could not be opened.
    #[error("Vulkan loader not found: {0} (run tools/setup.sh)")]
    Loader(String),
    /// No usable device or a missing feature.
    #[error("{0}")]
    Unsupported(String),
    /// Memory allocation failed; names the resource and its size.
    #[error("GPU memory for {name} ({size} bytes): {error}")]
    Alloc {
        /// The resource being allocated.
        name: String,
        /// Bytes asked for.
        size: u64,
        /// What the allocator said.
        error: gpu_allocator::AllocationError,
    },
    /// A shader failed to compile; the message names file and line.
    #[error("shader {0}")]
    Shader(String),
}

/// `vk::SampleCountFlags` for a sample count (1, 2, 4, 8, 16...; others give 1).
pub(crate) fn sample_flags(samples: u32) -> ash::vk::SampleCountFlags {
    match samples {
        2 => ash::vk::SampleCountFlags::TYPE_2,
        4 => ash::vk::SampleCountFlags::TYPE_4,
        8 => ash::vk::SampleCountFlags::TYPE_8,
        16 => ash::vk::SampleCountFlags::TYPE_16,
        _ => ash::vk::SampleCountFlags::TYPE_1,
    }
}

/// Result alias of the GPU layer.
pub type GpuResult<T> = std::result::Result<T, GpuError>;

/// Attach context to a raw `vk::Result`.
pub(crate) trait VkContext<T> {
    fn ctx(self, what: &'static str) -> GpuResult<T>;
}

impl<T> VkContext<T> for Result<T, ash::vk::Result> {
    fn ctx(self, what: &'static str) -> GpuResult<T> {
        self.map_err(|result| GpuError::Vk { what, result })
    }
}
