//! Props: static triangle meshes placed by instance records (the ground, heads), and skinned
//! ones posed by the skinning pass (bodies and clothes). Reads: frame block, prop vertices,
//! prop instances, skin indices and this frame's posed vertices. Writes: colour and depth
//! (camera) or the light's prop depth map.

use std::sync::Arc;

use super::{DrawTarget, PassSets, vertex_pipeline};
use crate::vk::{CommandRecorder, Context, GpuResult, Pipeline, PipelineLayout};

/// One instanced draw: a mesh's vertex range and a run of instances.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PropDraw {
    /// First vertex of the mesh in the prop vertex buffer.
    pub first_vertex: u32,
    /// Vertices of the mesh (a triangle list).
    pub vertex_count: u32,
    /// First instance record.
    pub first_instance: u32,
    /// Instances.
    pub instance_count: u32,
    /// A skinned mesh: `first_vertex` and `vertex_count` are its range of the skin index
    /// buffer, and each instance names its posed vertices.
    pub skinned: bool,
}

/// The prop pipeline.
pub struct PropPass {
    pipeline: Pipeline,
}

impl PropPass {
    /// Compile the pipeline for `target` (shaded for the camera, depth only for the light).
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        target: DrawTarget,
    ) -> GpuResult<Self> {
        let frag = matches!(target, DrawTarget::Camera(_)).then_some("props.frag");
        Ok(PropPass {
            pipeline: vertex_pipeline(ctx, layout, "props", ("props.vert", frag), target)?,
        })
    }

    /// Draw `draws` (inside rendering).
    pub fn record(&self, rec: &mut CommandRecorder, sets: PassSets, draws: &[PropDraw]) {
        if draws.is_empty() {
            return;
        }
        rec.bind(&self.pipeline, &sets.both());
        for d in draws {
            rec.draw_instanced(
                d.vertex_count,
                d.instance_count,
                d.first_vertex,
                d.first_instance,
            );
        }
    }
}
