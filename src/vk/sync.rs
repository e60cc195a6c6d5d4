//! Fences (CPU waits for GPU work) and semaphores (GPU waits for GPU work, e.g. a swapchain
//! image).

use std::sync::Arc;

use ash::vk;

use super::{Context, GpuResult, VkContext};

/// A fence, optionally created signalled (a frame slot that has never been submitted).
pub struct Fence {
    ctx: Arc<Context>,
    raw: vk::Fence,
}

impl Fence {
    /// Create a fence.
    pub fn new(ctx: &Arc<Context>, signaled: bool) -> GpuResult<Self> {
        let flags = if signaled {
            vk::FenceCreateFlags::SIGNALED
        } else {
            vk::FenceCreateFlags::empty()
        };
        // SAFETY: valid device and create info.
        let raw = unsafe {
            ctx.device
                .create_fence(&vk::FenceCreateInfo::default().flags(flags), None)
        }
        .ctx("create fence")?;
        Ok(Fence {
            ctx: ctx.clone(),
            raw,
        })
    }

    /// Block until signalled.
    pub fn wait(&self) -> GpuResult<()> {
        // SAFETY: valid fence of this device.
        unsafe { self.ctx.device.wait_for_fences(&[self.raw], true, u64::MAX) }
            .ctx("wait for fence")
    }

    /// Return to the unsignalled state (not while a submission uses it).
    pub fn reset(&self) -> GpuResult<()> {
        // SAFETY: the caller waited for the fence first.
        unsafe { self.ctx.device.reset_fences(&[self.raw]) }.ctx("reset fence")
    }

    pub(crate) fn raw(&self) -> vk::Fence {
        self.raw
    }
}

impl Drop for Fence {
    fn drop(&mut self) {
        // SAFETY: owners wait for (or never submitted) the work this fence tracks.
        unsafe { self.ctx.device.destroy_fence(self.raw, None) };
    }
}

/// A binary semaphore.
pub struct Semaphore {
    ctx: Arc<Context>,
    raw: vk::Semaphore,
}

impl Semaphore {
    /// Create a semaphore.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        // SAFETY: valid device and create info.
        let raw = unsafe {
            ctx.device
                .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
        }
        .ctx("create semaphore")?;
        Ok(Semaphore {
            ctx: ctx.clone(),
            raw,
        })
    }

    pub(crate) fn raw(&self) -> vk::Semaphore {
        self.raw
    }
}

impl Drop for Semaphore {
    fn drop(&mut self) {
        // SAFETY: owners drop semaphores after the work using them completed.
        unsafe { self.ctx.device.destroy_semaphore(self.raw, None) };
    }
}
