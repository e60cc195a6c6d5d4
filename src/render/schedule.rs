//! The frame, top to bottom: every pass a frame may run, in the order it runs, and what each
//! hands the next. [`add_frame`] is the one place that decides what runs in a frame; the
//! passes own their pipelines and declare their uses, and the frame graph derives the
//! synchronisation between them.
//!
//! 1. What changed since the last frame: hair dynamics steps, hair mesh textures rebuilt from
//!    new poses, the LHS baseline's skinning, the density volumes requested.
//! 2. A host frame's depth, in the renderer's terms (host frames only).
//! 3. Statistics cleared, skinned props posed, the root probe.
//! 4. The light's view: culling and LoD, generation (compute path), the shadow maps.
//! 5. The camera's view: culling and LoD, generation (compute path).
//! 6. The opaque pass (props, scalps, opaque strands), then far hair from density volumes.
//! 7. Transparent strands (k-buffer or depth peeling) and the software rasterizer, resolved.
//! 8. Temporal accumulation.
//! 9. The outputs (statistics, image readback, overlay, presentation), or the composite over
//!    the host's colour.
//!
//! Adding a feature: its folder under `features/`, its shaders, and one step here.

use super::RenderPath;
use super::core::binding::PassSets;
use super::core::graph::FrameGraph;
use super::dynamics::pass::SimulatedCharacter;
use super::features::temporal::{TemporalFeature, TemporalInputs};
use super::host::targets::{HostTargetPasses, HostTargetRes};
use super::host::{DepthMapping, HostImage};
use super::passes::compute_generate::GenerateView;
use super::passes::hair_mesh_update::UpdateJob;
use super::passes::lhs_skin::LhsState;
use super::passes::output::{FrameOutputs, add_outputs};
use super::passes::shadow::ShadowDraw;
use super::passes::transparency::{TransparencyPass, TransparentDraw};
use super::passes::{
    FrameInputs, FramePasses, FrameRes, add_clear_args, add_clear_args_for_camera,
};
use super::settings::{LightRaster, ShadowMode};
use super::soft::StrandRaster;
use super::transparency::Transparency;
use crate::render::core::graph::ImageState::Tracked;
use crate::vk::{Access, Buffer, GpuResult};

/// What changed since the last frame, rebuilt before anything draws.
pub struct Changes<'a> {
    /// Hair mesh texture rebuilds (new poses).
    pub jobs: &'a [UpdateJob<'a>],
    /// GPU hair dynamics: the slot's step table and the simulated characters.
    pub dynamics: Option<(&'a Buffer, &'a [SimulatedCharacter<'a>])>,
    /// The LHS baseline's stored strands and the frame slot, on the LHS path.
    pub lhs: Option<(&'a mut LhsState, usize)>,
    /// Density volumes built this frame: the slot's job table, their cells (in the table's
    /// order), the most bundles among their characters.
    pub volume_builds: Option<(&'a Buffer, Vec<&'a Buffer>, u32)>,
}

/// A host frame's images and the pass that brings its depth in and composites over its colour.
pub struct HostStart<'a> {
    /// The host target passes (made by the first host frame).
    pub passes: &'a HostTargetPasses,
    /// The host's colour image.
    pub color: &'a HostImage<'a>,
    /// The host's depth image, when it has one.
    pub depth: Option<&'a HostImage<'a>>,
    /// The host's depth in the renderer's terms.
    pub mapping: DepthMapping,
    /// The uses the host left its colour and depth in (tracked from here on).
    pub uses: (&'a mut Access, &'a mut Access),
    /// The frame slot.
    pub slot: usize,
}

/// Everything one frame adds to its graph.
pub struct ScheduleInputs<'a, 'o> {
    /// What changed since the last frame.
    pub changes: Changes<'a>,
    /// A host frame's start (`None`: the renderer's own frame).
    pub host: Option<HostStart<'a>>,
    /// What the views draw.
    pub draw: FrameInputs<'a>,
    /// Where the results go.
    pub outputs: FrameOutputs<'a, 'o>,
}

/// Add one frame to `g`, top to bottom (the module's list).
pub fn add_frame<'a>(
    g: &mut FrameGraph<'a>,
    passes: &'a FramePasses,
    r: &FrameRes<'a>,
    plan: ScheduleInputs<'a, '_>,
) -> GpuResult<()> {
    let ScheduleInputs {
        changes,
        host,
        draw: mut inp,
        outputs,
    } = plan;
    // 1. What changed.
    add_changes(g, passes, r, changes, inp.sets)?;
    // 2. A host frame's depth.
    let host = host.map(|h| add_host_start(g, r, h));
    // 3-5. Statistics, skinning, the probe, the light's view, the camera's culling and
    // generation.
    add_before_drawing(g, passes, r, &inp)?;
    TemporalFeature::add_clear(g, r.visibility);
    // 6. The opaque pass and the volume tier.
    let strands = StrandWork::of(&inp);
    let query = inp.mesh_query.take();
    let volumes = inp.volume_slots > 0;
    let opaque = strands.hardware && !strands.transparent;
    // Far hair drawn from density volumes goes over the opaque pass, and then takes over its
    // MSAA resolve.
    let query = passes
        .opaque
        .add(g, r, &inp, (opaque, opaque && !volumes), query);
    if volumes {
        let flags = (opaque, inp.raster.uses_software());
        passes
            .volume_hair
            .add(g, r, inp.sets, inp.volume_slots, flags);
    }
    // 7. Transparent strands and the software rasterizer, resolved.
    add_composited(g, passes, r, &inp, strands, query)?;
    // 8. Temporal accumulation.
    inp.temporal_feature.add(g, temporal_inputs(r, &inp));
    // 9. The outputs, and a host frame's composite.
    add_outputs(g, r, outputs);
    if let Some((host_passes, res, slot)) = host {
        host_passes.add_composite(g, r, slot, res)?;
    }
    Ok(())
}

