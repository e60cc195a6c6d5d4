//! What each of the frames in flight owns: command buffer, fence, per-frame uniform data and
//! character records, timestamp and mesh queries (reset every frame), statistics and image
//! readback, its descriptor set 0, and the resources retired with it; and the report a
//! finished frame gives.

use std::any::Any;
use std::sync::Arc;

use ash::vk;
use glam::Vec2;

use super::path::RenderPath;
use super::shared::{CharacterRecord, FrameBlock, FrameStats, GenerateArgs};
use crate::vk::{
    Buffer, BufferDesc, CommandBuffer, Context, DescriptorSet, DescriptorSetLayout, Fence,
    GpuResult, MeshPrimitivesQuery, Profiler,
};

/// Frames the CPU may record ahead of the GPU.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// A resource released once the frame it was retired with has completed.
pub enum Retired {
    /// Any GPU object (buffer, image, set...): dropped.
    Resource(Box<dyn Any + Send>),
    /// A character slot: reusable.
    CharacterSlot(u32),
}

/// What a completed frame did.
#[derive(Clone, Debug)]
pub struct FrameReport {
    /// Frame number (from 0, per renderer).
    pub frame: u64,
    /// Generation path used.
    pub path: RenderPath,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// What the GPU generated for the camera.
    pub stats: FrameStats,
    /// What the GPU generated for the light's view (zero without shadows, and on the static
    /// and LHS paths).
    pub light_stats: FrameStats,
    /// The buffers the views' LoD had to fit (the LoD pressure's budgets).
    pub budgets: ViewBudgets,
    /// GPU milliseconds per timing scope (a pass, or passes grouped under one name; scopes
    /// of one name summed), in the order they first ran.
    pub pass_ms: Vec<(&'static str, f64)>,
    /// GPU milliseconds from the frame's first command to its last (an outer pair of
    /// timestamps); `None` where the device could not time it.
    pub frame_ms: Option<f64>,
    /// Commands the frame recorded outside every timing scope (0: the scopes account for all
    /// its work).
    pub unscoped_commands: u32,
    /// Mesh path: `MESH_PRIMITIVES_GENERATED_EXT` where the device supports it.
    pub mesh_primitives: Option<u64>,
    /// CPU milliseconds spent recording the frame's commands.
    pub record_ms: f64,
    /// RGBA8 pixels (sRGB), top row first, when requested.
    pub rgba: Option<Vec<u8>>,
    /// Motion vectors and nearest surfaces per pixel, top row first, when requested
    /// (`FrameOptions::read_motion`).
    pub motion: Option<Vec<PixelMotion>>,
    /// The frame graph's passes, uses and derived dependencies, when
    /// `FrameOptions::describe_frame` was set.
    pub frame_graph: Option<String>,
    /// The volume tier: characters drawn as their density volume alone, and those blended
    /// between strands and volume.
    pub volume_characters: (u32, u32),
    /// With `FrameOptions::probe_roots`: per crowd bundle, its first strand's root as the GPU
    /// placed it this frame (world), and the character slot + 1 in w (0: no bundle).
    pub roots: Option<Vec<[f32; 4]>>,
}

impl FrameReport {
    /// GPU milliseconds of the whole frame: the outer pair, else the sum of the scopes.
    pub fn gpu_ms(&self) -> f64 {
        self.frame_ms.unwrap_or_else(|| self.scoped_ms())
    }

    /// The sum of the timing scopes.
    pub fn scoped_ms(&self) -> f64 {
        self.pass_ms.iter().map(|p| p.1).sum()
    }

    /// The part of the frame no scope covers (barrier waits and work between scopes).
    pub fn unscoped_ms(&self) -> Option<f64> {
        self.frame_ms.map(|f| (f - self.scoped_ms()).max(0.0))
    }

    /// `name=ms` per scope, then `unscoped=ms` (and the commands recorded outside every
    /// scope, where there were any), joined with `sep`: what every tool prints per frame.
    pub fn scope_summary(&self, sep: &str) -> String {
        let mut parts: Vec<String> = self
            .pass_ms
            .iter()
            .map(|(n, ms)| format!("{n}={ms:.2}"))
            .collect();
        if let Some(u) = self.unscoped_ms() {
            parts.push(format!("unscoped={u:.2}"));
        }
        if self.unscoped_commands > 0 {
            parts.push(format!("unscoped commands={}", self.unscoped_commands));
        }
        parts.join(sep)
    }

    /// Work the frame's buffers had no room for, camera and light together (all zero:
    /// nothing was lost).
    pub fn dropped(&self) -> Dropped {
        Dropped::of(&self.stats).plus(Dropped::of(&self.light_stats))
    }

