//! The opaque scalps of every character in one draw (two triangles per bundle, pulled from the
//! root slice). Reads: frame block, character records, bundle table, textures. Writes: colour
//! and depth.

use std::sync::Arc;

use super::{DrawTarget, PassSets, TargetFormats, vertex_pipeline};
use crate::vk::{CommandRecorder, Context, GpuResult, Pipeline, PipelineLayout};

/// The scalp pipeline.
pub struct ScalpPass {
    pipeline: Pipeline,
}

impl ScalpPass {
    /// Compile the pipeline for the given target formats.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        targets: TargetFormats,
    ) -> GpuResult<Self> {
        Ok(ScalpPass {
            pipeline: vertex_pipeline(
                ctx,
                layout,
                "scalp",
                ("scalp.vert", Some("scalp.frag")),
                DrawTarget::Camera(targets),
            )?,
        })
    }

    /// Draw the scalps of `bundles` bundles (inside rendering).
    pub fn record(&self, rec: &mut CommandRecorder, sets: PassSets, bundles: u32) {
        rec.bind(&self.pipeline, &sets.both());
        rec.draw(bundles * 6);
    }
}
