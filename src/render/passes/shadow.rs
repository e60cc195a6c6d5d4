//! The light's passes (deep opacity maps / approximate deep shadow maps, `render::shadow`):
//! the props' depth, the hair's depth, and for deep opacity maps the hair's opacity in
//! layers behind that depth. The hair is generated for the light's view by the same task +
//! mesh shaders, or drawn from the vertex pool the compute path generated for the light.
//! What each pass reads and writes is declared where it is added to the frame graph.

use std::sync::Arc;

use super::props::{PropList, PropPass};
use super::strands::{StrandDraw, StrandUse, strand_uses};
use super::{DrawTarget, FrameRes, PassSets};
use crate::render::RenderPath;
use crate::render::core::graph::FrameGraph;
use crate::render::shadow::ShadowMode;
use crate::vk::{Access, Attachment, Context, GpuResult, PipelineLayout};

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
    /// Props (bodies) that cast shadows.
    pub props: PropList<'a>,
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

    /// Add the light's passes: the props' depth, the hair's depth and, for deep opacity
    /// maps, the hair's opacity layers; every map ends up sampled by the camera's passes.
    pub fn add<'a>(&'a self, g: &mut FrameGraph<'a>, r: &FrameRes<'a>, d: ShadowDraw<'a>) {
        let [hair, _, layers] = r.shadow;
        g.begin_scope("shadow draw");
        self.add_props(g, r, &d);
        let sets = d.sets;
        let [hair_image, _, layers_image] = r.images.shadow;
        let p = g
            .pass("shadow hair depth")
            .discard(hair, Access::DepthAttachment);
        let (path, bundles, args) = (d.path, d.bundles, r.args_buffer);
        strand_uses(p, r, path, StrandUse::Light).record(move |rec, _| {
            rec.begin_rendering_depth(Attachment {
                image: hair_image,
                clear: Some([1.0; 4]),
                resolve: None,
            });
            let result = match bundles {
                0 => Ok(()),
                _ => self.depth.record(rec, sets, bundles, path, args),
            };
            rec.end_rendering();
            result
        });
        if d.mode == ShadowMode::DeepOpacity {
            let p = g
                .pass("shadow opacity")
                .read(hair, Access::SampledRead)
                .discard(layers, Access::ColorAttachment);
            strand_uses(p, r, path, StrandUse::Light).record(move |rec, _| {
                rec.begin_rendering_color(Attachment {
                    image: layers_image,
                    clear: Some([0.0; 4]),
                    resolve: None,
                });
                let result = match bundles {
                    0 => Ok(()),
                    _ => self.opacity.record(rec, sets, bundles, path, args),
                };
                rec.end_rendering();
                result
            });
        }
        g.end_scope();
    }

    /// Add the props' depth pass of the light (hardware triangles; both light rasters).
    pub fn add_props<'a>(&'a self, g: &mut FrameGraph<'a>, r: &FrameRes<'a>, d: &ShadowDraw<'a>) {
        let (sets, props) = (d.sets, d.props);
        let prop_image = r.images.shadow[1];
        g.pass("shadow props")
            .read(r.constants, Access::VertexRead)
            .read(r.skinned, Access::VertexRead)
            .discard(r.shadow[1], Access::DepthAttachment)
            .record(move |rec, _| {
                rec.begin_rendering_depth(Attachment {
                    image: prop_image,
                    clear: Some([1.0; 4]),
                    resolve: None,
                });
                self.props.record(rec, sets, props);
                rec.end_rendering();
                Ok(())
            });
    }
}
