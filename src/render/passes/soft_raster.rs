//! The software rasterizer's passes (`render::soft`), after the strands' generation (which
//! appended the segments) and any hardware strand passes of the frame: the opaque depth is
//! copied out, the segments are binned into tiles (count, scan, scatter) and each tile is
//! rasterized into the frame's k-buffer, which the transparency resolve then composites.
//! Reads: frame block, `GenerateArgs` (segment count), the segments, the depth target.
//! Writes: the tile table and entries, the soft depth copy, the k-buffer nodes and tail,
//! `GenerateArgs` (binning dispatch, statistics).

use std::sync::Arc;

use super::{PassSets, dispatch_2d, shader_options};
use crate::render::shared::GenerateArgs;
use crate::render::soft::{SoftBuffers, tile_grid};
use crate::render::targets::RenderTargets;
use crate::vk::shader::compile;
use crate::vk::{
    Access, Buffer, CommandRecorder, Context, GpuResult, Pipeline, PipelineLayout, Profiler,
};

/// What one frame's software raster reads and writes.
pub struct SoftDraw<'a> {
    /// Camera sets (the frame block carries the budgets and the tile grid).
    pub sets: PassSets<'a>,
    /// `GenerateArgs`: segments appended, binning dispatch, statistics.
    pub args: &'a Buffer,
    /// The soft buffers (segments, tiles, entries, depth copy).
    pub buffers: &'a SoftBuffers,
    /// Depth target after the opaque pass (single sample); `None`: the depth copy was
    /// filled by the caller.
    pub targets: Option<&'a mut RenderTargets>,
    /// Target size.
    pub size: (u32, u32),
}

/// The pipelines of the software rasterizer.
pub struct SoftRasterPass {
    /// Mesh path: task + mesh shaders (`SOFT_PASS`) that build the software bundles' strands
    /// and append their segments, drawing nothing.
    mesh_segments: Option<Pipeline>,
    task_bundles: u32,
    bin_args: Pipeline,
    count: Pipeline,
    scan: Pipeline,
    scatter: Pipeline,
    raster: Pipeline,
}

