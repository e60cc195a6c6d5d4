//! Transient resources: buffers and images a frame graph creates from their descriptions
//! ([`super::FrameGraph::create_buffer`], [`super::FrameGraph::create_image`]). Their contents
//! do not outlive the frame, but the objects do: the pool keeps each one by name and hands
//! it to the next frame that asks for it, growing it (by half again, so a crowd that grows a
//! character at a time does not reallocate every frame), recreating an image whose
//! description changed, and shrinking a buffer that has needed under a quarter of its size
//! for [`SHRINK_AFTER_FRAMES`] frames. Replaced objects are handed back with
//! [`TransientPool::take_released`] for the frame's deferred release (frames in flight may
//! still use them). A pooled buffer remembers the uses the last frame made of it, so the next
//! frame's first use waits for those alone (an imported buffer's first use waits for any).

use std::any::Any;
use std::sync::Arc;

use ash::vk;

use crate::vk::{
    Access, Buffer, BufferDesc, Context, DescriptorSet, GpuError, GpuResult, Image, ImageDesc,
};

/// Frames a buffer may stay four times larger than it needs before it is shrunk.
pub const SHRINK_AFTER_FRAMES: u32 = 240;

/// Smallest transient buffer (bindings need a buffer even when a frame uses none of it).
const MIN_BYTES: u64 = 16;

/// What a transient buffer is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TransientBuffer {
    /// Name (the pool's key, the graph's and the debugger's label).
    pub name: &'static str,
    /// Bytes this frame needs (0: none; the buffer still exists for its binding).
    pub bytes: u64,
    /// Usage flags.
    pub usage: vk::BufferUsageFlags,
    /// The binding of set 0 it is written to, when shaders read it there.
    pub binding: Option<u32>,
    /// What it holds in a user's words, and what a user changes to make it smaller (the
    /// feature that sizes it says so; the pool's refusal quotes it).
    pub user_terms: UserTerms,
}

/// A transient buffer in a user's words: what it holds and the flags that size it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UserTerms {
    /// What the buffer holds, e.g. "per-pixel fragment lists".
    pub what: &'static str,
    /// What to change, e.g. "lower --size".
    pub remedy: &'static str,
}

impl UserTerms {
    /// Storage of a frame that only its size sets.
    pub const FRAME_STORAGE: UserTerms = UserTerms {
        what: "frame storage",
        remedy: "lower --size",
    };
}

impl TransientBuffer {
    /// A storage buffer of `bytes`, bound at `binding` of set 0, that transfers may fill
    /// and copy.
    pub fn storage(name: &'static str, bytes: u64, binding: u32) -> Self {
        TransientBuffer {
            name,
            bytes,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            binding: Some(binding),
            user_terms: UserTerms::FRAME_STORAGE,
        }
    }

    /// The same buffer, described to a user as `what`, made smaller by `remedy`.
    pub fn for_user(mut self, what: &'static str, remedy: &'static str) -> Self {
        self.user_terms = UserTerms { what, remedy };
        self
    }
}

/// What became of a transient this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Realized {
    /// Made for the first time.
    New,
    /// An earlier frame's object, reused.
    Reused,
    /// Replaced by a larger one (it was this many bytes).
    Grown(u64),
    /// Replaced by a smaller one after long disuse of its size (it was this many bytes).
    Shrunk(u64),
    /// An image recreated because its description changed.
    Recreated,
}

struct PooledBuffer {
    desc: TransientBuffer,
    buffer: Buffer,
    /// Consecutive frames it needed under a quarter of its size.
    oversized_frames: u32,
    /// The uses (bits of [`Access`]) the last frame that used it made since its last
    /// write: what the next frame's first use waits for. 0 for a new buffer.
    last_uses: u32,
}

struct PooledImage {
    desc: ImageDesc,
    image: Image,
    /// Its last use (layout), kept across frames.
    last: Access,
}

/// The transient buffers and images of a renderer's frames; see the module documentation.
pub struct TransientPool {
    ctx: Arc<Context>,
    buffers: Vec<PooledBuffer>,
    images: Vec<PooledImage>,
    released: Vec<Box<dyn Any + Send>>,
}

fn same_image(a: &ImageDesc, b: &ImageDesc) -> bool {
    (a.extent, a.format, a.usage, a.dim_3d, a.samples)
        == (b.extent, b.format, b.usage, b.dim_3d, b.samples)
}

impl TransientPool {
    /// An empty pool.
    pub fn new(ctx: &Arc<Context>) -> Self {
        TransientPool {
            ctx: ctx.clone(),
            buffers: Vec::new(),
            images: Vec::new(),
            released: Vec::new(),
        }
    }

