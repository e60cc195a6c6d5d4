//! One file per pass. Each pass owns its pipelines and adds itself to the frame graph with
//! `add`, declaring what it reads and writes; the graph derives the synchronisation.

pub mod bundle_lod;
pub mod compute_generate;
pub mod hair_mesh_update;
pub mod lhs_skin;
pub mod opaque;
pub mod output;
pub mod pool_segments;
pub mod root_probe;
pub mod scalp;
pub mod shadow;
pub mod soft_raster;
pub mod soft_shadow;
pub mod strands;
pub mod transparency;

use std::sync::Arc;

use super::RenderPath;
pub use super::core::binding::{PassSets, device_shader_options, shader_options};
pub use super::core::frame_res::{
    FrameImages, FrameRes, FrameSources, FrameTransients, add_clear_args,
    add_clear_args_for_camera, add_depth_copy,
};
pub use super::core::pipelines::{
    DrawTarget, TargetFormats, dispatch_2d, own_set_compute, vertex_pipeline,
};
pub use super::features::props::{draw as props, skin};
use super::features::temporal::{TemporalFeature, TemporalRes, TemporalWork};
use super::graph::FrameGraph;
use super::settings::{LightRaster, ShadowMode};
use super::shared::GenerateArgs;
use super::soft::SoftBudget;
use super::targets::{COLOR_FORMAT, DEPTH_FORMAT};
use super::transparency::Transparency;
use crate::vk::{
    Access, Attachment, Buffer, Context, GpuResult, MeshPrimitivesQuery, PipelineLayout,
};
use compute_generate::ComputeGenerate;
use props::PropList;
use shadow::ShadowPass;
use transparency::TransparencyPass;

/// Refuse, before any work, a `width x height` frame whose per-pixel buffers (fragment lists
/// of `transparency`, temporal history when `temporal`, the software rasterizer's depth when
/// `soft`) need more than `limit` bytes (the device's `maxStorageBufferRange`): one line in
/// the settings' terms, never only a buffer's name.
pub fn check_frame_storage(
    limit: u64,
    (width, height): (u32, u32),
    transparency: Transparency,
    temporal: bool,
    soft: bool,
) -> Result<(), String> {
    let work = temporal.then_some(TemporalWork {
        accumulate: true,
        vertex_slots: 0,
    });
    let camera = soft.then_some(SoftBudget::EMPTY);
    let t = frame_transients(transparency, (camera, None), (width, height), work);
    let size = |b: u64| match b {
        0..0x4000_0000 => format!("{} MiB", b.div_ceil(1 << 20)),
        _ => format!("{:.1} GiB", b as f64 / (1u64 << 30) as f64),
    };
    match t.buffers().find(|b| b.bytes > limit) {
        None => Ok(()),
        Some(b) => {
            let super::graph::UserTerms { what, remedy } = b.user_terms;
            Err(format!(
                "a {width}x{height} image with transparency {transparency} needs {} of {what}, more than the {} this device's largest storage buffer holds; {remedy}",
                size(b.bytes),
                size(limit)
            ))
        }
    }
}

/// The transients of a frame at `size`, whose per-pixel buffers are those of
/// `transparency` (the software rasterizer composites through a k-buffer), with the
/// software rasterizer's budget when it draws the camera's strands (`camera`) and when it
/// draws the light's (`light`: budget, map side, shadow mode).
pub fn frame_transients(
    transparency: Transparency,
    (camera, light): (Option<SoftBudget>, Option<(SoftBudget, u32, ShadowMode)>),
    (width, height): (u32, u32),
    temporal: Option<TemporalWork>,
) -> FrameTransients {
    let segments = camera.map_or(0, |b| b.segments);
    let temporal_buffers = super::temporal::transient_buffers(temporal, segments, (width, height));
    let peel = matches!(transparency, Transparency::DepthPeeling { .. });
    let budget = camera.or(light.map(|l| l.0)).unwrap_or(SoftBudget::EMPTY);
    let views = (camera.map(|_| (width, height)), light.map(|l| l.1));
    FrameTransients {
        transparency: transparency.buffers(width as u64 * height as u64),
        soft: SoftBudget::buffers(budget, views.0, views.1),
        soft_shadow: super::soft::shadow_buffers(
            light.map(|l| (l.1, l.2 == ShadowMode::DeepOpacity)),
        ),
        peel_image: peel.then(|| super::transparency::peel_image(width, height)),
        temporal: temporal_buffers,
        motion: temporal.is_some(),
    }
}

