//! The static and LHS paths through the software rasterizer: the stored strands in the vertex
//! pool (the last compute-path frame's, skinned on the LHS path) become segments
//! (`pool_segments.comp`, the same `emit_soft_segments` as generated strands), which the
//! software rasterizer's binning and raster then draw. What each step reads and writes is
//! declared where it is added to the frame graph.

use std::sync::Arc;

use super::{FrameRes, PassSets, TemporalRes, device_shader_options};
use crate::render::core::graph::FrameGraph;
use crate::render::core::shared::GenerateArgs;
use crate::vk::shader::compile;
use crate::vk::{Access, Context, GpuResult, Pipeline, PipelineLayout};

/// Bytes of the software rasterizer's four counters in `FrameStats` (segments and tile
/// entries, demanded and written), from `GenerateArgs::SEGMENTS_DEMANDED_OFFSET`.
const SOFT_COUNTER_BYTES: u64 = 16;

/// The stored strands' segment pass.
pub struct PoolSegments {
    pipeline: Pipeline,
}

impl PoolSegments {
    /// Compile the pipeline.
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let spirv = compile("pool_segments.comp", &device_shader_options(ctx, 1))?;
        Ok(PoolSegments {
            pipeline: Pipeline::compute(ctx, "pool segments", layout, &spirv)?,
        })
    }

    /// Add the segments of the pool's strands seen from the view of `sets`. The draw
    /// arguments stay the compute frame's; only the software rasterizer's counters restart.
    pub fn add<'a>(&'a self, g: &mut FrameGraph<'a>, r: &FrameRes<'a>, sets: PassSets<'a>) {
        let args = r.args_buffer;
        g.pass("soft counters clear")
            .write(r.args, Access::TransferWrite)
            .record(move |rec, _| {
                let at = GenerateArgs::SEGMENTS_DEMANDED_OFFSET;
                rec.fill_buffer(args, at, SOFT_COUNTER_BYTES, 0);
                Ok(())
            });
        let rw = Access::ComputeReadWrite;
        g.begin_scope("soft segments");
        let p = g
            .pass("pool segments")
            .read_all(&[r.constants, r.textures], Access::ComputeRead)
            .read_all(&[r.pool, r.lods, r.offsets], Access::ComputeRead)
            .read(r.args, Access::IndirectRead)
            .write(r.args, rw)
            .write(r.soft_segments, rw)
            .write_some(TemporalRes::segment_motion(r.temporal), rw);
        r.shading_uses(p, Access::ComputeRead)
            .record(move |rec, _| {
                rec.bind(&self.pipeline, &sets.both());
                rec.dispatch_indirect(args, GenerateArgs::DISPATCH_OFFSET);
                Ok(())
            });
        g.end_scope();
    }
}

#[cfg(test)]
mod tests {
    use crate::render::core::shared::{FrameStats, GenerateArgs};

    /// The clear covers the four software counters and nothing after them (the LoD demand
    /// that follows is the compute frame's).
    #[test]
    fn soft_counters_are_four_statistics_in_a_row() {
        let end = std::mem::offset_of!(GenerateArgs, stats)
            + std::mem::offset_of!(FrameStats, tile_entries_written)
            + 4;
        assert_eq!(
            GenerateArgs::SEGMENTS_DEMANDED_OFFSET + super::SOFT_COUNTER_BYTES,
            end as u64
        );
    }
}
