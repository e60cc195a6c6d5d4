//! Animated hair meshes: rebuild the hair mesh texture and the u/v textures of every character
//! whose pose changed (`glsl/hair_mesh_update.comp`, the GPU twin of `bake::deform`), then copy
//! the packed texels into its textures. Reads: the pose (uploaded, or written by
//! `features::dynamics::pass`) and static basis buffers. Writes: the
//! characters' position, u and v textures (left sampled). Runs before anything reads them.

use std::sync::Arc;

use super::{FrameRes, dispatch_2d};
use crate::render::core::graph::{FrameGraph, ImageState, Res};
use crate::render::core::shared::DeformBinding;
use crate::vk::{
    Access, Buffer, Context, DescriptorSet, DescriptorSetLayout, GpuResult, Image, Pipeline,
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

    /// Add the updates: the rebuild of every job's packed texels (reading `simulated`, the
    /// poses the GPU dynamics wrote this frame), their copies into the textures, and the
    /// hand-back of the textures to sampling.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes,
        jobs: &'a [UpdateJob<'a>],
        simulated: &[Res],
    ) {
        if jobs.is_empty() {
            return;
        }
        let outputs: Vec<Vec<Res>> = jobs
            .iter()
            .map(|j| {
                j.outputs
                    .iter()
                    .map(|b| g.import_buffer("update texels", b))
                    .collect()
            })
            .collect();
        let images: Vec<Vec<Res>> = jobs
            .iter()
            .map(|j| {
                j.images
                    .iter()
                    .map(|i| {
                        g.import_image(
                            "character texture",
                            i,
                            ImageState::Fixed(Access::SampledRead),
                        )
                    })
                    .collect()
            })
            .collect();
        g.begin_scope("hair mesh update");
        let mut p = g
            .pass("hair mesh update")
            .read(r.constants, Access::ComputeRead)
            .read_all(simulated, Access::ComputeRead);
        for o in outputs.iter().flatten() {
            p = p.discard(*o, Access::ComputeReadWrite);
        }
        p.record(move |rec, _| {
            for job in jobs {
                rec.bind(&self.pipeline, &[job.set]);
                let (x, y) = dispatch_2d(job.groups);
                rec.dispatch(x, y, 1);
            }
            Ok(())
        });
        let mut p = g.pass("texture upload");
        for (o, i) in outputs.iter().flatten().zip(images.iter().flatten()) {
            p = p
                .read(*o, Access::TransferRead)
                .discard(*i, Access::TransferWrite);
        }
        p.record(move |rec, _| {
            for job in jobs {
                for (buffer, image) in job.outputs.iter().zip(job.images) {
                    rec.copy_buffer_to_image(buffer, image);
                }
            }
            Ok(())
        });
        let all: Vec<Res> = images.into_iter().flatten().collect();
        g.pass("textures sampled")
            .read_all(&all, Access::SampledRead)
            .done();
        g.end_scope();
    }
}
