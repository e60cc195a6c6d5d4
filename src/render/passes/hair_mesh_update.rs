//! Animated hair meshes: rebuild the hair mesh texture and the u/v textures of every character
//! whose pose changed (`glsl/hair_mesh_update.comp`, the GPU twin of `bake::deform`), then copy
//! the packed texels into its textures. Reads: the pose and static basis buffers. Writes: the
//! characters' position, u and v textures (left sampled). Runs before anything reads them.

use std::sync::Arc;

use super::dispatch_2d;
use crate::render::shared::DeformBinding;
use crate::vk::{
    Access, Buffer, CommandRecorder, Context, DescriptorSet, DescriptorSetLayout, GpuResult, Image,
    Pipeline, Profiler,
};

/// One character's update this frame.
pub struct UpdateJob<'a> {
    /// Its update set for this frame slot.
    pub set: &'a DescriptorSet,
    /// Workgroups.
    pub groups: u32,
    /// Packed texels: hair mesh texture, u, v.
    pub outputs: &'a [Buffer; 3],
    /// Its textures: hair mesh texture, u, v (sampled).
    pub images: [&'a Image; 3],
}

/// The update pipeline.
pub struct HairMeshUpdate {
    set_layout: Arc<DescriptorSetLayout>,
    pipeline: Pipeline,
}

impl HairMeshUpdate {
    /// Compile the pass.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        let (set_layout, pipeline) = super::own_set_compute(
            ctx,
            "hair mesh update",
            "hair_mesh_update.comp",
            DeformBinding::ALL.iter().map(|(b, _)| *b as u32),
        )?;
        Ok(HairMeshUpdate {
            set_layout,
            pipeline,
        })
    }

    /// Layout of the per-character update sets.
    pub fn set_layout(&self) -> &Arc<DescriptorSetLayout> {
        &self.set_layout
    }

    /// Record the updates (outside rendering).
    pub fn record(&self, rec: &mut CommandRecorder, profiler: &mut Profiler, jobs: &[UpdateJob]) {
        if jobs.is_empty() {
            return;
        }
        profiler.begin(rec, "hair mesh update");
        // The output buffers were last read by the previous update's copies.
        rec.barrier(&[Access::TransferRead], &[Access::ComputeReadWrite]);
        for job in jobs {
            rec.bind(&self.pipeline, &[job.set]);
            let (x, y) = dispatch_2d(job.groups);
            rec.dispatch(x, y, 1);
        }
        rec.barrier(&[Access::ComputeReadWrite], &[Access::TransferRead]);
        for job in jobs {
            for (buffer, image) in job.outputs.iter().zip(job.images) {
                rec.image_barrier(image, Access::SampledRead, Access::TransferWrite);
                rec.copy_buffer_to_image(buffer, image);
                rec.image_barrier(image, Access::TransferWrite, Access::SampledRead);
            }
        }
        profiler.end(rec);
    }
}
