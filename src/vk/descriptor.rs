//! Descriptor set layouts described by [`BindingDesc`] lists, and descriptor sets (each with its
//! own small pool) written one binding at a time. Bindless arrays (descriptor indexing) are
//! partially bound and updatable while unused slots' command buffers are pending.

use std::sync::Arc;

use ash::vk;

use super::buffer::Buffer;
use super::image::{Image, Sampler};
use super::{Context, GpuError, GpuResult, VkContext};

/// What a binding holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DescriptorKind {
    /// Uniform buffer.
    UniformBuffer,
    /// Storage buffer.
    StorageBuffer,
    /// Combined image + sampler.
    SampledImage,
}

impl DescriptorKind {
    fn raw(self) -> vk::DescriptorType {
        match self {
            DescriptorKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            DescriptorKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            DescriptorKind::SampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    }
}

/// One binding of a set layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BindingDesc {
    /// Binding number (as in the shaders' `layout(binding = ...)`).
    pub binding: u32,
    /// Descriptor kind.
    pub kind: DescriptorKind,
    /// Array length (1 for a single resource).
    pub count: u32,
    /// A bindless array: partially bound, written while other slots are in use.
    pub bindless: bool,
}

impl BindingDesc {
    /// A single resource at `binding`.
    pub const fn single(binding: u32, kind: DescriptorKind) -> Self {
        BindingDesc {
            binding,
            kind,
            count: 1,
            bindless: false,
        }
    }

    /// A bindless array of `count` resources at `binding`.
    pub const fn bindless(binding: u32, kind: DescriptorKind, count: u32) -> Self {
        BindingDesc {
            binding,
            kind,
            count,
            bindless: true,
        }
    }
}

/// A descriptor set layout.
pub struct DescriptorSetLayout {
    ctx: Arc<Context>,
    raw: vk::DescriptorSetLayout,
    bindings: Vec<BindingDesc>,
}

impl DescriptorSetLayout {
    /// Create a layout with `bindings`, visible to all stages.
    pub fn new(ctx: &Arc<Context>, bindings: &[BindingDesc]) -> GpuResult<Arc<Self>> {
        let raw_bindings: Vec<_> = bindings
            .iter()
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(b.kind.raw())
                    .descriptor_count(b.count)
                    .stage_flags(vk::ShaderStageFlags::ALL)
            })
            .collect();
        let flags: Vec<_> = bindings
            .iter()
            .map(|b| {
                if b.bindless {
                    vk::DescriptorBindingFlags::PARTIALLY_BOUND
                        | vk::DescriptorBindingFlags::UPDATE_AFTER_BIND
                        | vk::DescriptorBindingFlags::UPDATE_UNUSED_WHILE_PENDING
                } else {
                    vk::DescriptorBindingFlags::empty()
                }
            })
            .collect();
        let mut flag_info =
            vk::DescriptorSetLayoutBindingFlagsCreateInfo::default().binding_flags(&flags);
        let mut info = vk::DescriptorSetLayoutCreateInfo::default()
            .bindings(&raw_bindings)
            .push_next(&mut flag_info);
        if bindings.iter().any(|b| b.bindless) {
            info = info.flags(vk::DescriptorSetLayoutCreateFlags::UPDATE_AFTER_BIND_POOL);
        }
        // SAFETY: valid create info; the device enabled the descriptor indexing features that
        // bindless bindings need (checked at device creation).
        let raw = unsafe { ctx.device.create_descriptor_set_layout(&info, None) }
            .ctx("descriptor set layout")?;
        Ok(Arc::new(DescriptorSetLayout {
            ctx: ctx.clone(),
            raw,
            bindings: bindings.to_vec(),
        }))
    }

    pub(crate) fn raw(&self) -> vk::DescriptorSetLayout {
        self.raw
    }

    fn binding(&self, binding: u32) -> GpuResult<&BindingDesc> {
        self.bindings
            .iter()
            .find(|b| b.binding == binding)
            .ok_or_else(|| GpuError::Unsupported(format!("no descriptor binding {binding}")))
    }
}

impl Drop for DescriptorSetLayout {
    fn drop(&mut self) {
        // SAFETY: sets and pipelines using the layout hold an Arc to it, so none is alive.
        unsafe {
            self.ctx
                .device
                .destroy_descriptor_set_layout(self.raw, None)
        };
    }
}

