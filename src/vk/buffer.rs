//! Buffers with gpu-allocator memory.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::Allocation;

use super::{Context, GpuError, GpuResult, VkContext};

/// How to create a [`Buffer`].
#[derive(Clone, Debug)]
pub struct BufferDesc {
    /// Debug name.
    pub name: String,
    /// Size in bytes (> 0).
    pub size: u64,
    /// Usage flags.
    pub usage: vk::BufferUsageFlags,
    /// Memory location.
    pub location: MemoryLocation,
}

impl BufferDesc {
    /// A device-local buffer.
    pub fn new(name: &str, size: u64, usage: vk::BufferUsageFlags) -> Self {
        BufferDesc {
            name: name.into(),
            size: size.max(16),
            usage,
            location: MemoryLocation::GpuOnly,
        }
    }

    /// Host-visible memory the CPU writes (uploads, uniforms).
    pub fn host_visible(mut self) -> Self {
        self.location = MemoryLocation::CpuToGpu;
        self
    }

    /// Host-visible memory the CPU reads back.
    pub fn readback(mut self) -> Self {
        self.location = MemoryLocation::GpuToCpu;
        self
    }
}

/// A buffer and its memory; freed on drop.
pub struct Buffer {
    ctx: Arc<Context>,
    raw: vk::Buffer,
    allocation: Option<Allocation>,
    /// Size in bytes.
    pub size: u64,
}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Buffer({} bytes)", self.size)
    }
}

impl Buffer {
    /// Create a buffer as described.
    pub fn new(ctx: &Arc<Context>, desc: &BufferDesc) -> GpuResult<Self> {
        let info = vk::BufferCreateInfo::default()
            .size(desc.size)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_buffer(&info, None) }.ctx("create buffer")?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let allocation = ctx.allocate_bound(
            &desc.name,
            requirements,
            desc.location,
            true,
            |memory, offset| {
                // SAFETY: memory from the allocator matches the requirements of `raw`.
                unsafe { ctx.device.bind_buffer_memory(raw, memory, offset) }
            },
        );
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: unbound buffer, not in use.
                unsafe { ctx.device.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        ctx.name_object(raw, &desc.name);
        Ok(Buffer {
            ctx: ctx.clone(),
            raw,
            allocation: Some(allocation),
            size: desc.size,
        })
    }

    /// Create a host-visible buffer holding `data`.
    pub fn with_data(
        ctx: &Arc<Context>,
        name: &str,
        usage: vk::BufferUsageFlags,
        data: &[u8],
    ) -> GpuResult<Self> {
        let mut b = Buffer::new(
            ctx,
            &BufferDesc::new(name, data.len() as u64, usage).host_visible(),
        )?;
        b.write(0, data)?;
        Ok(b)
    }

    /// Create a device-local buffer holding `data` (uploaded through a staging buffer; blocks
    /// until the copy completed). `usage` gets `TRANSFER_DST` added.
    pub fn device_local_with_data(
        ctx: &Arc<Context>,
        name: &str,
        usage: vk::BufferUsageFlags,
        data: &[u8],
    ) -> GpuResult<Self> {
        let buffer = Buffer::new(
            ctx,
            &BufferDesc::new(
                name,
                data.len() as u64,
                usage | vk::BufferUsageFlags::TRANSFER_DST,
            ),
        )?;
        let staging = Buffer::with_data(ctx, "staging", vk::BufferUsageFlags::TRANSFER_SRC, data)?;
        ctx.submit_and_wait(|rec| {
            rec.copy_buffer(&staging, 0, &buffer, 0, data.len() as u64);
        })?;
        Ok(buffer)
    }

    fn mapped(&mut self) -> GpuResult<&mut [u8]> {
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| GpuError::Unsupported("buffer is not host visible".into()))
    }

    /// Write `data` at byte `offset` of a host-visible buffer.
    pub fn write(&mut self, offset: usize, data: &[u8]) -> GpuResult<()> {
        let m = self.mapped()?;
        let end = offset
            .checked_add(data.len())
            .filter(|&e| e <= m.len())
            .ok_or_else(|| GpuError::Unsupported("buffer write out of range".into()))?;
        m[offset..end].copy_from_slice(data);
        Ok(())
    }

    pub(crate) fn raw(&self) -> vk::Buffer {
        self.raw
    }

    /// The buffer's device address, as the `uvec2` a shader's `buffer_reference` takes (low
    /// word, high word); the buffer needs `SHADER_DEVICE_ADDRESS` usage.
    pub fn device_address(&self) -> [u32; 2] {
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.raw);
        // SAFETY: valid buffer of this device; the device has bufferDeviceAddress enabled.
        let address = unsafe { self.ctx.device.get_buffer_device_address(&info) };
        [address as u32, (address >> 32) as u32]
    }

    /// Read the contents of a host-visible buffer.
    pub fn read(&mut self) -> GpuResult<Vec<u8>> {
        self.read_range(0, self.size as usize)
    }

    /// Read `len` bytes at `offset` of a host-visible buffer.
    pub fn read_range(&mut self, offset: usize, len: usize) -> GpuResult<Vec<u8>> {
        let m = self.mapped()?;
        let end = offset
            .checked_add(len)
            .filter(|&e| e <= m.len())
            .ok_or_else(|| GpuError::Unsupported("buffer read out of range".into()))?;
        Ok(m[offset..end].to_vec())
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: callers wait for the GPU before dropping resources it uses.
        unsafe { self.ctx.device.destroy_buffer(self.raw, None) };
        if let Some(a) = self.allocation.take() {
            let _ = self.ctx.allocator().free(a);
        }
    }
}