/// How a frame's strands are drawn.
#[derive(Clone, Copy)]
struct StrandWork {
    /// Some bundles are drawn as hardware strips: every one without the software rasterizer,
    /// the thick ones with `auto` (never the static and LHS paths' stored strands, which all
    /// go to software).
    hardware: bool,
    /// The hardware strips are drawn in the transparency passes, not the opaque pass.
    transparent: bool,
    /// The software rasterizer draws some bundles.
    software: bool,
}

impl StrandWork {
    fn of(inp: &FrameInputs) -> Self {
        let stored = matches!(inp.path, RenderPath::Static | RenderPath::Lhs);
        let hardware = inp.bundles > 0
            && match inp.raster {
                StrandRaster::Hardware => true,
                StrandRaster::Auto { .. } => !stored,
                StrandRaster::Software { .. } => false,
            };
        StrandWork {
            hardware,
            transparent: hardware && inp.transparency != Transparency::Opaque,
            software: inp.bundles > 0 && inp.raster.uses_software(),
        }
    }
}

/// Step 1: hair dynamics, then the hair mesh rebuilds they and new poses need; the LHS
/// baseline's skinning; the requested density volumes.
fn add_changes<'a>(
    g: &mut FrameGraph<'a>,
    passes: &'a FramePasses,
    r: &FrameRes<'a>,
    changes: Changes<'a>,
    sets: PassSets<'a>,
) -> GpuResult<()> {
    let poses = match changes.dynamics {
        Some((table, simulated)) => passes.hair_dynamics.add(g, table, simulated),
        None => Vec::new(),
    };
    passes.hair_mesh_update.add(g, r, changes.jobs, &poses);
    if let Some((lhs, slot)) = changes.lhs {
        passes.lhs_skin.add(g, r, lhs, slot)?;
    }
    if let Some((table, volumes, most_bundles)) = changes.volume_builds {
        passes
            .density_volume
            .add(g, r, sets, table, &volumes, most_bundles);
    }
    Ok(())
}

/// Step 2: a host frame's images in the graph (their uses start from the host's) and its
/// depth in the renderer's; what its composite needs at the end.
fn add_host_start<'a>(
    g: &mut FrameGraph<'a>,
    r: &FrameRes<'a>,
    h: HostStart<'a>,
) -> (&'a HostTargetPasses, HostTargetRes<'a>, usize) {
    let (color_use, depth_use) = h.uses;
    let color = g.import_image("host colour", h.color.image, Tracked(color_use));
    let depth = h.depth.map(|d| {
        let res = g.import_image("host depth", d.image, Tracked(depth_use));
        (res, d.after)
    });
    h.passes
        .add_depth(g, r, h.slot, (depth.map(|d| d.0), h.mapping));
    let color = (color, h.color.image, h.color.after);
    (h.passes, HostTargetRes { color, depth }, h.slot)
}

/// Steps 3-5: statistics cleared, skinning, the root probe, the light's passes, the camera's
/// culling and LoD and, on the compute path, its generation.
fn add_before_drawing<'a>(
    g: &mut FrameGraph<'a>,
    passes: &'a FramePasses,
    r: &FrameRes<'a>,
    inp: &FrameInputs<'a>,
) -> GpuResult<()> {
    // Statistics accumulate from zero every frame; the static path keeps the last compute
    // frame's draw arguments (and statistics).
    let keep_args = matches!(inp.path, RenderPath::Static | RenderPath::Lhs);
    if !keep_args {
        add_clear_args(g, r);
    }
    let compute = inp.bundles > 0 && inp.path == RenderPath::Compute;
    passes.skin.add(g, r, inp.sets, inp.skin);
    if let Some(probe) = inp.probe {
        passes.root_probe.add(g, r, inp.sets, probe);
    }
    if let Some(mode) = inp.shadow {
        add_light(g, passes, r, inp, mode)?;
        // The camera's statistics start from zero again; the light's are kept.
        if !keep_args {
            add_clear_args_for_camera(g, r);
        }
    }
    if inp.bundles > 0 && !keep_args {
        passes
            .lod
            .add(g, r, (inp.sets, "cull"), inp.bundles, compute);
    }
    if compute {
        let view = GenerateView::Camera;
        passes.generate.add(g, r, inp.sets, inp.bundles, view);
    }
    Ok(())
}

