//! The root probe (`FrameOptions::probe_roots`): every bundle's first strand root, placed by
//! the GPU from this frame's textures and character records with the generator's own
//! functions (`glsl/root_probe.comp`), read back into the frame's report. Reads: the frame's
//! inputs and textures. Writes: the frame slot's probe buffer, which the host reads.

use std::sync::Arc;

use super::{FrameRes, PassSets, device_shader_options, dispatch_2d};
use crate::render::core::graph::{FrameGraph, Res};
use crate::vk::shader::compile;
use crate::vk::{Access, Context, GpuResult, Pipeline, PipelineLayout};

/// The probe pipeline.
pub struct RootProbePass {
    pipeline: Pipeline,
}

impl RootProbePass {
    /// Compile the pipeline.
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let spirv = compile("root_probe.comp", &device_shader_options(ctx, 1))?;
        Ok(RootProbePass {
            pipeline: Pipeline::compute(ctx, "root probe", layout, &spirv)?,
        })
    }

    /// Add the probe of `bundles` bundles into `probe` (then read by the host).
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        (probe, bundles): (Res, u32),
    ) {
        if bundles == 0 {
            return;
        }
        g.begin_scope("root probe");
        g.pass("root probe")
            .read_all(&[r.constants, r.textures], Access::ComputeRead)
            .write(probe, Access::ComputeReadWrite)
            .record(move |rec, _| {
                rec.bind(&self.pipeline, &sets.both());
                rec.push_constants(&self.pipeline, &[bundles, 0u32, 0, 0]);
                // One workgroup a bundle (`root_probe.comp`: uniform texture index).
                let (x, y) = dispatch_2d(bundles);
                rec.dispatch(x, y, 1);
                Ok(())
            });
        g.end_scope();
        g.pass("root probe to host")
            .read(probe, Access::HostRead)
            .done();
    }
}
