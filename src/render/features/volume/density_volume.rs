//! Strand density volumes (`glsl/density_volume.comp`, the twin of
//! `reference::volume::density_volume`): one dispatch for every volume requested this frame,
//! a workgroup per (bundle, volume), reading the frame slot's job table by device address.
//! Reads: the frame's records, bundle table and the characters' textures (after this frame's
//! texture rebuilds). Writes: each requested volume's cells, cleared first (the frame's
//! density volumes, one resource of the graph: shaders reach them by device address); then a
//! second dispatch, a workgroup per volume, writes each one's occupancy mask after its cells.

use std::sync::Arc;

use crate::render::core::binding::{PassSets, shader_options};
use crate::render::core::frame_res::FrameRes;
use crate::render::core::graph::FrameGraph;
use crate::render::core::shared::DENSITY_PASS_OCCUPANCY;
use crate::vk::shader::compile;
use crate::vk::{Access, Buffer, Context, GpuResult, Pipeline, PipelineLayout};

/// The density build's pipeline.
pub struct DensityVolumePass {
    pipeline: Pipeline,
}

impl DensityVolumePass {
    /// Compile the pass.
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let spirv = compile("density_volume.comp", &shader_options(1))?;
        Ok(DensityVolumePass {
            pipeline: Pipeline::compute(ctx, "density volume", layout, &spirv)?,
        })
    }

    /// Add the builds of `volumes` (the cells buffers of the jobs in `table`, in that order;
    /// `most_bundles`: the largest bundle count among them).
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes,
        sets: PassSets<'a>,
        table: &'a Buffer,
        volumes: &[&'a Buffer],
        most_bundles: u32,
    ) {
        if volumes.is_empty() || most_bundles == 0 {
            return;
        }
        let jobs = g.host_input("density volume jobs");
        g.begin_scope("density volume");
        let clear: Vec<&'a Buffer> = volumes.to_vec();
        g.pass("density clear")
            .write(r.volumes, Access::TransferWrite)
            .record(move |rec, _| {
                for buffer in clear {
                    rec.fill_buffer(buffer, 0, buffer.size, 0);
                }
                Ok(())
            });
        let p = g
            .pass("density volume")
            .read(jobs, Access::ComputeRead)
            .read_all(&[r.constants, r.textures], Access::ComputeRead)
            .write(r.volumes, Access::ComputeReadWrite);
        let address = table.device_address();
        let count = volumes.len() as u32;
        p.record(move |rec, _| {
            rec.bind(&self.pipeline, &sets.both());
            rec.push_constants(&self.pipeline, &[address[0], address[1], count, 0]);
            rec.dispatch(most_bundles, count, 1);
            Ok(())
        });
        let occupancy = [address[0], address[1], count, DENSITY_PASS_OCCUPANCY];
        g.pass("density occupancy")
            .read(jobs, Access::ComputeRead)
            .read_all(&[r.constants], Access::ComputeRead)
            .write(r.volumes, Access::ComputeReadWrite)
            .record(move |rec, _| {
                rec.bind(&self.pipeline, &sets.both());
                rec.push_constants(&self.pipeline, &occupancy);
                rec.dispatch(1, count, 1);
                Ok(())
            });
        g.end_scope();
    }
}
