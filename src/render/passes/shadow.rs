//! The light's passes (deep opacity maps / approximate deep shadow maps, `render::shadow`):
//! the props' depth, the hair's depth, and for deep opacity maps the hair's opacity in
//! layers behind that depth. The hair is generated for the light's view by the same task +
//! mesh shaders, or drawn from the vertex pool the compute path generated for the light.
//! Reads: the light's frame block (light set 0), character records, bundles, textures or the
//! vertex pool, prop meshes. Writes: the three shadow maps, left for sampling.

use std::sync::Arc;

use super::props::{PropDraw, PropPass};
use super::strands::StrandDraw;
use super::{DrawTarget, PassSets};
use crate::render::RenderPath;
use crate::render::shadow::ShadowMode;
use crate::render::targets::ShadowMaps;
use crate::vk::{
    Access, Attachment, Buffer, CommandRecorder, Context, GpuResult, PipelineLayout, Profiler,
};

/// What one frame's light passes draw.
pub struct ShadowDraw<'a> {
    /// Deep opacity (two hair passes) or approximate (one).
    pub mode: ShadowMode,
    /// Light set 0 and the texture set.
    pub sets: PassSets<'a>,
    /// Bundles of all characters.
    pub bundles: u32,
    /// Generation path (compute: the vertex pool already holds the light's strands).
    pub path: RenderPath,
    /// Indirect arguments of the compute path.
    pub args: &'a Buffer,
    /// Props (bodies) that cast shadows.
    pub props: &'a [PropDraw],
}

/// Pipelines of the light's passes.
pub struct ShadowPass {
    props: PropPass,
    depth: StrandDraw,
    opacity: StrandDraw,
}

impl ShadowPass {
    /// Compile the pipelines (mesh path ones where supported).
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        task_bundles: u32,
    ) -> GpuResult<Self> {
        Ok(ShadowPass {
            props: PropPass::new(ctx, layout, DrawTarget::ShadowDepth)?,
            depth: StrandDraw::new(ctx, layout, DrawTarget::ShadowDepth, task_bundles)?,
            opacity: StrandDraw::new(ctx, layout, DrawTarget::ShadowOpacity, task_bundles)?,
        })
    }

    fn strands(
        &self,
        draw: &StrandDraw,
        rec: &mut CommandRecorder,
        d: &ShadowDraw,
    ) -> GpuResult<()> {
        if d.bundles == 0 {
            return Ok(());
        }
        draw.record(rec, d.sets, d.bundles, d.path, d.args)
    }

    /// Record the light's passes into `maps` (which end up readable by the camera passes).
    pub fn record(
        &self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        maps: &mut ShadowMaps,
        d: ShadowDraw,
    ) -> GpuResult<()> {
        profiler.begin(rec, "shadow draw");
        // Earlier frames may still sample the maps: order after their reads.
        rec.image_barrier(&maps.prop_depth, maps.access[1], Access::DepthAttachment);
        rec.begin_rendering_depth(Attachment {
            image: &maps.prop_depth,
            clear: Some([1.0; 4]),
            resolve: None,
        });
        self.props.record(rec, d.sets, d.props);
        rec.end_rendering();
        rec.image_barrier(&maps.hair_depth, maps.access[0], Access::DepthAttachment);
        rec.begin_rendering_depth(Attachment {
            image: &maps.hair_depth,
            clear: Some([1.0; 4]),
            resolve: None,
        });
        let mut result = self.strands(&self.depth, rec, &d);
        rec.end_rendering();
        rec.image_barrier(
            &maps.hair_depth,
            Access::DepthAttachment,
            Access::SampledRead,
        );
        rec.image_barrier(
            &maps.prop_depth,
            Access::DepthAttachment,
            Access::SampledRead,
        );
        let layers_from = maps.access[2];
        if d.mode == ShadowMode::DeepOpacity && result.is_ok() {
            rec.image_barrier(&maps.layers, layers_from, Access::ColorAttachment);
            rec.begin_rendering_color(Attachment {
                image: &maps.layers,
                clear: Some([0.0; 4]),
                resolve: None,
            });
            result = self.strands(&self.opacity, rec, &d);
            rec.end_rendering();
            rec.image_barrier(&maps.layers, Access::ColorAttachment, Access::SampledRead);
        } else if layers_from != Access::SampledRead {
            // Unused in this mode, but the camera's shaders declare it: keep it readable.
            rec.image_barrier(&maps.layers, layers_from, Access::SampledRead);
        }
        maps.access = [Access::SampledRead; 3];
        profiler.end(rec);
        result
    }

    /// Without shadows this frame: leave every map in the layout the camera's shaders expect
    /// (their contents are not read).
    pub fn keep_readable(rec: &mut CommandRecorder, maps: &mut ShadowMaps) {
        let images = [&maps.hair_depth, &maps.prop_depth, &maps.layers];
        for (image, access) in images.into_iter().zip(maps.access.iter_mut()) {
            if *access != Access::SampledRead {
                rec.image_barrier(image, *access, Access::SampledRead);
                *access = Access::SampledRead;
            }
        }
    }
}