/// Step 4: the light's passes of a frame with shadows in `mode`: its culling and LoD, its
/// generation (compute path), then its hardware or software map passes.
fn add_light<'a>(
    g: &mut FrameGraph<'a>,
    passes: &'a FramePasses,
    r: &FrameRes<'a>,
    inp: &FrameInputs<'a>,
    mode: ShadowMode,
) -> GpuResult<()> {
    let soft_light = inp.light_raster == LightRaster::Software;
    if inp.bundles > 0 && matches!(inp.path, RenderPath::Mesh | RenderPath::Compute) {
        let pool = inp.path == RenderPath::Compute;
        passes
            .lod
            .add(g, r, (inp.light_sets, "shadow cull"), inp.bundles, pool);
    }
    if inp.bundles > 0 && inp.path == RenderPath::Compute {
        let view = match soft_light {
            true => GenerateView::LightSoftware,
            false => GenerateView::Light,
        };
        passes.generate.add(g, r, inp.light_sets, inp.bundles, view);
    }
    let draw = ShadowDraw {
        mode,
        sets: inp.light_sets,
        bundles: inp.bundles,
        path: inp.path,
        props: inp.light_props,
    };
    if soft_light {
        let soft = passes.soft()?;
        soft.shadow.add(g, r, (&passes.shadow, &soft.raster), draw);
    } else {
        passes.shadow.add(g, r, draw);
    }
    Ok(())
}

/// Step 7: the transparent strands (or, without them, the software rasterizer's k-buffer
/// cleared), the software rasterizer, and the resolve of both.
fn add_composited<'a>(
    g: &mut FrameGraph<'a>,
    passes: &'a FramePasses,
    r: &FrameRes<'a>,
    inp: &FrameInputs<'a>,
    strands: StrandWork,
    mesh_query: Option<&'a mut crate::vk::MeshPrimitivesQuery>,
) -> GpuResult<()> {
    if strands.transparent {
        let draw = TransparentDraw {
            mode: inp.transparency,
            sets: inp.sets,
            bundles: inp.bundles,
            path: inp.path,
            size: inp.size,
            mesh_query,
        };
        passes.transparency.add_layers(g, r, draw)?;
    } else if strands.software {
        let pixels = inp.size.0 as u64 * inp.size.1 as u64;
        TransparencyPass::add_kbuffer_clear(g, r, inp.kbuffer_budget, pixels);
    }
    if strands.software {
        add_software(g, passes, r, inp)?;
    }
    if strands.transparent || strands.software {
        let peel = matches!(inp.transparency, Transparency::DepthPeeling { .. });
        passes.transparency.add_resolve(g, r, peel, inp.sets)?;
    }
    Ok(())
}

/// The software rasterizer's camera passes: the segments not yet appended (the mesh path's
/// segment pass; the static and LHS paths' stored strands), binning and raster.
fn add_software<'a>(
    g: &mut FrameGraph<'a>,
    passes: &'a FramePasses,
    r: &FrameRes<'a>,
    inp: &FrameInputs<'a>,
) -> GpuResult<()> {
    let soft = passes.soft()?;
    match inp.path {
        RenderPath::Mesh => {
            let view = (inp.sets, "soft segments");
            soft.raster
                .add_mesh_segments(g, r, view, inp.bundles, inp.size);
        }
        RenderPath::Static | RenderPath::Lhs => soft.pool.add(g, r, inp.sets),
        RenderPath::Compute => {}
    }
    soft.raster.add(g, r, inp.sets, inp.size, true);
    Ok(())
}

/// What the temporal passes take from frame `r` drawn with `inp`, in frames with motion
/// vectors.
fn temporal_inputs<'a>(r: &FrameRes<'a>, inp: &FrameInputs<'a>) -> Option<TemporalInputs<'a>> {
    match (r.visibility, r.temporal, inp.temporal) {
        (Some(visibility), Some(res), Some(work)) => Some(TemporalInputs {
            constants: r.constants,
            visibility,
            res,
            output: (r.output, r.images.output),
            sets: inp.sets,
            size: inp.size,
            work,
            readback: inp.motion_readback,
        }),
        _ => None,
    }
}
