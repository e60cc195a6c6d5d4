//! The light's passes through the software rasterizer (`glsl/soft_shadow.comp`): the light's
//! generation appended every visible bundle's segments unshaded (`RASTER_LIGHT`; compute
//! generation, or the mesh path's segment pass added here); they are binned into the map's
//! tiles as the camera's are, then one compute pass writes the nearest hair depth per texel
//! and, for deep opacity maps, a second one the opacity layers behind it; transfers copy both
//! into the maps the camera's passes sample, so lookups (`shadow_lookup.glsl`) are the same
//! for both light rasters. The props' depth stays a hardware pass (`ShadowPass::add_props`).
//! What each step reads and writes is declared where it is added to the frame graph.

use std::sync::Arc;

use super::shadow::{ShadowDraw, ShadowPass};
use super::soft_raster::SoftRasterPass;
use super::{FrameRes, device_shader_options};
use crate::render::RenderPath;
use crate::render::core::graph::{FrameGraph, Res};
use crate::render::shadow::ShadowMode;
use crate::render::soft::tile_grid;
use crate::vk::shader::compile;
use crate::vk::{Access, Context, GpuResult, Pipeline, PipelineLayout};

/// The software shadow passes' pipelines.
pub struct SoftShadowPass {
    depth: Pipeline,
    opacity: Pipeline,
}

impl SoftShadowPass {
    /// Compile the depth and opacity pipelines.
    pub fn new(ctx: &Arc<Context>, layout: &Arc<PipelineLayout>) -> GpuResult<Self> {
        let opts = device_shader_options(ctx, 1);
        let opacity = opts.clone().define("OPACITY_PASS", 1);
        Ok(SoftShadowPass {
            depth: Pipeline::compute(
                ctx,
                "soft shadow depth",
                layout,
                &compile("soft_shadow.comp", &opts)?,
            )?,
            opacity: Pipeline::compute(
                ctx,
                "soft shadow opacity",
                layout,
                &compile("soft_shadow.comp", &opacity)?,
            )?,
        })
    }

    /// Add the light's passes for `d` (the light's segments generated before on the compute
    /// path): props' depth, the mesh path's segments, binning, hair depth, and for deep
    /// opacity maps the layers; every map ends up sampled by the camera's passes.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        (hardware, soft): (&'a ShadowPass, &'a SoftRasterPass),
        d: ShadowDraw<'a>,
    ) {
        let side = r.images.shadow[0].desc.extent[0];
        g.begin_scope("shadow draw");
        hardware.add_props(g, r, &d);
        g.end_scope();
        if d.path == RenderPath::Mesh && d.bundles > 0 {
            let view = (d.sets, "shadow soft segments");
            soft.add_mesh_segments(g, r, view, d.bundles, (side, side));
        }
        g.begin_scope("shadow soft bin");
        soft.add_binning(g, r, d.sets, (side, side));
        g.end_scope();
        g.begin_scope("shadow soft raster");
        self.add_depth(g, r, &d, side);
        if d.mode == ShadowMode::DeepOpacity {
            self.add_opacity(g, r, &d, side);
        }
        g.end_scope();
    }

    /// The nearest hair depth per texel, copied into the hair depth map.
    fn add_depth<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        d: &ShadowDraw<'a>,
        side: u32,
    ) {
        let step = MapStep {
            names: ("soft shadow depth", "soft shadow depth copy"),
            pipeline: &self.depth,
            out: r.soft_shadow_depth,
            map: 0,
        };
        add_map_step(g, r, d, side, step, &[]);
    }

    /// The deep opacity layers behind the hair depth, copied into the layers map.
    fn add_opacity<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        d: &ShadowDraw<'a>,
        side: u32,
    ) {
        let step = MapStep {
            names: ("soft shadow opacity", "soft shadow layers copy"),
            pipeline: &self.opacity,
            out: r.soft_shadow_layers,
            map: 2,
        };
        add_map_step(g, r, d, side, step, &[r.soft_shadow_depth]);
    }
}

/// One software shadow map: a compute pass over the map's tiles writing `out`, then its copy
/// into shadow map `map` (0 hair depth, 2 layers).
struct MapStep<'a> {
    /// The compute pass's and the copy's names.
    names: (&'static str, &'static str),
    pipeline: &'a Pipeline,
    out: Res,
    map: usize,
}

/// Add `step`, whose compute pass also reads `extra` (besides the frame constants and the
/// binned segments).
fn add_map_step<'a>(
    g: &mut FrameGraph<'a>,
    r: &FrameRes<'a>,
    d: &ShadowDraw<'a>,
    side: u32,
    step: MapStep<'a>,
    extra: &[Res],
) {
    let (tx, ty) = tile_grid(side, side);
    let (sets, out, pipeline) = (d.sets, step.out, step.pipeline);
    g.pass(step.names.0)
        .read(r.constants, Access::ComputeRead)
        .read_all(
            &[r.soft_segments, r.soft_tiles, r.soft_entries],
            Access::ComputeRead,
        )
        .read_all(extra, Access::ComputeRead)
        .discard(out, Access::ComputeReadWrite)
        .record(move |rec, _| {
            rec.bind(pipeline, &sets.both());
            rec.dispatch(tx, ty, 1);
            Ok(())
        });
    let map = r.images.shadow[step.map];
    g.pass(step.names.1)
        .read(out, Access::TransferRead)
        .discard(r.shadow[step.map], Access::TransferWrite)
        .record(move |rec, res| {
            rec.copy_buffer_to_image(res.buffer(out)?, map);
            Ok(())
        });
}
