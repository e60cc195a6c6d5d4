//! GPU timestamps per pass and mesh-primitive counts, one query pool per frame in flight,
//! reset at the start of every frame.

use std::sync::Arc;

use ash::vk;

use super::command::CommandRecorder;
use super::{Context, GpuResult, VkContext};

/// Most timed passes in one frame.
pub const MAX_TIMED_PASSES: u32 = 32;

/// Timestamp queries: `begin(name)` / `end()` pairs around the passes of one frame.
pub struct Profiler {
    ctx: Arc<Context>,
    pool: vk::QueryPool,
    names: Vec<&'static str>,
}

impl Profiler {
    /// Room for [`MAX_TIMED_PASSES`] passes.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(MAX_TIMED_PASSES * 2);
        // SAFETY: valid create info.
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.ctx("create query pool")?;
        Ok(Profiler {
            ctx: ctx.clone(),
            pool,
            names: Vec::new(),
        })
    }

    /// Reset every query (record first in the frame, outside rendering).
    pub fn reset(&mut self, rec: &mut CommandRecorder) {
        self.names.clear();
        // SAFETY: recording outside rendering; the range is the whole pool.
        unsafe {
            self.ctx
                .device
                .cmd_reset_query_pool(rec.raw(), self.pool, 0, MAX_TIMED_PASSES * 2)
        };
    }

    fn stamp(&self, rec: &mut CommandRecorder, query: u32) {
        // SAFETY: recording; the query was reset this frame and is written once.
        unsafe {
            self.ctx.device.cmd_write_timestamp2(
                rec.raw(),
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                query,
            )
        };
    }

    /// Timestamp the start of pass `name`. Passes past [`MAX_TIMED_PASSES`] are not timed.
    pub fn begin(&mut self, rec: &mut CommandRecorder, name: &'static str) {
        if self.names.len() as u32 >= MAX_TIMED_PASSES {
            return;
        }
        self.names.push(name);
        self.stamp(rec, (self.names.len() as u32 - 1) * 2);
    }

    /// Timestamp the end of the pass begun last.
    pub fn end(&mut self, rec: &mut CommandRecorder) {
        if let Some(n) = self.names.len().checked_sub(1) {
            self.stamp(rec, n as u32 * 2 + 1);
        }
    }

    /// `(pass, milliseconds)` after the frame completed.
    pub fn results(&self) -> GpuResult<Vec<(&'static str, f64)>> {
        let n = self.names.len();
        if n == 0 {
            return Ok(Vec::new());
        }
        let mut data = vec![0u64; n * 2];
        // SAFETY: the frame's submission completed; WAIT makes the results available.
        unsafe {
            self.ctx.device.get_query_pool_results(
                self.pool,
                0,
                &mut data,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .ctx("query results")?;
        let period = self.ctx.info.timestamp_period as f64;
        Ok(self
            .names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                (
                    *name,
                    data[2 * i + 1].saturating_sub(data[2 * i]) as f64 * period / 1e6,
                )
            })
            .collect())
    }
}

impl Drop for Profiler {
    fn drop(&mut self) {
        // SAFETY: owners drop it after its frame retired.
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}

/// One `MESH_PRIMITIVES_GENERATED_EXT` query (VK_EXT_mesh_shader queries): the primitives
/// mesh shaders emit between `begin` and `end`.
pub struct MeshPrimitivesQuery {
    ctx: Arc<Context>,
    pool: vk::QueryPool,
    used: bool,
}

impl MeshPrimitivesQuery {
    /// `None` where the device has no mesh shader queries.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Option<Self>> {
        if !ctx.info.mesh_queries {
            return Ok(None);
        }
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::MESH_PRIMITIVES_GENERATED_EXT)
            .query_count(1);
        // SAFETY: valid create info; the query type is enabled (meshShaderQueries).
        let pool =
            unsafe { ctx.device.create_query_pool(&info, None) }.ctx("create mesh query pool")?;
        Ok(Some(MeshPrimitivesQuery {
            ctx: ctx.clone(),
            pool,
            used: false,
        }))
    }

    /// Reset (record outside rendering, every frame).
    pub fn reset(&mut self, rec: &mut CommandRecorder) {
        self.used = false;
        // SAFETY: recording outside rendering.
        unsafe {
            self.ctx
                .device
                .cmd_reset_query_pool(rec.raw(), self.pool, 0, 1)
        };
    }

    /// Start counting (inside rendering).
    pub fn begin(&mut self, rec: &mut CommandRecorder) {
        self.used = true;
        // SAFETY: recording; reset this frame.
        unsafe {
            self.ctx
                .device
                .cmd_begin_query(rec.raw(), self.pool, 0, vk::QueryControlFlags::empty())
        };
    }

    /// Stop counting (same rendering instance as `begin`).
    pub fn end(&mut self, rec: &mut CommandRecorder) {
        // SAFETY: matches begin.
        unsafe { self.ctx.device.cmd_end_query(rec.raw(), self.pool, 0) };
    }

    /// The count after the frame completed; `None` if it was not used this frame.
    pub fn result(&self) -> GpuResult<Option<u64>> {
        if !self.used {
            return Ok(None);
        }
        let mut data = [0u64; 1];
        // SAFETY: the submission completed; WAIT makes the result available.
        unsafe {
            self.ctx.device.get_query_pool_results(
                self.pool,
                0,
                &mut data,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .ctx("mesh query results")?;
        Ok(Some(data[0]))
    }
}

impl Drop for MeshPrimitivesQuery {
    fn drop(&mut self) {
        // SAFETY: owners drop it after its frame retired.
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}
