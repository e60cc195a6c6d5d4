//! The opaque pass: props, scalps and the strands drawn opaque in hardware, into the
//! frame's colour and depth (the mesh path generates its strands inside it).

use std::sync::Arc;

use super::props::PropPass;
use super::scalp::ScalpPass;
use super::strands::{self, StrandDraw};
use super::{DrawTarget, FrameInputs, FrameRes, TargetFormats};
use crate::render::RenderPath;
use crate::render::core::graph::FrameGraph;
use crate::vk::{Access, Attachment, Context, GpuResult, MeshPrimitivesQuery, PipelineLayout};

/// The pipelines of the opaque pass.
pub struct OpaquePass {
    props: PropPass,
    scalp: ScalpPass,
    strands: StrandDraw,
}

impl OpaquePass {
    /// Compile the pass's pipelines for `targets`; the mesh path's with `task_bundles` bundles
    /// per task workgroup.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        targets: TargetFormats,
        task_bundles: u32,
    ) -> GpuResult<Self> {
        let camera = DrawTarget::Camera(targets);
        Ok(OpaquePass {
            props: PropPass::new(ctx, layout, camera)?,
            scalp: ScalpPass::new(ctx, layout, targets)?,
            strands: StrandDraw::new(ctx, layout, camera, task_bundles)?,
        })
    }

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.strands.has_mesh_path()
    }

    /// The opaque pass: props, scalps and, with `strands`, the hardware-drawn strands; with
    /// `resolve`, the colour's MSAA resolve ends here (MSAA frames draw no software strands).
    /// Returns the mesh query when this pass did not use it.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        inp: &FrameInputs<'a>,
        (strands, resolve): (bool, bool),
        query: Option<&'a mut MeshPrimitivesQuery>,
    ) -> Option<&'a mut MeshPrimitivesQuery> {
        let clear = inp.clear;
        let mesh = inp.path == RenderPath::Mesh;
        g.begin_scope(if mesh { "mesh draw" } else { "draw" });
        let mut p = g.pass("opaque");
        p = match clear {
            Some(_) => p
                .discard(r.color, Access::ColorAttachment)
                .discard(r.depth, Access::DepthAttachment),
            None => p
                .write(r.color, Access::ColorAttachment)
                .write(r.depth, Access::DepthAttachment),
        };
        let resolve_into = r.images.resolved.filter(|_| resolve);
        if let (Some(res), true) = (r.resolved, resolve) {
            p = p.discard(res, Access::ColorAttachment);
        }
        p = p
            .read(r.constants, Access::VertexRead)
            .read(r.skinned, Access::VertexRead)
            .read(r.textures, Access::VertexRead)
            .read_all(&r.shadow, Access::SampledRead)
            .write_some(r.visibility, Access::FragmentReadWrite);
        let strands = inp.bundles > 0 && strands;
        if strands {
            p = strands::strand_uses(p, r, inp.path, strands::StrandUse::CameraShaded);
        }
        let (mut query, rest) = match strands && mesh {
            true => (query, None),
            false => (None, query),
        };
        let (sets, bundles, props, args) = (inp.sets, inp.bundles, inp.props, r.args_buffer);
        let (color, depth) = (r.images.color, r.images.depth);
        p.record(move |rec, _| {
            rec.begin_rendering(
                Attachment {
                    image: color,
                    clear,
                    resolve: resolve_into,
                },
                Attachment {
                    image: depth,
                    clear: clear.map(|_| [1.0; 4]),
                    resolve: None,
                },
            );
            self.props.record(rec, sets, props);
            let mut result = Ok(());
            if bundles > 0 {
                self.scalp.record(rec, sets, bundles);
            }
            if strands && mesh {
                if let Some(q) = query.as_deref_mut() {
                    q.begin(rec);
                }
                result = self.strands.record_mesh(rec, sets, bundles);
                if let Some(q) = query {
                    q.end(rec);
                }
            } else if strands {
                self.strands.record_pulled(rec, sets, args);
            }
            rec.end_rendering();
            result
        });
        g.end_scope();
        rest
    }
}
