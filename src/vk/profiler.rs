//! GPU timestamps per pass.

use std::sync::Arc;

use ash::vk;

use super::{Context, GpuResult, VkContext};

/// Timestamp queries: `begin(name)` / `end()` pairs around passes.
pub struct Profiler {
    ctx: Arc<Context>,
    pool: vk::QueryPool,
    names: Vec<String>,
    capacity: u32,
}

impl Profiler {
    /// Room for `passes` timed passes.
    pub fn new(ctx: &Arc<Context>, passes: u32) -> GpuResult<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(passes * 2);
        // SAFETY: valid create info.
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.ctx("create query pool")?;
        Ok(Profiler {
            ctx: ctx.clone(),
            pool,
            names: Vec::new(),
            capacity: passes,
        })
    }

    /// Reset all queries (record at the start of a frame).
    pub fn reset(&mut self, cmd: vk::CommandBuffer) {
        self.names.clear();
        // SAFETY: recording; the range is within the pool.
        unsafe {
            self.ctx
                .device
                .cmd_reset_query_pool(cmd, self.pool, 0, self.capacity * 2)
        };
    }

    /// Timestamp the start of pass `name`.
    pub fn begin(&mut self, cmd: vk::CommandBuffer, name: &str) {
        if self.names.len() as u32 >= self.capacity {
            return;
        }
        let q = self.names.len() as u32 * 2;
        self.names.push(name.to_string());
        // SAFETY: recording; query was reset this frame.
        unsafe {
            self.ctx.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                q,
            )
        };
    }

    /// Timestamp the end of the pass begun last.
    pub fn end(&mut self, cmd: vk::CommandBuffer) {
        let Some(n) = self.names.len().checked_sub(1) else {
            return;
        };
        // SAFETY: recording; query was reset this frame.
        unsafe {
            self.ctx.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                n as u32 * 2 + 1,
            )
        };
    }

    /// `(pass, milliseconds)` after the frame completed.
    pub fn results(&self) -> GpuResult<Vec<(String, f64)>> {
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
                    name.clone(),
                    data[2 * i + 1].saturating_sub(data[2 * i]) as f64 * period / 1e6,
                )
            })
            .collect())
    }
}

impl Drop for Profiler {
    fn drop(&mut self) {
        // SAFETY: not in use once dropped.
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}

/// A `MESH_PRIMITIVES_GENERATED_EXT` query per slot (VK_EXT_mesh_shader queries): counts the
/// primitives mesh shaders emit between `begin` and `end`.
pub struct MeshPrimitivesQuery {
    ctx: Arc<Context>,
    pool: vk::QueryPool,
    slots: u32,
}

impl MeshPrimitivesQuery {
    /// `slots` queries; `None` where the device has no mesh shader queries.
    pub fn new(ctx: &Arc<Context>, slots: u32) -> GpuResult<Option<Self>> {
        if !ctx.info.mesh_queries || slots == 0 {
            return Ok(None);
        }
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::MESH_PRIMITIVES_GENERATED_EXT)
            .query_count(slots);
        // SAFETY: valid create info; the query type is enabled (meshShaderQueries).
        let pool =
            unsafe { ctx.device.create_query_pool(&info, None) }.ctx("create mesh query pool")?;
        Ok(Some(MeshPrimitivesQuery {
            ctx: ctx.clone(),
            pool,
            slots,
        }))
    }

    /// Reset all slots (outside a render pass instance).
    pub fn reset(&self, cmd: vk::CommandBuffer) {
        // SAFETY: recording; range within the pool.
        unsafe {
            self.ctx
                .device
                .cmd_reset_query_pool(cmd, self.pool, 0, self.slots)
        };
    }

    /// Start counting into `slot`.
    pub fn begin(&self, cmd: vk::CommandBuffer, slot: u32) {
        // SAFETY: recording; slot reset this frame.
        unsafe {
            self.ctx.device.cmd_begin_query(
                cmd,
                self.pool,
                slot.min(self.slots - 1),
                vk::QueryControlFlags::empty(),
            )
        };
    }

    /// Stop counting into `slot`.
    pub fn end(&self, cmd: vk::CommandBuffer, slot: u32) {
        // SAFETY: matches `begin` in the same render pass instance.
        unsafe {
            self.ctx
                .device
                .cmd_end_query(cmd, self.pool, slot.min(self.slots - 1))
        };
    }

    /// Sum of the first `used` slots after the submission completed.
    pub fn total(&self, used: u32) -> GpuResult<u64> {
        let used = used.min(self.slots);
        if used == 0 {
            return Ok(0);
        }
        let mut data = vec![0u64; used as usize];
        // SAFETY: the submission completed; WAIT makes results available.
        unsafe {
            self.ctx.device.get_query_pool_results(
                self.pool,
                0,
                &mut data,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .ctx("mesh query results")?;
        Ok(data.iter().sum())
    }
}

impl Drop for MeshPrimitivesQuery {
    fn drop(&mut self) {
        // SAFETY: not in use once dropped.
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}
