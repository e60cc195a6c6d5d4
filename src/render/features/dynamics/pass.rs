//! Hair dynamics on the GPU (`glsl/hair_dynamics.comp`, `render::dynamics`): one dispatch for
//! every character simulated this frame, one workgroup each, reading the frame slot's job
//! table by device address. Reads and writes: each character's state buffer. Writes: its pose
//! buffer, which `passes::hair_mesh_update` reads next.

use std::sync::Arc;

use crate::render::core::binding::shader_options;
use crate::render::core::graph::{FrameGraph, Res};
use crate::render::core::pipelines::dispatch_2d;
use crate::vk::shader::compile;
use crate::vk::{Access, Buffer, Context, GpuResult, Pipeline, PipelineLayout};

/// One simulated character's buffers this frame.
pub struct SimulatedCharacter<'a> {
    /// Positions and velocities, then the substep positions.
    pub state: &'a Buffer,
    /// The pose the texture rebuild reads.
    pub pose: &'a Buffer,
}

/// The solver's pipeline.
pub struct HairDynamicsPass {
    pipeline: Pipeline,
}

impl HairDynamicsPass {
    /// Compile the pass.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        let layout = PipelineLayout::new(ctx, &[])?;
        let options = match ctx.info.cpu_device {
            true => shader_options(1).define("CPU_DEVICE", 1),
            false => shader_options(1),
        };
        let spirv = compile("hair_dynamics.comp", &options)?;
        Ok(HairDynamicsPass {
            pipeline: Pipeline::compute(ctx, "hair dynamics", &layout, &spirv)?,
        })
    }

    /// Add the step of every character in `simulated` (the jobs in `table`, in that order);
    /// returns each character's pose in the graph, for the texture rebuild to read.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        table: &'a Buffer,
        simulated: &[SimulatedCharacter<'a>],
    ) -> Vec<Res> {
        if simulated.is_empty() {
            return Vec::new();
        }
        let jobs = g.host_input("hair dynamics jobs");
        let states: Vec<Res> = simulated
            .iter()
            .map(|s| g.import_buffer("hair state", s.state))
            .collect();
        let poses: Vec<Res> = simulated
            .iter()
            .map(|s| g.import_buffer("simulated pose", s.pose))
            .collect();
        let count = simulated.len() as u32;
        let address = table.device_address();
        g.begin_scope("hair dynamics");
        let mut p = g.pass("hair dynamics").read(jobs, Access::ComputeRead);
        for (s, pose) in states.iter().zip(&poses) {
            p = p
                .write(*s, Access::ComputeReadWrite)
                .discard(*pose, Access::ComputeReadWrite);
        }
        p.record(move |rec, _| {
            rec.bind(&self.pipeline, &[]);
            rec.push_constants(&self.pipeline, &[address[0], address[1], count, 0]);
            let (x, y) = dispatch_2d(count);
            rec.dispatch(x, y, 1);
            Ok(())
        });
        g.end_scope();
        poses
    }
}