/// A descriptor set allocated from its own pool.
pub struct DescriptorSet {
    ctx: Arc<Context>,
    layout: Arc<DescriptorSetLayout>,
    pool: vk::DescriptorPool,
    raw: vk::DescriptorSet,
}

impl DescriptorSet {
    /// Allocate a set of `layout`.
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        layout: &Arc<DescriptorSetLayout>,
    ) -> GpuResult<Self> {
        let sizes: Vec<_> = layout
            .bindings
            .iter()
            .map(|b| vk::DescriptorPoolSize {
                ty: b.kind.raw(),
                descriptor_count: b.count,
            })
            .collect();
        let mut pool_info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(1)
            .pool_sizes(&sizes);
        if layout.bindings.iter().any(|b| b.bindless) {
            pool_info = pool_info.flags(vk::DescriptorPoolCreateFlags::UPDATE_AFTER_BIND);
        }
        // SAFETY: valid create info.
        let pool = unsafe { ctx.device.create_descriptor_pool(&pool_info, None) }
            .ctx("descriptor pool")?;
        let layouts = [layout.raw];
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(pool)
            .set_layouts(&layouts);
        // SAFETY: the pool has room for exactly this set.
        let raw = match unsafe { ctx.device.allocate_descriptor_sets(&alloc) } {
            Ok(v) => v[0],
            Err(result) => {
                // SAFETY: nothing was allocated from the pool.
                unsafe { ctx.device.destroy_descriptor_pool(pool, None) };
                return Err(GpuError::Vk {
                    what: "allocate descriptor set",
                    result,
                });
            }
        };
        ctx.name_object(raw, name);
        Ok(DescriptorSet {
            ctx: ctx.clone(),
            layout: layout.clone(),
            pool,
            raw,
        })
    }

    pub(crate) fn raw(&self) -> vk::DescriptorSet {
        self.raw
    }

    /// Point buffer binding `binding` at all of `buffer`. Not while a pending command buffer
    /// uses this set (frames write their own set after their fence).
    pub fn write_buffer(&self, binding: u32, buffer: &Buffer) -> GpuResult<()> {
        let b = self.layout.binding(binding)?;
        if b.kind == DescriptorKind::SampledImage {
            return Err(GpuError::Unsupported(format!(
                "binding {binding} holds images, not buffers"
            )));
        }
        let info = [vk::DescriptorBufferInfo {
            buffer: buffer.raw(),
            offset: 0,
            range: vk::WHOLE_SIZE,
        }];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.raw)
            .dst_binding(binding)
            .descriptor_type(b.kind.raw())
            .buffer_info(&info);
        // SAFETY: the buffer is alive; the caller keeps it alive while the set is used.
        unsafe { self.ctx.device.update_descriptor_sets(&[write], &[]) };
        Ok(())
    }

    /// Write element `index` of image binding `binding` (image in `SHADER_READ_ONLY_OPTIMAL`).
    /// For bindless arrays, `index` must not be used by a pending command buffer.
    pub fn write_image(
        &self,
        binding: u32,
        index: u32,
        image: &Image,
        sampler: &Sampler,
    ) -> GpuResult<()> {
        let b = self.layout.binding(binding)?;
        if b.kind != DescriptorKind::SampledImage || index >= b.count {
            return Err(GpuError::Unsupported(format!(
                "binding {binding}: no image element {index}"
            )));
        }
        let info = [vk::DescriptorImageInfo {
            sampler: sampler.raw(),
            image_view: image.view(),
            image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        }];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.raw)
            .dst_binding(binding)
            .dst_array_element(index)
            .descriptor_type(b.kind.raw())
            .image_info(&info);
        // SAFETY: image and sampler are alive; the caller keeps them while the slot is used.
        unsafe { self.ctx.device.update_descriptor_sets(&[write], &[]) };
        Ok(())
    }
}

impl Drop for DescriptorSet {
    fn drop(&mut self) {
        // SAFETY: owners drop sets only after the frames using them retired.
        unsafe { self.ctx.device.destroy_descriptor_pool(self.pool, None) };
    }
}