/// What one frame's passes draw.
pub struct FrameInputs<'a> {
    /// Camera descriptor sets.
    pub sets: PassSets<'a>,
    /// The light's sets (its frame block), for the shadow passes.
    pub light_sets: PassSets<'a>,
    /// Bundles of all characters.
    pub bundles: u32,
    /// Generation path.
    pub path: RenderPath,
    /// Clear colour, or `None` to draw over the previous contents.
    pub clear: Option<[f32; 4]>,
    /// Props to draw (bodies, ground).
    pub props: PropList<'a>,
    /// The props the light's bodies map draws (the same, bodies at the light's far level).
    pub light_props: PropList<'a>,
    /// Skinning jobs and the most vertices of one (0 jobs: no skinning pass).
    pub skin: (u32, u32),
    /// The root probe's output and the bundles to probe, when the frame probes roots.
    pub probe: Option<(crate::render::core::graph::Res, u32)>,
    /// Shadow mode of this frame; `None` when off (or nothing to shadow).
    pub shadow: Option<super::shadow::ShadowMode>,
    /// How the strands are composited.
    pub transparency: super::Transparency,
    /// How strands are rasterized.
    pub raster: super::soft::StrandRaster,
    /// How the light's passes draw the hair.
    pub light_raster: LightRaster,
    /// k-buffer nodes per pixel of this frame (the OIT budget, or the software
    /// rasterizer's K in opaque frames).
    pub kbuffer_budget: u32,
    /// Target size.
    pub size: (u32, u32),
    /// The mesh path's primitive query (wraps the strand draw).
    pub mesh_query: Option<&'a mut MeshPrimitivesQuery>,
    /// Motion vectors and accumulation, when the frame has them.
    pub temporal: Option<TemporalWork>,
    /// The temporal feature that adds their passes.
    pub temporal_feature: &'a TemporalFeature,
    /// Where the motion vectors are copied for the host, when asked for.
    pub motion_readback: Option<&'a Buffer>,
    /// Character slots whose hair may be drawn from their density volume this frame (the
    /// volume tier; 0: none).
    pub volume_slots: u32,
}

/// The pipelines of every pass of a frame; [`crate::render::schedule`] adds them to the frame
/// graph in order.
pub struct FramePasses {
    /// Culling, LoD and LoD pressure per view (both paths).
    pub(in crate::render) lod: bundle_lod::BundleLodPass,
    /// The compute path's generation.
    pub(in crate::render) generate: ComputeGenerate,
    /// The light's hardware maps.
    pub(in crate::render) shadow: ShadowPass,
    /// Skinned props posed.
    pub(in crate::render) skin: skin::SkinPass,
    /// The root probe.
    pub(in crate::render) root_probe: root_probe::RootProbePass,
    /// Props, scalps and opaque strands.
    pub(in crate::render) opaque: opaque::OpaquePass,
    /// Transparent strands and the k-buffer resolve.
    pub(in crate::render) transparency: TransparencyPass,
    /// The software rasterizer's passes, on devices with 64-bit shared and buffer atomics.
    soft: Option<SoftPasses>,
    /// Hair mesh textures rebuilt from new poses.
    pub(in crate::render) hair_mesh_update: hair_mesh_update::HairMeshUpdate,
    /// GPU hair dynamics.
    pub(in crate::render) hair_dynamics: crate::render::features::dynamics::pass::HairDynamicsPass,
    /// The LHS baseline's skinning.
    pub(in crate::render) lhs_skin: lhs_skin::LhsSkin,
    /// Density volume builds.
    pub(in crate::render) density_volume:
        crate::render::features::volume::density_volume::DensityVolumePass,
    /// Far hair drawn from density volumes.
    pub(in crate::render) volume_hair: crate::render::features::volume::volume_hair::VolumeHairDraw,
}

/// The software rasterizer's passes (they need 64-bit shared and buffer atomics).
pub(in crate::render) struct SoftPasses {
    /// Binning and raster (and the mesh path's segment pass).
    pub raster: soft_raster::SoftRasterPass,
    /// The light's maps.
    pub shadow: soft_shadow::SoftShadowPass,
    /// The static and LHS paths' stored strands as segments.
    pub pool: pool_segments::PoolSegments,
}

/// Write `bytes` into `table`, a host-visible table that shaders read by device address (the
/// job tables of the hair dynamics and the density volumes), first replacing it with one of
/// the next power-of-two size when it is missing or too small. The caller owns a frame slot
/// whose earlier frame has completed, so the old table is free.
pub fn write_address_table<'t>(
    ctx: &Arc<Context>,
    table: &'t mut Option<Buffer>,
    name: &str,
    bytes: &[u8],
) -> GpuResult<&'t Buffer> {
    let size = bytes.len().max(1) as u64;
    let buffer = match table.take() {
        Some(t) if t.size >= size => t,
        _ => {
            let usage = ash::vk::BufferUsageFlags::STORAGE_BUFFER
                | ash::vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
            let desc = crate::vk::BufferDesc::new(name, size.next_power_of_two(), usage);
            Buffer::new(ctx, &desc.host_visible())?
        }
    };
    let buffer = table.insert(buffer);
    buffer.write(0, bytes)?;
    Ok(buffer)
}

