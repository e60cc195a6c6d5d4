//! Skinning: every skinned prop instance drawn this frame (bodies and clothes, near or far
//! versions) is posed by its character's skin matrices into the frame's posed vertices
//! (`glsl/skin.comp`; CPU twin `skin::skin_vertex`), read by the camera's and the light's
//! prop passes. Reads: the frame's inputs (rest vertices, matrices, jobs). Writes: the posed
//! vertices.

use std::sync::Arc;

use crate::render::core::binding::{PassSets, device_shader_options};
use crate::render::core::frame_res::FrameRes;
use crate::render::core::graph::FrameGraph;
use crate::render::core::shared::SKIN_GROUP_SIZE;
use crate::vk::shader::compile;
use crate::vk::{Access, Context, GpuResult, Pipeline, PipelineLayout};

/// Most jobs one dispatch covers (workgroup rows).
const JOBS_PER_DISPATCH: u32 = 65_535;

/// The skinning pipeline.
pub struct SkinPass {
    pipeline: Pipeline,
}

impl SkinPass {
    /// Compile the pipeline.
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let spirv = compile("skin.comp", &device_shader_options(ctx, 1))?;
        Ok(SkinPass {
            pipeline: Pipeline::compute(ctx, "skin", layout, &spirv)?,
        })
    }

    /// Add the skinning of `jobs` jobs of at most `widest` vertices each (none: nothing).
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        (jobs, widest): (u32, u32),
    ) {
        if jobs == 0 {
            return;
        }
        g.begin_scope("skin");
        g.pass("skin")
            .read(r.constants, Access::ComputeRead)
            .write(r.skinned, Access::ComputeReadWrite)
            .record(move |rec, _| {
                rec.bind(&self.pipeline, &sets.both());
                let groups = widest.div_ceil(SKIN_GROUP_SIZE);
                let mut first = 0;
                while first < jobs {
                    let rows = (jobs - first).min(JOBS_PER_DISPATCH);
                    rec.push_constants(&self.pipeline, &[first, 0u32, 0, 0]);
                    rec.dispatch(groups, rows, 1);
                    first += rows;
                }
                Ok(())
            });
        g.end_scope();
    }
}
