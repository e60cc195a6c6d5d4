//! GPU timestamps: an outer pair around every frame and one pair per timing scope (a pass or
//! a group of passes), plus mesh-primitive counts; one query pool per frame in flight, reset at
//! the start of every frame.

use std::sync::Arc;

use ash::vk;

use super::command::CommandRecorder;
use super::{Context, GpuResult, VkContext};

/// Most timing scopes in one frame; scopes past it are not timed (their commands count as
/// unscoped, so the frame report shows the loss).
pub const MAX_TIMED_PASSES: u32 = 126;

/// Queries 0 and 1 are the frame's outer pair; scope `i` is `2 + 2i` and `3 + 2i`.
const QUERIES: u32 = 2 + 2 * MAX_TIMED_PASSES;

/// A frame's timestamps, read back after it completed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameTimes {
    /// From the frame's first command to its last (the outer pair), milliseconds; `None`
    /// where the frame was not bracketed.
    pub frame_ms: Option<f64>,
    /// Milliseconds per scope name, in the order each name first opened (scopes of one name
    /// summed).
    pub scopes: Vec<(&'static str, f64)>,
}

/// Timestamp queries: `begin_frame`, then `begin(name)` / `end()` pairs, then `end_frame`.
pub struct Profiler {
    ctx: Arc<Context>,
    pool: vk::QueryPool,
    names: Vec<&'static str>,
    /// Outer pair written this frame: (begin, end).
    framed: (bool, bool),
    open: bool,
}

impl Profiler {
    /// Room for the frame's pair and [`MAX_TIMED_PASSES`] scopes.
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(QUERIES);
        // SAFETY: valid create info.
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.ctx("create query pool")?;
        Ok(Profiler {
            ctx: ctx.clone(),
            pool,
            names: Vec::new(),
            framed: (false, false),
            open: false,
        })
    }

    /// Reset every query (record first in the frame, outside rendering).
    pub fn reset(&mut self, rec: &mut CommandRecorder) {
        self.names.clear();
        self.framed = (false, false);
        self.open = false;
        // SAFETY: recording outside rendering; the range is the whole pool.
        unsafe {
            self.ctx
                .device
                .cmd_reset_query_pool(rec.raw(), self.pool, 0, QUERIES)
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

    /// Timestamp the frame's start (after [`Self::reset`], before its first command).
    pub fn begin_frame(&mut self, rec: &mut CommandRecorder) {
        if !self.framed.0 {
            self.framed.0 = true;
            self.stamp(rec, 0);
        }
    }

    /// Timestamp the frame's end (after its last command).
    pub fn end_frame(&mut self, rec: &mut CommandRecorder) {
        if self.framed.0 && !self.framed.1 {
            self.framed.1 = true;
            self.stamp(rec, 1);
        }
    }

    /// Whether a scope is open now.
    pub fn scope_open(&self) -> bool {
        self.open
    }

    /// Timestamp the start of scope `name` (scopes do not nest: an open one is ended first).
    /// Scopes past [`MAX_TIMED_PASSES`] are not timed.
    pub fn begin(&mut self, rec: &mut CommandRecorder, name: &'static str) {
        if self.open {
            self.end(rec);
        }
        if self.names.len() as u32 >= MAX_TIMED_PASSES {
            return;
        }
        self.names.push(name);
        self.open = true;
        rec.scope_changed(true);
        self.stamp(rec, 2 + (self.names.len() as u32 - 1) * 2);
    }

    /// Timestamp the end of the open scope.
    pub fn end(&mut self, rec: &mut CommandRecorder) {
        if !self.open {
            return;
        }
        self.open = false;
        rec.scope_changed(false);
        self.stamp(rec, 3 + (self.names.len() as u32 - 1) * 2);
    }

    /// Read `count` written queries from `first`.
    fn read(&self, first: u32, count: usize) -> GpuResult<Vec<u64>> {
        let mut data = vec![0u64; count];
        if count > 0 {
            // SAFETY: the frame's submission completed and these queries were written this
            // frame (an unwritten one would never become available); WAIT makes them so.
            unsafe {
                self.ctx.device.get_query_pool_results(
                    self.pool,
                    first,
                    &mut data,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .ctx("query results")?;
        }
        Ok(data)
    }

    /// The frame's timestamps after it completed.
    pub fn results(&self) -> GpuResult<FrameTimes> {
        let period = self.ctx.info.timestamp_period as f64;
        let ms = |a: u64, b: u64| b.saturating_sub(a) as f64 * period / 1e6;
        // A scope still open at the end of recording has no end stamp: not read.
        let closed = self.names.len() - usize::from(self.open);
        let data = self.read(2, 2 * closed)?;
        let mut scopes: Vec<(&'static str, f64)> = Vec::new();
        for (i, name) in self.names[..closed].iter().enumerate() {
            let t = ms(data[2 * i], data[2 * i + 1]);
            match scopes.iter_mut().find(|s| s.0 == *name) {
                Some(s) => s.1 += t,
                None => scopes.push((name, t)),
            }
        }
        let frame_ms = if self.framed.0 && self.framed.1 {
            let pair = self.read(0, 2)?;
            Some(ms(pair[0], pair[1]))
        } else {
            None
        };
        Ok(FrameTimes { frame_ms, scopes })
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
