//! Props: static triangle meshes placed by instance records (the ground, heads), and skinned
//! ones posed by the skinning pass (bodies and clothes). Reads: frame block, prop vertices,
//! prop instances, skin indices and this frame's posed vertices. Writes: colour and depth
//! (camera) or the light's prop depth map.

use std::sync::Arc;

use crate::render::core::binding::PassSets;
use crate::render::core::pipelines::{DrawTarget, vertex_pipeline};
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

/// A frame's prop draws and the skinned meshes' index buffer they index.
#[derive(Clone, Copy, Default)]
pub struct PropList<'a> {
    /// The draws.
    pub draws: &'a [PropDraw],
    /// Every skinned mesh's triangle list (`PropDraw::first_vertex` counts into it).
    pub skin_indices: Option<&'a crate::vk::Buffer>,
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

    /// Draw `props` (inside rendering): static meshes as vertex ranges, skinned ones indexed,
    /// so a posed vertex that several triangles share is shaded once where the device keeps
    /// it (lavapipe does: about 6 index reads per vertex in the people's meshes).
    pub fn record(&self, rec: &mut CommandRecorder, sets: PassSets, props: PropList) {
        if props.draws.is_empty() {
            return;
        }
        rec.bind(&self.pipeline, &sets.both());
        for d in props.draws {
            match (d.skinned, props.skin_indices) {
                (true, Some(index)) => rec.draw_indexed_instanced(
                    index,
                    (d.first_vertex, d.vertex_count),
                    (d.first_instance, d.instance_count),
                ),
                // A skinned draw without its indices cannot happen (the table made both).
                (true, None) => {}
                (false, _) => rec.draw_instanced(
                    d.vertex_count,
                    d.instance_count,
                    d.first_vertex,
                    d.first_instance,
                ),
            }
        }
    }
}
