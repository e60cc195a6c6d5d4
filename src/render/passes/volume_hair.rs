//! The volume tier's far hair (seed 002, vkhr sec. 4; `glsl/volume_hair.vert`,
//! `glsl/volume_hair.frag`): each character with a share of volume this frame draws its
//! density volume's box, whose fragments march the view ray through the volume and write the
//! shaded hair premultiplied over the target at the hair's mean depth. Drawn inside the
//! opaque pass after the strands. Reads: frame block, character records, the light's maps,
//! the density volumes (by device address). Writes: colour and depth (and the visibility
//! words in frames with motion vectors).

use std::sync::Arc;

use super::{DrawTarget, PassSets, TargetFormats, device_shader_options};
use crate::vk::shader::compile;
use crate::vk::{BlendMode, CommandRecorder, Context, GpuResult, Pipeline, PipelineLayout};

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
            .stage(ash::vk::ShaderStageFlags::VERTEX, &v)
            .stage(ash::vk::ShaderStageFlags::FRAGMENT, &f);
        Ok(VolumeHairDraw {
            pipeline: Pipeline::graphics(ctx, layout, &desc)?,
        })
    }

    /// Draw the volumes of the first `slots` character slots (inside rendering; characters
    /// without a share of volume get no triangles).
    pub fn record(&self, rec: &mut CommandRecorder, sets: PassSets, slots: u32) {
        rec.bind(&self.pipeline, &sets.both());
        rec.draw_instanced(BOX_VERTICES, slots, 0, 0);
    }
}