    /// Refuse a description no device buffer can hold, before anything is allocated.
    pub fn check(&self, desc: &TransientBuffer) -> GpuResult<()> {
        let limit = self.ctx.info.max_storage_buffer_range;
        if desc.usage.contains(vk::BufferUsageFlags::STORAGE_BUFFER) && desc.bytes > limit {
            let UserTerms { what, remedy } = desc.user_terms;
            return Err(GpuError::Unsupported(format!(
                "this frame's {what} ({}) needs {} bytes, more than the {limit} this device's largest storage buffer holds; {remedy}",
                desc.name, desc.bytes
            )));
        }
        Ok(())
    }

    /// The buffer for `desc` (index into the pool), made, reused, grown or shrunk.
    pub(super) fn buffer(&mut self, desc: &TransientBuffer) -> GpuResult<(usize, Realized)> {
        self.check(desc)?;
        let need = desc.bytes.max(MIN_BYTES);
        let Some(i) = self.buffers.iter().position(|b| b.desc.name == desc.name) else {
            let buffer = self.make_buffer(desc, need)?;
            self.buffers.push(PooledBuffer {
                desc: *desc,
                buffer,
                oversized_frames: 0,
                last_uses: 0,
            });
            return Ok((self.buffers.len() - 1, Realized::New));
        };
        let pooled = &mut self.buffers[i];
        let size = pooled.buffer.size;
        pooled.oversized_frames = match need * 4 <= size {
            true => pooled.oversized_frames + 1,
            false => 0,
        };
        let usage_changed = pooled.desc.usage != desc.usage;
        let (bytes, realized) = if need > size || usage_changed {
            let limit = match desc.usage.contains(vk::BufferUsageFlags::STORAGE_BUFFER) {
                true => self.ctx.info.max_storage_buffer_range,
                false => u64::MAX,
            };
            (
                (size + size / 2).min(limit).max(need),
                Realized::Grown(size),
            )
        } else if pooled.oversized_frames >= SHRINK_AFTER_FRAMES {
            (need, Realized::Shrunk(size))
        } else {
            pooled.desc = *desc;
            return Ok((i, Realized::Reused));
        };
        let buffer = self.make_buffer(desc, bytes)?;
        let pooled = &mut self.buffers[i];
        let old = std::mem::replace(&mut pooled.buffer, buffer);
        (pooled.desc, pooled.oversized_frames, pooled.last_uses) = (*desc, 0, 0);
        self.released.push(Box::new(old));
        Ok((i, realized))
    }

    fn make_buffer(&self, desc: &TransientBuffer, bytes: u64) -> GpuResult<Buffer> {
        Buffer::new(&self.ctx, &BufferDesc::new(desc.name, bytes, desc.usage))
    }

    /// The image for `desc` (index into the pool) and its last use, made, reused or
    /// recreated.
    pub(super) fn image(&mut self, desc: &ImageDesc) -> GpuResult<(usize, Realized)> {
        let found = self.images.iter().position(|p| p.desc.name == desc.name);
        if let Some(i) = found.filter(|&i| same_image(&self.images[i].desc, desc)) {
            return Ok((i, Realized::Reused));
        }
        let pooled = PooledImage {
            desc: desc.clone(),
            image: Image::new(&self.ctx, desc)?,
            last: Access::Nothing,
        };
        Ok(match found {
            Some(i) => {
                let old = std::mem::replace(&mut self.images[i], pooled);
                self.released.push(Box::new(old.image));
                (i, Realized::Recreated)
            }
            None => {
                self.images.push(pooled);
                (self.images.len() - 1, Realized::New)
            }
        })
    }

    pub(super) fn buffer_at(&self, i: usize) -> &Buffer {
        &self.buffers[i].buffer
    }

    pub(super) fn buffer_last_uses(&self, i: usize) -> u32 {
        self.buffers[i].last_uses
    }

    pub(super) fn set_buffer_last_uses(&mut self, i: usize, uses: u32) {
        self.buffers[i].last_uses = uses;
    }

    pub(super) fn image_at(&self, i: usize) -> (&Image, Access) {
        (&self.images[i].image, self.images[i].last)
    }

    pub(super) fn set_image_last(&mut self, i: usize, last: Access) {
        self.images[i].last = last;
    }

    /// Write every pooled buffer that has a binding into `set` (buffers an earlier frame
    /// made stay bound, so no binding ever names a released buffer).
    pub fn write_bindings(&self, set: &DescriptorSet) -> GpuResult<()> {
        for b in &self.buffers {
            if let Some(binding) = b.desc.binding {
                set.write_buffer(binding, &b.buffer)?;
            }
        }
        Ok(())
    }

    /// The objects replaced since the last call, for the current frame's deferred release.
    pub fn take_released(&mut self) -> Vec<Box<dyn Any + Send>> {
        std::mem::take(&mut self.released)
    }

    /// Bytes held by the pool's buffers and images.
    pub fn bytes(&self) -> u64 {
        let b: u64 = self.buffers.iter().map(|b| b.buffer.size).sum();
        let i: u64 = self.images.iter().map(|i| i.image.byte_size()).sum();
        b + i
    }
}
