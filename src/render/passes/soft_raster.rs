//! The software rasterizer's passes (`render::soft`), after the strands' generation (which
//! appended the segments) and any hardware strand passes of the frame: the opaque depth is
//! copied out, the segments are binned into tiles (count, scan, scatter) and each tile is
//! rasterized into the frame's k-buffer, which the transparency resolve then composites.
//! What each step reads and writes is declared where it is added to the frame graph.

use std::sync::Arc;

use super::{FrameRes, PassSets, TemporalRes, add_depth_copy, device_shader_options, dispatch_2d};
use crate::render::core::graph::FrameGraph;
use crate::render::core::shared::GenerateArgs;
use crate::render::soft::tile_grid;
use crate::vk::shader::compile;
use crate::vk::{Access, Context, GpuResult, Pipeline, PipelineLayout};

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
            let opts = device_shader_options(ctx, task_bundles).define("SOFT_PASS", 1);
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
        let opts = device_shader_options(ctx, 1);
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

    /// Mesh path: add the pass that builds the software bundles of `bundles` bundles in task
    /// and mesh shaders and appends their segments (compute generation appends them in
    /// `generate.comp`), timed as `scope`, for the view of `sets` (the camera's, or the
    /// light's for the software shadows).
    pub fn add_mesh_segments<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        (sets, scope): (PassSets<'a>, &'static str),
        bundles: u32,
        size: (u32, u32),
    ) {
        let task_bundles = self.task_bundles;
        let pipeline = self.mesh_segments.as_ref();
        g.begin_scope(scope);
        let p = g
            .pass("soft segments (mesh)")
            .read_all(&[r.constants, r.textures, r.lods], Access::TaskRead)
            .read(r.textures, Access::MeshRead)
            .write(r.args, Access::TaskReadWrite)
            .write(r.args, Access::MeshReadWrite)
            .write(r.soft_segments, Access::MeshReadWrite)
            .write_some(
                TemporalRes::segment_motion(r.temporal),
                Access::MeshReadWrite,
            );
        r.shading_uses(p, Access::MeshRead).record(move |rec, _| {
            let p = pipeline.ok_or_else(|| {
                crate::vk::GpuError::Unsupported("no usable VK_EXT_mesh_shader".into())
            })?;
            rec.begin_rendering_empty(size.0, size.1);
            rec.bind(p, &sets.both());
            let (x, y) = dispatch_2d(bundles.div_ceil(task_bundles));
            let result = rec.draw_mesh_tasks(x, y, 1);
            rec.end_rendering();
            result
        });
        g.end_scope();
    }

    /// Add the binning and raster of the segments generation appended this frame. The
    /// k-buffer must be cleared (or hold this frame's hardware fragments) before.
    /// `copy_depth`: copy the opaque depth target into the soft depth first (otherwise the
    /// caller filled it).
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        size: (u32, u32),
        copy_depth: bool,
    ) {
        let (tx, ty) = tile_grid(size.0, size.1);
        let rw = Access::ComputeReadWrite;
        g.begin_scope("soft bin");
        if copy_depth {
            add_depth_copy(g, r, "soft depth copy");
        }
        self.add_binning(g, r, sets, size);
        g.end_scope();
        g.begin_scope("soft raster");
        g.pass("soft raster")
            .read(r.constants, Access::ComputeRead)
            .read_all(&[r.soft_segments, r.soft_tiles], Access::ComputeRead)
            .read_all(&[r.soft_entries, r.soft_depth], Access::ComputeRead)
            .write(r.args, rw)
            .write(r.oit_nodes, rw)
            .write(r.oit_tail, rw)
            .write_some(r.visibility, rw)
            .read_some(TemporalRes::segment_motion(r.temporal), Access::ComputeRead)
            .record(move |rec, _| {
                rec.bind(&self.raster, &sets.both());
                rec.dispatch(tx, ty, 1);
                Ok(())
            });
        g.end_scope();
    }

    /// Add the binning of the segments appended this frame into the tiles of a
    /// `size` view (the camera's target, or the light's map with the light's sets): the tile
    /// table cleared, the dispatch sized, segments counted per tile, the tiles' ranges
    /// scanned, segment indices scattered into them.
    pub fn add_binning<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        size: (u32, u32),
    ) {
        let (tx, ty) = tile_grid(size.0, size.1);
        let rw = Access::ComputeReadWrite;
        let (args, soft_tiles) = (r.args_buffer, r.soft_tiles);
        g.pass("soft tiles clear")
            .discard(r.soft_tiles, Access::TransferWrite)
            .record(move |rec, res| {
                rec.fill_buffer(res.buffer(soft_tiles)?, 0, tx as u64 * ty as u64 * 16, 0);
                Ok(())
            });
        g.pass("soft bin args")
            .read(r.constants, Access::ComputeRead)
            .write(r.args, rw)
            .record(move |rec, _| {
                rec.bind(&self.bin_args, &sets.both());
                rec.dispatch(1, 1, 1);
                Ok(())
            });
        let bin = |g: &mut FrameGraph<'a>, name, pipeline: &'a Pipeline, scatter: bool| {
            let mut p = g
                .pass(name)
                .read(r.constants, Access::ComputeRead)
                .read(r.soft_segments, Access::ComputeRead)
                .read(r.args, Access::IndirectRead)
                .write(r.args, rw)
                .write(r.soft_tiles, rw);
            if scatter {
                p = p.discard(r.soft_entries, rw);
            }
            p.record(move |rec, _| {
                rec.bind(pipeline, &sets.both());
                rec.dispatch_indirect(args, GenerateArgs::SOFT_DISPATCH_OFFSET);
                Ok(())
            });
        };
        bin(g, "soft bin count", &self.count, false);
        g.pass("soft tile scan")
            .read(r.constants, Access::ComputeRead)
            .write(r.soft_tiles, rw)
            .write(r.args, rw)
            .record(move |rec, _| {
                rec.bind(&self.scan, &sets.both());
                rec.dispatch(1, 1, 1);
                Ok(())
            });
        bin(g, "soft bin scatter", &self.scatter, true);
    }
}
