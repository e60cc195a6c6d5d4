//! Descriptor set layouts and sets (one pool per set; sets here are few and long-lived).

use std::sync::Arc;

use ash::vk;

use super::{Context, GpuResult, VkContext};

/// A descriptor set layout plus one set allocated from its own pool.
pub struct DescriptorSet {
    ctx: Arc<Context>,
    /// The layout.
    pub layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    /// The set.
    pub set: vk::DescriptorSet,
}

/// A resource to bind.
pub enum Binding<'a> {
    /// Uniform buffer.
    Uniform(&'a super::Buffer),
    /// Storage buffer.
    Storage(&'a super::Buffer),
    /// Sampled image with a sampler (image in SHADER_READ_ONLY_OPTIMAL).
    Texture(&'a super::Image, vk::Sampler),
}

impl Binding<'_> {
    fn ty(&self) -> vk::DescriptorType {
        match self {
            Binding::Uniform(_) => vk::DescriptorType::UNIFORM_BUFFER,
            Binding::Storage(_) => vk::DescriptorType::STORAGE_BUFFER,
            Binding::Texture(..) => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    }
}

impl DescriptorSet {
    /// Create a layout and set for `bindings` (binding `i` = element `i`), visible to all stages.
    pub fn new(ctx: &Arc<Context>, name: &str, bindings: &[Binding]) -> GpuResult<Self> {
        let layout_bindings: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(b.ty())
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::ALL)
            })
            .collect();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings);
        // SAFETY: valid create infos throughout; objects are destroyed in Drop.
        unsafe {
            let layout = ctx
                .device
                .create_descriptor_set_layout(&info, None)
                .ctx("descriptor set layout")?;
            let sizes: Vec<_> = bindings
                .iter()
                .map(|b| vk::DescriptorPoolSize {
                    ty: b.ty(),
                    descriptor_count: 1,
                })
                .collect();
            let pool_info = vk::DescriptorPoolCreateInfo::default()
                .max_sets(1)
                .pool_sizes(&sizes);
            let pool = ctx
                .device
                .create_descriptor_pool(&pool_info, None)
                .ctx("descriptor pool")?;
            let layouts = [layout];
            let alloc = vk::DescriptorSetAllocateInfo::default()
                .descriptor_pool(pool)
                .set_layouts(&layouts);
            let set = ctx
                .device
                .allocate_descriptor_sets(&alloc)
                .ctx("allocate descriptor set")?[0];
            ctx.name_object(set, name);
            let buffer_infos: Vec<[vk::DescriptorBufferInfo; 1]> = bindings
                .iter()
                .map(|b| match b {
                    Binding::Uniform(buf) | Binding::Storage(buf) => [vk::DescriptorBufferInfo {
                        buffer: buf.raw,
                        offset: 0,
                        range: vk::WHOLE_SIZE,
                    }],
                    Binding::Texture(..) => [vk::DescriptorBufferInfo::default()],
                })
                .collect();
            let image_infos: Vec<[vk::DescriptorImageInfo; 1]> = bindings
                .iter()
                .map(|b| match b {
                    Binding::Texture(img, sampler) => [vk::DescriptorImageInfo {
                        sampler: *sampler,
                        image_view: img.view,
                        image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    }],
                    _ => [vk::DescriptorImageInfo::default()],
                })
                .collect();
            let writes: Vec<_> = bindings
                .iter()
                .enumerate()
                .map(|(i, b)| {
                    let w = vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(i as u32)
                        .descriptor_type(b.ty());
                    match b {
                        Binding::Texture(..) => w.image_info(&image_infos[i]),
                        _ => w.buffer_info(&buffer_infos[i]),
                    }
                })
                .collect();
            ctx.device.update_descriptor_sets(&writes, &[]);
            Ok(DescriptorSet {
                ctx: ctx.clone(),
                layout,
                pool,
                set,
            })
        }
    }
}

impl Drop for DescriptorSet {
    fn drop(&mut self) {
        // SAFETY: not in use once dropped.
        unsafe {
            self.ctx.device.destroy_descriptor_pool(self.pool, None);
            self.ctx
                .device
                .destroy_descriptor_set_layout(self.layout, None);
        }
    }
}