    /// The share of their strands the camera's bundles kept so the frame fit its buffers
    /// (1: the LoD as asked; below 1 every bundle of the kind that ran short was thinned by
    /// it, widened to keep its coverage): the smaller of the software and the vertex-pool
    /// shares, and of the camera's and the light's.
    pub fn lod_pressure(&self) -> f32 {
        [&self.stats, &self.light_stats]
            .iter()
            .map(|s| self.budgets.pressure(s))
            .fold(1.0, f32::min)
    }
}

/// The buffers a frame's views fit their LoD into (`lod_pressure.comp`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ViewBudgets {
    /// Software rasterizer segments per view (0: no software rasterizer).
    pub segments: u32,
    /// Compute path: vertex-pool slots per view (0: the frame drew no pool).
    pub pool: u32,
}

impl ViewBudgets {
    /// The share of its strands a view with statistics `s` kept (the smaller of the software
    /// and the pool share; `reference::lod::lod_pressure`).
    pub fn pressure(&self, s: &FrameStats) -> f32 {
        use crate::reference::lod::lod_pressure;
        let soft = lod_pressure(s.soft_demand, s.soft_slack, self.segments);
        let pool = match self.pool {
            0 => 1.0,
            slots => lod_pressure(s.pool_demand, s.pool_slack, slots),
        };
        soft.min(pool)
    }
}

/// Work a frame's fixed-size buffers had no room for: counted on the GPU, never silent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dropped {
    /// Strands the LoD asked for that the compute path's vertex pool could not hold.
    pub strands: u32,
    /// Software rasterizer segments past the segment budget.
    pub segments: u32,
    /// Software rasterizer (tile, segment) entries past the entry budget: the fragments those
    /// segments would have made in those tiles.
    pub tile_entries: u32,
}

impl Dropped {
    /// What one view's statistics say was dropped.
    pub fn of(s: &FrameStats) -> Self {
        Dropped {
            strands: s.strands_demanded.saturating_sub(s.strands_drawn),
            segments: s.segments_demanded.saturating_sub(s.segments_written),
            tile_entries: s
                .tile_entries_demanded
                .saturating_sub(s.tile_entries_written),
        }
    }

    /// Both views' drops.
    pub fn plus(self, o: Dropped) -> Self {
        Dropped {
            strands: self.strands.saturating_add(o.strands),
            segments: self.segments.saturating_add(o.segments),
            tile_entries: self.tile_entries.saturating_add(o.tile_entries),
        }
    }

    /// Whether anything was dropped.
    pub fn any(&self) -> bool {
        *self != Dropped::default()
    }
}

impl std::fmt::Display for Dropped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} strands, {} segments, {} tile entries (fragments) dropped",
            self.strands, self.segments, self.tile_entries
        )
    }
}

pub(crate) struct Pending {
    pub frame: u64,
    pub path: RenderPath,
    pub width: u32,
    pub height: u32,
    pub record_ms: f64,
    pub read_image: bool,
    pub read_motion: bool,
    /// The frame graph's description, when asked for.
    pub frame_graph: Option<String>,
    /// Volume-only and blended characters.
    pub volume_characters: (u32, u32),
    /// The frame probed roots (`FrameOptions::probe_roots`) of this many bundles.
    pub probe_roots: Option<u32>,
    /// Commands recorded outside every timing scope.
    pub unscoped_commands: u32,
    /// The buffers the views' LoD had to fit.
    pub budgets: ViewBudgets,
}

/// One frame in flight.
pub(crate) struct FrameSlot {
    pub cmd: CommandBuffer,
    pub fence: Fence,
    pub frame_ubo: Buffer,
    /// The light's frame block (shadow passes).
    pub light_ubo: Buffer,
    pub records: Buffer,
    pub prop_instances: Buffer,
    /// This frame's skin matrices and skinning jobs (host-visible), and posed vertices.
    pub skin_matrices: Buffer,
    pub skin_jobs: Buffer,
    pub skinned: Buffer,
    /// The root probe's output (host-visible), sized for the crowd's bundles.
    pub root_probe: Buffer,
    pub stats_readback: Buffer,
    pub image_readback: Option<Buffer>,
    /// Motion vectors for the host (`uvec4` per pixel), when asked for.
    pub motion_readback: Option<Buffer>,
    pub profiler: Profiler,
    pub mesh_query: Option<MeshPrimitivesQuery>,
    pub set: DescriptorSet,
    /// Set 0 of the shadow passes: as `set`, with `light_ubo` as the frame block.
    pub light_set: DescriptorSet,
    pub retired: Vec<Retired>,
    pub pending: Option<Pending>,
    /// The GPU hair dynamics' job table (host-visible, read by address), once needed.
    pub sim_jobs: Option<Buffer>,
    /// The density volume builds' job table (grown as needed).
    pub density_jobs: Option<Buffer>,
}

