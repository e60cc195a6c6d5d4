//! The temporal passes: the visibility words are emptied before the camera's drawing (whose
//! passes note each pixel's nearest surface); after it the motion pass turns them into motion
//! vectors and, with accumulation, blends the reprojected history into the frame
//! (`temporal.comp`), whose colour is copied out of the output image first and back onto it
//! last. What each step reads and writes is declared where it is added.

use std::sync::Arc;

use super::TemporalWork;
use crate::render::core::binding::{PassSets, device_shader_options};
pub use crate::render::core::frame_res::TemporalRes;
use crate::render::core::graph::{FrameGraph, Res};
use crate::render::core::shared::TEMPORAL_GROUP;
use crate::vk::shader::compile;
use crate::vk::{Access, Buffer, Context, GpuResult, Image, Pipeline, PipelineLayout};

/// What the temporal passes take from the frame.
pub struct TemporalInputs<'a> {
    /// The frame block.
    pub constants: Res,
    /// The visibility words the camera's passes wrote.
    pub visibility: Res,
    /// The rest of the temporal resources.
    pub res: TemporalRes,
    /// The frame's output image: its graph handle and the image.
    pub output: (Res, &'a Image),
    /// The camera's descriptor sets.
    pub sets: PassSets<'a>,
    /// Target size.
    pub size: (u32, u32),
    /// What this frame does.
    pub work: TemporalWork,
    /// Where the motion vectors are copied for the host, when asked for.
    pub readback: Option<&'a Buffer>,
}

/// The motion and accumulation pipeline (`temporal.comp`, two stages).
pub struct TemporalPass {
    pipeline: Pipeline,
}

impl TemporalPass {
    /// Compile the pipeline (it reads 64-bit visibility words: the caller creates this pass
    /// only on devices with 64-bit buffer atomics).
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let spirv = compile("temporal.comp", &device_shader_options(ctx, 1))?;
        Ok(TemporalPass {
            pipeline: Pipeline::compute(ctx, "temporal", layout, &spirv)?,
        })
    }

    /// Add the pass that empties the visibility words (before any camera pass notes them).
    pub fn add_clear(g: &mut FrameGraph<'_>, visibility: Option<Res>) {
        let Some(visibility) = visibility else {
            return;
        };
        g.pass("visibility clear")
            .discard(visibility, Access::TransferWrite)
            .record(move |rec, res| {
                rec.fill_buffer(res.buffer(visibility)?, 0, ash::vk::WHOLE_SIZE, u32::MAX);
                Ok(())
            });
    }

    /// Add the motion pass and, with `work.accumulate`, the accumulation around it (after
    /// every camera pass); the motion vectors are copied into `readback` where given.
    pub fn add<'a>(&'a self, g: &mut FrameGraph<'a>, inputs: TemporalInputs<'a>) {
        let TemporalInputs {
            constants,
            visibility,
            res: t,
            output: (output_res, output),
            sets,
            size,
            work,
            readback,
        } = inputs;
        if work.accumulate {
            g.begin_scope("temporal input");
            g.pass("temporal input")
                .read(output_res, Access::TransferRead)
                .discard(t.frame_color, Access::TransferWrite)
                .record(move |rec, res| {
                    rec.copy_image_to_buffer(output, res.buffer(t.frame_color)?);
                    Ok(())
                });
            g.end_scope();
        }
        g.begin_scope("temporal");
        let groups = (
            size.0.div_ceil(TEMPORAL_GROUP),
            size.1.div_ceil(TEMPORAL_GROUP),
        );
        let rw = Access::ComputeReadWrite;
        // The motion target is written where it is read back or is the frame's only work.
        let write_motion = readback.is_some() || !work.accumulate;
        let mut p = g
            .pass("temporal")
            .read_all(&[constants, visibility], Access::ComputeRead);
        if write_motion {
            p = p.discard(t.motion, rw);
        }
        if work.accumulate {
            // Reads the frame's colour (first half), writes the accumulated one (second).
            p = p
                .write(t.frame_color, rw)
                .read(t.history.0, Access::ComputeRead)
                .discard(t.history.1, rw);
        }
        p.record(move |rec, _| {
            rec.bind(&self.pipeline, &sets.both());
            rec.push_constants(&self.pipeline, &[write_motion as u32, 0, 0, 0]);
            rec.dispatch(groups.0, groups.1, 1);
            Ok(())
        });
        g.end_scope();
        if work.accumulate {
            g.begin_scope("temporal output");
            let (frame_color, pixels) = (t.frame_color, size.0 as u64 * size.1 as u64);
            g.pass("temporal output")
                .read(t.frame_color, Access::TransferRead)
                .write(output_res, Access::TransferWrite)
                .record(move |rec, res| {
                    let colors = res.buffer(frame_color)?;
                    rec.copy_buffer_to_image_at(colors, pixels * 4, output);
                    Ok(())
                });
            g.end_scope();
        }
        if let Some(buffer) = readback {
            let target = g.import_buffer("motion readback", buffer);
            g.pass("motion readback")
                .read(t.motion, Access::TransferRead)
                .discard(target, Access::TransferWrite)
                .record(move |rec, res| {
                    let motion = res.buffer(t.motion)?;
                    rec.copy_buffer(motion, 0, buffer, 0, buffer.size.min(motion.size));
                    Ok(())
                });
            g.pass("motion host read")
                .read(target, Access::HostRead)
                .done();
        }
    }
}
