//! Resource uses and the barriers between them: one small table of (pipeline stage, access,
//! image layout) per use, in the spirit of vk-sync.

use ash::vk;

/// How a resource is used by a command; barriers are written between two uses. One small
/// table (stage, access, image layout) in the spirit of vk-sync, for the uses this project has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// No previous use (contents may be discarded).
    Nothing,
    /// Read as indirect dispatch/draw arguments.
    IndirectRead,
    /// Storage/uniform read in compute shaders (written by an earlier use).
    ComputeRead,
    /// Storage read/write in compute shaders.
    ComputeReadWrite,
    /// Storage read in vertex shaders.
    VertexRead,
    /// Storage read in task shaders.
    TaskRead,
    /// Storage read/write in task shaders.
    TaskReadWrite,
    /// Storage read in mesh shaders.
    MeshRead,
    /// Storage read/write in mesh shaders (the software rasterizer's segments).
    MeshReadWrite,
    /// Storage/uniform read in fragment shaders.
    FragmentRead,
    /// Storage read/write (and atomics) in fragment shaders.
    FragmentReadWrite,
    /// Sampled by any shader stage (image in `SHADER_READ_ONLY_OPTIMAL`).
    SampledRead,
    /// Written as a colour attachment.
    ColorAttachment,
    /// Read and written as a depth attachment.
    DepthAttachment,
    /// Source of a transfer.
    TransferRead,
    /// Destination of a transfer (copy, fill).
    TransferWrite,
    /// Read by the host after the submission completed.
    HostRead,
    /// Handed to the presentation engine (swapchain images).
    Present,
}

pub(crate) struct AccessInfo {
    stage: vk::PipelineStageFlags2,
    access: vk::AccessFlags2,
    pub(crate) layout: vk::ImageLayout,
    writes: bool,
}

impl Access {
    pub(crate) fn info(self) -> AccessInfo {
        use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
        // Shader stages read storage and uniform buffers, or read and write storage.
        let read = |s| {
            (
                s,
                A::SHADER_STORAGE_READ | A::UNIFORM_READ,
                L::UNDEFINED,
                false,
            )
        };
        let read_write = |s| {
            let access = A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE;
            (s, access, L::GENERAL, true)
        };
        let (stage, access, layout, writes) = match self {
            Access::Nothing => (S::NONE, A::NONE, L::UNDEFINED, false),
            Access::IndirectRead => (
                S::DRAW_INDIRECT,
                A::INDIRECT_COMMAND_READ,
                L::UNDEFINED,
                false,
            ),
            // Compute reads storage images too, in the general layout.
            Access::ComputeRead => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ | A::UNIFORM_READ,
                L::GENERAL,
                false,
            ),
            Access::TaskRead => read(S::TASK_SHADER_EXT),
            Access::VertexRead => read(S::VERTEX_SHADER),
            Access::MeshRead => read(S::MESH_SHADER_EXT),
            Access::FragmentRead => read(S::FRAGMENT_SHADER),
            Access::ComputeReadWrite => read_write(S::COMPUTE_SHADER),
            Access::TaskReadWrite => read_write(S::TASK_SHADER_EXT),
            Access::MeshReadWrite => read_write(S::MESH_SHADER_EXT),
            Access::FragmentReadWrite => read_write(S::FRAGMENT_SHADER),
            Access::SampledRead => (
                S::ALL_COMMANDS,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                false,
            ),
            Access::ColorAttachment => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
                true,
            ),
            Access::DepthAttachment => (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
                L::DEPTH_ATTACHMENT_OPTIMAL,
                true,
            ),
            Access::TransferRead => (
                S::TRANSFER,
                A::TRANSFER_READ,
                L::TRANSFER_SRC_OPTIMAL,
                false,
            ),
            Access::TransferWrite => (
                S::TRANSFER,
                A::TRANSFER_WRITE,
                L::TRANSFER_DST_OPTIMAL,
                true,
            ),
            Access::HostRead => (S::HOST, A::HOST_READ, L::GENERAL, false),
            Access::Present => (S::NONE, A::NONE, L::PRESENT_SRC_KHR, false),
        };
        AccessInfo {
            stage,
            access,
            layout,
            writes,
        }
    }
}

impl Access {
    /// Every use, in declaration order (for tables and conservative first uses).
    pub const ALL: [Access; 18] = [
        Access::Nothing,
        Access::IndirectRead,
        Access::ComputeRead,
        Access::ComputeReadWrite,
        Access::VertexRead,
        Access::TaskRead,
        Access::TaskReadWrite,
        Access::MeshRead,
        Access::MeshReadWrite,
        Access::FragmentRead,
        Access::FragmentReadWrite,
        Access::SampledRead,
        Access::ColorAttachment,
        Access::DepthAttachment,
        Access::TransferRead,
        Access::TransferWrite,
        Access::HostRead,
        Access::Present,
    ];

    /// Whether this use writes (so later uses must wait for it and see its writes).
    pub fn writes(self) -> bool {
        self.info().writes
    }

    /// The image layout this use needs (`UNDEFINED`: any, buffers only).
    pub fn layout(self) -> vk::ImageLayout {
        self.info().layout
    }

    /// Whether this use runs in a task or mesh shader.
    pub fn is_mesh_stage(self) -> bool {
        matches!(
            self,
            Access::TaskRead | Access::TaskReadWrite | Access::MeshRead | Access::MeshReadWrite
        )
    }
}

/// Source and destination masks of a barrier from `prev` uses to `next` uses. Only writes are
/// made available; a read-after-read needs just the execution dependency.
pub(crate) fn masks(
    prev: &[Access],
    next: &[Access],
) -> (
    vk::PipelineStageFlags2,
    vk::AccessFlags2,
    vk::PipelineStageFlags2,
    vk::AccessFlags2,
) {
    let mut src = (vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE);
    for a in prev {
        let i = a.info();
        src.0 |= i.stage;
        if i.writes {
            src.1 |= i.access
                & (vk::AccessFlags2::SHADER_STORAGE_WRITE
                    | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
                    | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE
                    | vk::AccessFlags2::TRANSFER_WRITE);
        }
    }
    let mut dst = (vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE);
    for a in next {
        let i = a.info();
        dst.0 |= i.stage;
        dst.1 |= i.access;
    }
    (src.0, src.1, dst.0, dst.1)
}
