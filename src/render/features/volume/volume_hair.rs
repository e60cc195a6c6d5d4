//! The volume tier's far hair (seed 002, vkhr sec. 4; `glsl/volume_hair.vert`,
//! `glsl/volume_hair.frag`): each character with a share of volume this frame draws its
//! density volume's box, whose fragments march the view ray through the volume and write the
//! shaded hair premultiplied over the target at the hair's mean depth. Drawn after the opaque
//! pass (whose MSAA resolve it then makes); with the software rasterizer, the march ends at the
//! opaque depth, copied into its buffer first. Reads: frame block, character records, the
//! light's maps, the density volumes (by device address). Writes: colour and depth (and the
//! visibility words in frames with motion vectors).

use std::sync::Arc;

use crate::render::core::binding::{PassSets, device_shader_options};
use crate::render::core::frame_res::{FrameRes, add_depth_copy};
use crate::render::core::graph::FrameGraph;
use crate::render::core::pipelines::{DrawTarget, TargetFormats};
use crate::vk::shader::compile;
use crate::vk::{
    Access, Attachment, BlendMode, Context, CullMode, GpuResult, Pipeline, PipelineLayout,
};

/// Vertices of one character's box.
const BOX_VERTICES: u32 = 36;

/// The volume hair pipeline.
pub struct VolumeHairDraw {
    pipeline: Pipeline,
}

impl VolumeHairDraw {
    /// Compile the pipeline for the given target formats.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        targets: TargetFormats,
    ) -> GpuResult<Self> {
        let opts = device_shader_options(ctx, 1);
        let v = compile("volume_hair.vert", &opts)?;
        let f = compile("volume_hair.frag", &opts)?;
        let desc = DrawTarget::Camera(targets)
            .graphics_desc("volume hair")
            .blend(BlendMode::PremultipliedOver)
            .cull(CullMode::Front)
            .stage(ash::vk::ShaderStageFlags::VERTEX, &v)
            .stage(ash::vk::ShaderStageFlags::FRAGMENT, &f);
        Ok(VolumeHairDraw {
            pipeline: Pipeline::graphics(ctx, layout, &desc)?,
        })
    }

    /// Add the pass drawing the volumes of the first `slots` character slots (characters
    /// without a share of volume get no triangles) over the colour and depth, ending with the
    /// colour's MSAA resolve when `resolve`. With `soft` (the camera's strands go through the
    /// software rasterizer, so the frame has its depth buffer) the opaque depth is copied
    /// there first, and each ray's march ends at the surface its pixel shows.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        slots: u32,
        (resolve, soft): (bool, bool),
    ) {
        g.begin_scope("volume hair");
        if soft {
            add_depth_copy(g, r, "volume depth copy");
        }
        let mut p = g
            .pass("volume hair")
            .read_some(Some(r.soft_depth).filter(|_| soft), Access::FragmentRead)
            .write(r.color, Access::ColorAttachment)
            .write(r.depth, Access::DepthAttachment)
            .read(r.constants, Access::VertexRead)
            .read(r.constants, Access::FragmentRead)
            .write_some(r.visibility, Access::FragmentReadWrite);
        let resolve_into = r.images.resolved.filter(|_| resolve);
        if let (Some(res), true) = (r.resolved, resolve) {
            p = p.discard(res, Access::ColorAttachment);
        }
        let (color, depth) = (r.images.color, r.images.depth);
        r.shading_uses(p, Access::FragmentRead)
            .record(move |rec, _| {
                rec.begin_rendering(
                    Attachment {
                        image: color,
                        clear: None,
                        resolve: resolve_into,
                    },
                    Attachment {
                        image: depth,
                        clear: None,
                        resolve: None,
                    },
                );
                rec.bind(&self.pipeline, &sets.both());
                rec.draw_instanced(BOX_VERTICES, slots, 0, 0);
                rec.end_rendering();
                Ok(())
            });
        g.end_scope();
    }
}