fn no_soft() -> crate::vk::GpuError {
    crate::vk::GpuError::Unsupported("no software rasterizer on this device".into())
}

impl FramePasses {
    /// Compile every pipeline; the mesh path with `task_bundles` bundles per task workgroup.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        task_bundles: u32,
        samples: u32,
    ) -> GpuResult<Self> {
        let targets = TargetFormats {
            color: COLOR_FORMAT,
            depth: DEPTH_FORMAT,
            samples,
        };
        Ok(FramePasses {
            lod: bundle_lod::BundleLodPass::new(ctx, layout)?,
            generate: ComputeGenerate::new(ctx, layout)?,
            shadow: ShadowPass::new(ctx, layout, task_bundles)?,
            skin: skin::SkinPass::new(ctx, layout)?,
            root_probe: root_probe::RootProbePass::new(ctx, layout)?,
            opaque: opaque::OpaquePass::new(ctx, layout, targets, task_bundles)?,
            transparency: TransparencyPass::new(ctx, layout, targets, task_bundles),
            soft: match ctx.info.int64_atomics {
                true => Some(SoftPasses {
                    raster: soft_raster::SoftRasterPass::new(ctx, layout, task_bundles)?,
                    shadow: soft_shadow::SoftShadowPass::new(ctx, layout)?,
                    pool: pool_segments::PoolSegments::new(ctx, layout)?,
                }),
                false => None,
            },
            hair_mesh_update: hair_mesh_update::HairMeshUpdate::new(ctx)?,
            hair_dynamics: crate::render::features::dynamics::pass::HairDynamicsPass::new(ctx)?,
            lhs_skin: lhs_skin::LhsSkin::new(ctx)?,
            density_volume:
                crate::render::features::volume::density_volume::DensityVolumePass::new(
                    ctx, layout,
                )?,
            volume_hair: crate::render::features::volume::volume_hair::VolumeHairDraw::new(
                ctx, layout, targets,
            )?,
        })
    }

    /// Layout of the animated characters' update sets.
    pub fn deform_set_layout(&self) -> &Arc<crate::vk::DescriptorSetLayout> {
        self.hair_mesh_update.set_layout()
    }

    /// The LHS baseline's skinning pass.
    pub fn lhs_skin(&self) -> &lhs_skin::LhsSkin {
        &self.lhs_skin
    }

    /// Check and compile what `mode` needs, before a frame uses it.
    pub fn prepare_transparency(&mut self, mode: super::Transparency) -> GpuResult<()> {
        self.transparency.prepare(mode)
    }

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.opaque.has_mesh_path()
    }

    /// Whether the software rasterizer is available.
    pub fn has_software_raster(&self) -> bool {
        self.soft.is_some()
    }

    /// The software rasterizer's passes, or why this device has none.
    pub(in crate::render) fn soft(&self) -> GpuResult<&SoftPasses> {
        self.soft.as_ref().ok_or_else(no_soft)
    }

    /// The software rasterizer alone over the targets (cleared to black first): `segments`
    /// segments already uploaded to the soft buffers, nothing in front (the soft depth is
    /// filled with 1), composited through a k-buffer of `budget` nodes
    /// (`debug::rasterize_segments`).
    pub fn add_soft_only<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        sets: PassSets<'a>,
        (segments, budget): (u32, u32),
    ) -> GpuResult<()> {
        let pass = &self.soft.as_ref().ok_or_else(no_soft)?.raster;
        let (w, h) = (r.images.color.desc.extent[0], r.images.color.desc.extent[1]);
        add_clear_args(g, r);
        let (args, soft_depth) = (r.args_buffer, r.soft_depth);
        g.pass("soft inputs")
            .write(r.args, Access::TransferWrite)
            .discard(r.soft_depth, Access::TransferWrite)
            .record(move |rec, res| {
                rec.fill_buffer(args, GenerateArgs::SEGMENTS_DEMANDED_OFFSET, 4, segments);
                let pixels = w as u64 * h as u64;
                rec.fill_buffer(res.buffer(soft_depth)?, 0, pixels * 4, 1.0f32.to_bits());
                Ok(())
            });
        let (color, depth) = (r.images.color, r.images.depth);
        g.pass("clear targets")
            .discard(r.color, Access::ColorAttachment)
            .discard(r.depth, Access::DepthAttachment)
            .record(move |rec, _| {
                rec.begin_rendering(
                    Attachment {
                        image: color,
                        clear: Some([0.0, 0.0, 0.0, 1.0]),
                        resolve: None,
                    },
                    Attachment {
                        image: depth,
                        clear: Some([1.0; 4]),
                        resolve: None,
                    },
                );
                rec.end_rendering();
                Ok(())
            });
        TransparencyPass::add_kbuffer_clear(g, r, budget, w as u64 * h as u64);
        pass.add(g, r, sets, (w, h), false);
        self.transparency.add_resolve(g, r, false, sets)
    }
}