impl SoftRasterPass {
    /// Compile the pipelines (the raster needs 64-bit shared atomics: the caller creates this
    /// pass only on devices that have them); the mesh-path segment pass where the mesh path
    /// is supported, with `task_bundles` bundles per task workgroup.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        task_bundles: u32,
    ) -> GpuResult<Self> {
        let mesh_segments = if super::strands::mesh_path_supported(ctx) {
            let opts = shader_options(task_bundles).define("SOFT_PASS", 1);
            let (task, mesh) = (
                compile("strands.task", &opts)?,
                compile("strands.mesh", &opts)?,
            );
            let desc = crate::vk::GraphicsDesc::new(
                "soft segments (mesh)",
                ash::vk::Format::UNDEFINED,
                ash::vk::Format::UNDEFINED,
            )
            .depth(crate::vk::DepthMode::Off)
            .stage(ash::vk::ShaderStageFlags::TASK_EXT, &task)
            .stage(ash::vk::ShaderStageFlags::MESH_EXT, &mesh);
            Some(Pipeline::graphics(ctx, layout, &desc)?)
        } else {
            None
        };
        let opts = shader_options(1);
        let p = |name: &str, file: &str, scatter: bool| {
            let o = if scatter {
                opts.clone().define("SCATTER", 1)
            } else {
                opts.clone()
            };
            Pipeline::compute(ctx, name, layout, &compile(file, &o)?)
        };
        Ok(SoftRasterPass {
            mesh_segments,
            task_bundles,
            bin_args: p("soft bin args", "soft_bin_args.comp", false)?,
            count: p("soft bin count", "soft_bin.comp", false)?,
            scan: p("soft tile scan", "soft_tile_scan.comp", false)?,
            scatter: p("soft bin scatter", "soft_bin.comp", true)?,
            raster: p("soft raster", "soft_raster.comp", false)?,
        })
    }

    /// Mesh path: build the software bundles of `bundles` bundles in task and mesh shaders and
    /// append their segments (compute generation appends them in `generate.comp`).
    pub fn record_mesh_segments(
        &self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        sets: PassSets,
        bundles: u32,
        size: (u32, u32),
    ) -> GpuResult<()> {
        let p = self.mesh_segments.as_ref().ok_or_else(|| {
            crate::vk::GpuError::Unsupported("no usable VK_EXT_mesh_shader".into())
        })?;
        profiler.begin(rec, "soft segments");
        rec.barrier(
            &[Access::TransferWrite, Access::ComputeReadWrite],
            &[Access::TaskReadWrite, Access::MeshReadWrite],
        );
        rec.begin_rendering_empty(size.0, size.1);
        rec.bind(p, &sets.both());
        let (x, y) = dispatch_2d(bundles.div_ceil(self.task_bundles));
        let result = rec.draw_mesh_tasks(x, y, 1);
        rec.end_rendering();
        profiler.end(rec);
        result
    }

    /// Record the binning and raster of the segments generation appended this frame. The
    /// k-buffer must be cleared (or hold this frame's hardware fragments) before.
    pub fn record(&self, rec: &mut CommandRecorder, profiler: &mut Profiler, draw: SoftDraw) {
        let b = draw.buffers;
        let (tx, ty) = tile_grid(draw.size.0, draw.size.1);
        let rw = [Access::ComputeReadWrite];
        profiler.begin(rec, "soft bin");
        rec.barrier(
            &[
                Access::ComputeReadWrite,
                Access::TransferRead,
                Access::IndirectRead,
            ],
            &[Access::TransferWrite],
        );
        if let Some(t) = draw.targets {
            rec.image_barrier(&t.depth, t.depth_access, Access::TransferRead);
            rec.copy_image_to_buffer_at(&t.depth, &b.depth, 0);
            t.depth_access = Access::TransferRead;
        }
        rec.fill_buffer(&b.tiles, 0, tx as u64 * ty as u64 * 16, 0);
        // Segments come from compute generation or from the mesh shaders of the draw passes.
        rec.barrier(
            &[
                Access::TransferWrite,
                Access::ComputeReadWrite,
                Access::MeshReadWrite,
                Access::TaskReadWrite,
            ],
            &rw,
        );
        rec.bind(&self.bin_args, &draw.sets.both());
        rec.dispatch(1, 1, 1);
        rec.barrier(&rw, &[Access::ComputeReadWrite, Access::IndirectRead]);
        rec.bind(&self.count, &draw.sets.both());
        rec.dispatch_indirect(draw.args, GenerateArgs::SOFT_DISPATCH_OFFSET);
        rec.barrier(&rw, &rw);
        rec.bind(&self.scan, &draw.sets.both());
        rec.dispatch(1, 1, 1);
        // The scan writes `GenerateArgs` statistics beside the scatter's indirect arguments.
        rec.barrier(&rw, &[Access::ComputeReadWrite, Access::IndirectRead]);
        rec.bind(&self.scatter, &draw.sets.both());
        rec.dispatch_indirect(draw.args, GenerateArgs::SOFT_DISPATCH_OFFSET);
        profiler.end(rec);
        // The k-buffer may hold this frame's hardware transparent fragments.
        rec.barrier(&[Access::ComputeReadWrite, Access::FragmentReadWrite], &rw);
        profiler.begin(rec, "soft raster");
        rec.bind(&self.raster, &draw.sets.both());
        rec.dispatch(tx, ty, 1);
        profiler.end(rec);
        rec.barrier(
            &rw,
            &[
                Access::FragmentReadWrite,
                Access::ComputeReadWrite,
                Access::TransferRead,
                Access::IndirectRead,
            ],
        );
    }
}