impl FrameSlot {
    pub fn new(ctx: &Arc<Context>, layout: &Arc<DescriptorSetLayout>) -> GpuResult<Self> {
        Ok(FrameSlot {
            cmd: CommandBuffer::new(ctx, "frame")?,
            fence: Fence::new(ctx, true)?,
            frame_ubo: frame_block_buffer(ctx, "frame block")?,
            light_ubo: frame_block_buffer(ctx, "light frame block")?,
            records: records_buffer(ctx, 1)?,
            prop_instances: prop_instance_buffer(ctx, 1)?,
            skin_matrices: host_table(ctx, "skin matrices", 64)?,
            skin_jobs: host_table(ctx, "skin jobs", 16)?,
            skinned: skinned_buffer(ctx, 1)?,
            root_probe: host_table(ctx, "root probe", 16)?,
            stats_readback: Buffer::new(
                ctx,
                &BufferDesc::new(
                    "stats readback",
                    size_of::<GenerateArgs>() as u64,
                    vk::BufferUsageFlags::TRANSFER_DST,
                )
                .readback(),
            )?,
            image_readback: None,
            motion_readback: None,
            profiler: Profiler::new(ctx)?,
            mesh_query: MeshPrimitivesQuery::new(ctx)?,
            set: DescriptorSet::new(ctx, "frame set", layout)?,
            light_set: DescriptorSet::new(ctx, "light frame set", layout)?,
            retired: Vec::new(),
            pending: None,
            sim_jobs: None,
            density_jobs: None,
        })
    }

    /// The report of this slot's completed frame `p`: its statistics, timings and what it
    /// read back.
    pub fn report(&mut self, p: Pending) -> GpuResult<FrameReport> {
        let args: GenerateArgs = bytemuck::pod_read_unaligned(&self.stats_readback.read()?);
        let rgba = match (&mut self.image_readback, p.read_image) {
            (Some(b), true) => Some(b.read_range(0, (p.width * p.height * 4) as usize)?),
            _ => None,
        };
        let motion = match (&mut self.motion_readback, p.read_motion) {
            (Some(b), true) => {
                let bytes = b.read_range(0, (p.width * p.height * 16) as usize)?;
                let words: &[[u32; 4]] = bytemuck::cast_slice(&bytes);
                Some(words.iter().copied().map(PixelMotion::from_words).collect())
            }
            _ => None,
        };
        let roots = match p.probe_roots {
            Some(n) => {
                let bytes = self.root_probe.read_range(0, n as usize * 16)?;
                Some(bytemuck::pod_collect_to_vec(&bytes))
            }
            None => None,
        };
        let mesh_primitives = match (&self.mesh_query, p.path) {
            (Some(q), RenderPath::Mesh) => q.result()?,
            _ => None,
        };
        let times = self.profiler.results()?;
        Ok(FrameReport {
            frame: p.frame,
            path: p.path,
            width: p.width,
            height: p.height,
            stats: args.stats,
            light_stats: args.light_stats,
            budgets: p.budgets,
            pass_ms: times.scopes,
            frame_ms: times.frame_ms,
            unscoped_commands: p.unscoped_commands,
            mesh_primitives,
            record_ms: p.record_ms,
            rgba,
            motion,
            frame_graph: p.frame_graph,
            volume_characters: p.volume_characters,
            roots,
        })
    }
}

/// A host-visible uniform buffer for one `FrameBlock`.
fn frame_block_buffer(ctx: &Arc<Context>, name: &str) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(
            name,
            size_of::<FrameBlock>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )
        .host_visible(),
    )
}

/// A host-visible buffer for `n` prop instances.
/// A host-visible storage buffer of `bytes` (at least 1 element's worth).
pub(crate) fn host_table(ctx: &Arc<Context>, name: &'static str, bytes: u64) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(name, bytes.max(16), vk::BufferUsageFlags::STORAGE_BUFFER).host_visible(),
    )
}

/// A device-local buffer for `n` posed vertices (written by the skinning pass).
pub(crate) fn skinned_buffer(ctx: &Arc<Context>, n: u32) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(
            "skinned vertices",
            n.max(1) as u64 * size_of::<super::shared::SkinnedVertex>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
        ),
    )
}

pub(crate) fn prop_instance_buffer(ctx: &Arc<Context>, n: u32) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(
            "prop instances",
            n.max(1) as u64 * size_of::<super::shared::PropInstance>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )
        .host_visible(),
    )
}

/// A host-visible buffer for `n` character records.
pub(crate) fn records_buffer(ctx: &Arc<Context>, n: u32) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(
            "character records",
            n.max(1) as u64 * size_of::<CharacterRecord>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )
        .host_visible(),
    )
}

/// One pixel of the motion target as read back.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelMotion {
    /// This frame's position minus the previous frame's, pixels.
    pub motion: Vec2,
    /// Visibility id of the nearest surface ([`VISIBILITY_EMPTY`](super::shared::VISIBILITY_EMPTY): none).
    pub id: u32,
    /// Depth (0..1) of the nearest surface (1 where none).
    pub depth: f32,
}
