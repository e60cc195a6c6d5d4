//! Strand strips: the compute path's vertex-pulling draw (one indirect draw for the crowd) and
//! the mesh path's task + mesh pipeline (one task dispatch for the crowd, `TASK_BUNDLES`
//! bundles per task workgroup). [`strand_uses`] declares what a strand draw reads and
//! writes on each path.

use std::sync::Arc;

use ash::vk;

use super::{DrawTarget, FrameRes, PassSets, TemporalRes, device_shader_options, dispatch_2d};
use crate::render::RenderPath;
use crate::render::core::graph::PassBuilder;
use crate::render::core::shared::{
    DISPATCH_ROW, GenerateArgs, MAX_SEGMENTS, STRAND_GROUP_SIZE, TASK_PAYLOAD_BUNDLES, TaskPayload,
};
use crate::vk::Access;
use crate::vk::shader::compile;
use crate::vk::{Buffer, CommandRecorder, Context, GpuError, GpuResult, Pipeline, PipelineLayout};

/// Whether the device's mesh shader limits fit `strands.task` / `strands.mesh`.
pub fn mesh_path_supported(ctx: &Context) -> bool {
    let max_groups_per_task =
        TASK_PAYLOAD_BUNDLES * crate::bake::blue_noise::MAX_STRANDS_PER_BUNDLE as u32;
    ctx.info.mesh_limits.is_some_and(|l| {
        l.max_mesh_output_vertices >= 2 * (MAX_SEGMENTS + 1)
            && l.max_mesh_output_primitives >= 2 * MAX_SEGMENTS
            && l.max_task_payload_size as usize >= size_of::<TaskPayload>()
            && l.max_mesh_work_group_invocations >= STRAND_GROUP_SIZE
            && l.max_task_work_group_invocations >= TASK_PAYLOAD_BUNDLES
            && l.max_mesh_work_group_total_count >= max_groups_per_task
            && l.max_mesh_work_group_count[0] >= DISPATCH_ROW
            && l.max_mesh_work_group_count[1] >= max_groups_per_task.div_ceil(DISPATCH_ROW)
            && l.max_task_work_group_count[0] >= DISPATCH_ROW
            && l.max_task_work_group_count[1] >= DISPATCH_ROW
    })
}

/// Strand pipelines.
pub struct StrandDraw {
    pulled: Pipeline,
    mesh: Option<Pipeline>,
    task_bundles: u32,
}

impl StrandDraw {
    /// Compile the pulled-strand pipeline and, where the device supports it, the mesh path
    /// with `task_bundles` (1..=32) bundles per task workgroup, drawing into `target`: shaded
    /// strips for the camera, depth for the light, or opacity into the deep opacity layers.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        target: DrawTarget,
        task_bundles: u32,
    ) -> GpuResult<Self> {
        if !(1..=TASK_PAYLOAD_BUNDLES).contains(&task_bundles) {
            return Err(GpuError::Unsupported(format!(
                "task bundles per workgroup must be 1..={TASK_PAYLOAD_BUNDLES}"
            )));
        }
        let opts = device_shader_options(ctx, task_bundles);
        let frag = target.strand_fragment_shader();
        let v = compile("strands.vert", &opts)?;
        let f = frag.map(|f| compile(f, &opts)).transpose()?;
        let with_fragment =
            |desc: crate::vk::GraphicsDesc<'static>| -> crate::vk::GraphicsDesc<'_> {
                match &f {
                    Some(f) => desc.stage(vk::ShaderStageFlags::FRAGMENT, f),
                    None => desc,
                }
            };
        let pulled = Pipeline::graphics(
            ctx,
            layout,
            &with_fragment(target.graphics_desc("pulled strands"))
                .stage(vk::ShaderStageFlags::VERTEX, &v),
        )?;
        let mesh = if mesh_path_supported(ctx) {
            let (t, m) = (
                compile("strands.task", &opts)?,
                compile("strands.mesh", &opts)?,
            );
            Some(Pipeline::graphics(
                ctx,
                layout,
                &with_fragment(target.graphics_desc("mesh strands"))
                    .stage(vk::ShaderStageFlags::TASK_EXT, &t)
                    .stage(vk::ShaderStageFlags::MESH_EXT, &m),
            )?)
        } else {
            None
        };
        Ok(StrandDraw {
            pulled,
            mesh,
            task_bundles,
        })
    }

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.mesh.is_some()
    }

    /// Compute path: draw the strands in the vertex pool (inside rendering).
    pub fn record_pulled(&self, rec: &mut CommandRecorder, sets: PassSets, args: &Buffer) {
        rec.bind(&self.pulled, &sets.both());
        rec.draw_indirect(args, GenerateArgs::DRAW_OFFSET);
    }

    /// Draw the crowd's strands as `path` does (inside rendering): the mesh path generates
    /// `bundles` bundles in its task and mesh shaders; the other paths pull the vertex pool
    /// with `args`' draw arguments.
    pub fn record(
        &self,
        rec: &mut CommandRecorder,
        sets: PassSets,
        bundles: u32,
        path: crate::render::RenderPath,
        args: &Buffer,
    ) -> GpuResult<()> {
        if path.pulls_vertices() {
            self.record_pulled(rec, sets, args);
            Ok(())
        } else {
            self.record_mesh(rec, sets, bundles)
        }
    }

    /// Mesh path: generate and draw the strands of `bundles` bundles as the view's bundle LoD
    /// pass decided (inside rendering).
    pub fn record_mesh(
        &self,
        rec: &mut CommandRecorder,
        sets: PassSets,
        bundles: u32,
    ) -> GpuResult<()> {
        let p = self
            .mesh
            .as_ref()
            .ok_or_else(|| GpuError::Unsupported("no usable VK_EXT_mesh_shader".into()))?;
        rec.bind(p, &sets.both());
        let (x, y) = dispatch_2d(bundles.div_ceil(self.task_bundles));
        rec.draw_mesh_tasks(x, y, 1)
    }
}

/// Which view a strand draw serves, and whether its fragments are lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrandUse {
    /// The light's view: depth and opacity only.
    Light,
    /// The camera's view, depth only (depth peeling's layer pass).
    CameraDepth,
    /// The camera's view, lit (shadow maps, shading table).
    CameraShaded,
}

/// Declare what drawing the strands as `path` does reads and writes (beside the pass's
/// targets): the pulled paths read the vertex pool, LoDs and offsets and the draw arguments
/// (and in the camera's view the vertices' deformation residuals); the mesh path's task
/// shaders read the bundle LoDs (`bundle_lod.rs`) and add to the statistics, its mesh shaders
/// the textures.
pub fn strand_uses<'g, 'a>(
    p: PassBuilder<'g, 'a>,
    r: &FrameRes,
    path: RenderPath,
    used: StrandUse,
) -> PassBuilder<'g, 'a> {
    let residuals = match used {
        StrandUse::Light => None,
        _ => TemporalRes::vertex_motion(r.temporal),
    };
    let p = if path.pulls_vertices() {
        p.read(r.constants, Access::VertexRead)
            .read_all(&[r.pool, r.lods, r.offsets], Access::VertexRead)
            .read_some(residuals, Access::VertexRead)
            .read(r.args, Access::IndirectRead)
    } else {
        p.read_all(&[r.constants, r.textures, r.lods], Access::TaskRead)
            .read(r.textures, Access::MeshRead)
            .write(r.args, Access::TaskReadWrite)
    };
    if used == StrandUse::CameraShaded {
        r.shading_uses(p, Access::FragmentRead)
    } else {
        p
    }
}
