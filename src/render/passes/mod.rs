//! One file per pass. Each pass owns its pipelines and adds itself to the frame graph with
//! `add`, declaring what it reads and writes; the graph derives the synchronisation.

pub mod bundle_lod;
pub mod compute_generate;
pub mod density_volume;
pub mod hair_dynamics;
pub mod hair_mesh_update;
pub mod host_targets;
pub mod lhs_skin;
pub mod opaque;
pub mod output;
pub mod pool_segments;
pub mod props;
pub mod root_probe;
pub mod scalp;
pub mod shadow;
pub mod skin;
pub mod soft_raster;
pub mod soft_shadow;
pub mod strands;
pub mod transparency;
pub mod volume_hair;

use std::sync::Arc;

use super::RenderPath;
pub use super::core::binding::{PassSets, device_shader_options, shader_options};
use super::features::temporal::{TemporalFeature, TemporalRes, TemporalWork};
use super::graph::TransientBuffer;
use super::graph::{FrameGraph, Res};
use super::settings::{LightRaster, ShadowMode};
use super::shared::GenerateArgs;
use super::soft::SoftBudget;
use super::targets::{COLOR_FORMAT, DEPTH_FORMAT, RenderTargets, ShadowMaps};
use super::transparency::Transparency;
use super::workspace::Workspace;
use crate::vk::{
    Access, Attachment, Buffer, Context, GpuResult, Image, ImageDesc, MeshPrimitivesQuery,
    PipelineLayout, shader::compile,
};
use compute_generate::ComputeGenerate;
use props::PropList;
use shadow::ShadowPass;
use transparency::TransparencyPass;

/// Formats and sample count of the targets the graphics passes draw into.
#[derive(Clone, Copy, Debug)]
pub struct TargetFormats {
    /// Colour format.
    pub color: ash::vk::Format,
    /// Depth format.
    pub depth: ash::vk::Format,
    /// Samples per pixel.
    pub samples: u32,
}

impl TargetFormats {
    /// An opaque, depth-tested graphics pipeline description for these targets.
    pub fn graphics_desc<'a>(&self, name: &'a str) -> crate::vk::GraphicsDesc<'a> {
        crate::vk::GraphicsDesc::new(name, self.color, self.depth).samples(self.samples)
    }
}

/// What a graphics pipeline draws into.
#[derive(Clone, Copy, Debug)]
pub enum DrawTarget {
    /// The camera view's colour and depth.
    Camera(TargetFormats),
    /// One of the light's depth maps: depth only, no fragment shader.
    ShadowDepth,
    /// The deep opacity layers: colour only, additive, no depth.
    ShadowOpacity,
    /// K-buffer insert: the camera's depth (tested, not written), no colour; fragments go to
    /// the per-pixel node buffers.
    OitInsert(TargetFormats),
    /// Depth peeling, first pass of a layer: depth only.
    PeelDepth,
    /// Depth peeling, second pass of a layer: depth test `EQUAL`; fragments go to the
    /// accumulation buffer.
    PeelColor,
}

impl DrawTarget {
    /// The pipeline description (formats, depth, blending) for this target.
    pub fn graphics_desc<'a>(&self, name: &'a str) -> crate::vk::GraphicsDesc<'a> {
        use crate::vk::{BlendMode, DepthMode, GraphicsDesc};
        use ash::vk::Format;
        match self {
            DrawTarget::Camera(t) => t.graphics_desc(name),
            DrawTarget::ShadowDepth => GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT),
            DrawTarget::ShadowOpacity => GraphicsDesc::new(
                name,
                super::targets::SHADOW_LAYERS_FORMAT,
                Format::UNDEFINED,
            )
            .depth(DepthMode::Off)
            .blend(BlendMode::Additive),
            DrawTarget::OitInsert(t) => GraphicsDesc::new(name, Format::UNDEFINED, t.depth)
                .samples(t.samples)
                .depth(DepthMode::TestOnly),
            DrawTarget::PeelDepth => GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT),
            DrawTarget::PeelColor => {
                GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT).depth(DepthMode::Equal)
            }
        }
    }

    /// The fragment shader strands drawn into this target use (`None`: depth only).
    pub fn strand_fragment_shader(&self) -> Option<&'static str> {
        match self {
            DrawTarget::Camera(_) => Some("strands.frag"),
            DrawTarget::ShadowDepth => None,
            DrawTarget::ShadowOpacity => Some("shadow.frag"),
            DrawTarget::OitInsert(_) => Some("oit.frag"),
            DrawTarget::PeelDepth => Some("peel_depth.frag"),
            DrawTarget::PeelColor => Some("peel_color.frag"),
        }
    }
}

/// A vertex (+ fragment, where given) pipeline drawing into `target`.
pub fn vertex_pipeline(
    ctx: &Arc<Context>,
    layout: &Arc<PipelineLayout>,
    name: &str,
    shaders: (&str, Option<&str>),
    target: DrawTarget,
) -> GpuResult<crate::vk::Pipeline> {
    let opts = match target {
        // The light's prop pass draws the bodies' map, in its own view.
        DrawTarget::ShadowDepth => device_shader_options(ctx, 1).define("BODY_MAP_PASS", 1),
        _ => device_shader_options(ctx, 1),
    };
    let v = compile(shaders.0, &opts)?;
    let f = shaders.1.map(|f| compile(f, &opts)).transpose()?;
    let mut desc = target
        .graphics_desc(name)
        .stage(ash::vk::ShaderStageFlags::VERTEX, &v);
    if let Some(f) = &f {
        desc = desc.stage(ash::vk::ShaderStageFlags::FRAGMENT, f);
    }
    crate::vk::Pipeline::graphics(ctx, layout, &desc)
}

/// A compute pipeline over its own set 0 of `bindings` storage buffers (passes outside the
/// frame's sets: the hair mesh update, LHS skinning): the set layout and the pipeline.
pub fn own_set_compute(
    ctx: &Arc<Context>,
    name: &str,
    shader: &str,
    bindings: impl IntoIterator<Item = u32>,
) -> GpuResult<(Arc<crate::vk::DescriptorSetLayout>, crate::vk::Pipeline)> {
    let bindings: Vec<crate::vk::BindingDesc> = bindings
        .into_iter()
        .map(|b| crate::vk::BindingDesc::single(b, crate::vk::DescriptorKind::StorageBuffer))
        .collect();
    let set_layout = crate::vk::DescriptorSetLayout::new(ctx, &bindings)?;
    let layout = PipelineLayout::new(ctx, std::slice::from_ref(&set_layout))?;
    let spirv = compile(shader, &device_shader_options(ctx, 1))?;
    let pipeline = crate::vk::Pipeline::compute(ctx, name, &layout, &spirv)?;
    Ok((set_layout, pipeline))
}

/// `(x, y)` workgroup counts for `groups` workgroups with at most `DISPATCH_ROW` per row.
pub fn dispatch_2d(groups: u32) -> (u32, u32) {
    let row = super::shared::DISPATCH_ROW;
    (groups.min(row), groups.div_ceil(row))
}

/// The frame's resources in the graph, and the objects the passes' commands name.
pub struct FrameRes<'a> {
    /// Host-written inputs: frame block, character records, bundle table, props.
    pub constants: Res,
    /// The characters' textures and the shading table (sampled).
    pub textures: Res,
    /// `GenerateArgs`: indirect arguments and statistics.
    pub args: Res,
    /// The compute path's vertex pool (a placeholder before its first use).
    pub pool: Res,
    /// Per-bundle LoD records.
    pub lods: Res,
    /// Per-bundle prefix sums.
    pub offsets: Res,
    /// Scan block sums.
    pub scan: Res,
    /// Colour target.
    pub color: Res,
    /// Depth target.
    pub depth: Res,
    /// The MSAA resolve of the colour target.
    pub resolved: Option<Res>,
    /// The single-sample image of the frame (`resolved` or `color`).
    pub output: Res,
    /// Shadow maps: hair depth, prop depth, opacity layers.
    pub shadow: [Res; 3],
    /// The characters' density volumes (read by device address).
    pub volumes: Res,
    /// K-buffer nodes.
    pub oit_nodes: Res,
    /// K-buffer tails.
    pub oit_tail: Res,
    /// Depth peeling: previous layer and opaque depth.
    pub peel_depth: Res,
    /// Depth peeling: accumulated colour.
    pub peel_accum: Res,
    /// Depth peeling: the layers' depth attachment.
    pub peel_image: Option<Res>,
    /// Software rasterizer: segments.
    pub soft_segments: Res,
    /// Software rasterizer: tile table.
    pub soft_tiles: Res,
    /// Software rasterizer: tile entries.
    pub soft_entries: Res,
    /// Software rasterizer: the opaque depth copy.
    pub soft_depth: Res,
    /// Software shadows: the hair depth nearest the light.
    pub soft_shadow_depth: Res,
    /// Software shadows: the deep opacity layers.
    pub soft_shadow_layers: Res,
    /// Per-pixel nearest surface (`temporal.glsl`), in frames with motion vectors: every
    /// camera pass that draws a surface writes it.
    pub visibility: Option<Res>,
    /// The temporal passes' other resources, in frames with motion vectors.
    pub temporal: Option<TemporalRes>,
    /// This frame's posed vertices of skinned props.
    pub skinned: Res,
    /// The `args` buffer (indirect commands name it).
    pub args_buffer: &'a Buffer,
    /// The imported images attachments and copies name.
    pub images: FrameImages<'a>,
}

/// The imported images of a frame that passes' commands name.
#[derive(Clone, Copy)]
pub struct FrameImages<'a> {
    /// Colour target.
    pub color: &'a Image,
    /// Depth target.
    pub depth: &'a Image,
    /// MSAA resolve.
    pub resolved: Option<&'a Image>,
    /// The single-sample output.
    pub output: &'a Image,
    /// Shadow maps: hair depth, prop depth, opacity layers.
    pub shadow: [&'a Image; 3],
}

/// What a frame imports into its graph.
pub struct FrameSources<'a> {
    /// Working buffers (args, pool, LoDs, offsets, scan).
    pub work: &'a Workspace,
    /// Colour and depth targets (their last uses are tracked).
    pub targets: &'a mut RenderTargets,
    /// Shadow maps.
    pub shadow: &'a mut ShadowMaps,
    /// The temporal history (read, written), once made.
    pub history: Option<(&'a Buffer, &'a Buffer)>,
    /// The frame slot's posed vertices (the skinning pass writes, prop passes read).
    pub skinned: &'a Buffer,
}

/// The transient resources of a frame, sized for its settings; the frame graph creates them
/// (every buffer every frame, sized 0 where unused, so set 0's bindings always name one).
pub struct FrameTransients {
    /// K-buffer nodes and tails, peel depth and accumulation.
    pub transparency: [TransientBuffer; 4],
    /// Software rasterizer segments, tiles, entries, depth.
    pub soft: [TransientBuffer; 4],
    /// Software shadows: hair depth and deep opacity layers.
    pub soft_shadow: [TransientBuffer; 2],
    /// Depth peeling's layer depth attachment, when peeling.
    pub peel_image: Option<ImageDesc>,
    /// Visibility, motion, frame colour, vertex and segment residuals
    /// (`render::temporal::transient_buffers`).
    pub temporal: [TransientBuffer; 5],
    /// Whether the frame computes motion vectors.
    pub motion: bool,
}

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
    let t = FrameTransients::new(transparency, (camera, None), (width, height), work);
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

impl FrameTransients {
    /// The transients of a frame at `size`, whose per-pixel buffers are those of
    /// `transparency` (the software rasterizer composites through a k-buffer), with the
    /// software rasterizer's budget when it draws the camera's strands (`camera`) and when it
    /// draws the light's (`light`: budget, map side, shadow mode).
    pub fn new(
        transparency: Transparency,
        (camera, light): (Option<SoftBudget>, Option<(SoftBudget, u32, ShadowMode)>),
        (width, height): (u32, u32),
        temporal: Option<TemporalWork>,
    ) -> Self {
        let segments = camera.map_or(0, |b| b.segments);
        let temporal_buffers =
            super::temporal::transient_buffers(temporal, segments, (width, height));
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

    /// Every transient buffer.
    pub fn buffers(&self) -> impl Iterator<Item = &TransientBuffer> {
        self.transparency
            .iter()
            .chain(&self.soft)
            .chain(&self.soft_shadow)
            .chain(&self.temporal)
    }
}

impl<'a> FrameRes<'a> {
    /// Import the frame's persistent resources into `g` and create its transients.
    pub fn new(g: &mut FrameGraph<'a>, src: FrameSources<'a>, t: &FrameTransients) -> Self {
        use crate::render::core::graph::ImageState::Tracked;
        let w = src.work.buffers();
        let RenderTargets {
            color,
            depth,
            resolved,
            color_access,
            depth_access,
            resolved_access,
        } = src.targets;
        let ShadowMaps {
            hair_depth,
            prop_depth,
            layers,
            access: [a0, a1, a2],
            ..
        } = src.shadow;
        let color_res = g.import_image("color", color, Tracked(color_access));
        let resolved_res = resolved
            .as_ref()
            .map(|r| g.import_image("color resolved", r, Tracked(resolved_access)));
        let (color, resolved) = (&*color, resolved.as_ref());
        let [oit_nodes, oit_tail, peel_depth, peel_accum] =
            t.transparency.map(|d| g.create_buffer(d));
        let [soft_segments, soft_tiles, soft_entries, soft_depth] =
            t.soft.map(|d| g.create_buffer(d));
        let [soft_shadow_depth, soft_shadow_layers] = t.soft_shadow.map(|d| g.create_buffer(d));
        let temporal = TemporalRes::create(g, &t.temporal, t.motion, src.history);
        let visibility = temporal.map(|t| t.0);
        FrameRes {
            constants: g.host_input("frame constants"),
            textures: g.host_input("textures"),
            args: g.import_buffer("args", w.args),
            pool: g.import_buffer("vertex pool", w.pool),
            lods: g.import_buffer("bundle lods", w.lods),
            offsets: g.import_buffer("bundle offsets", w.offsets),
            scan: g.import_buffer("scan scratch", w.scan),
            color: color_res,
            depth: g.import_image("depth", depth, Tracked(depth_access)),
            resolved: resolved_res,
            output: resolved_res.unwrap_or(color_res),
            shadow: [
                g.import_image("shadow hair depth", hair_depth, Tracked(a0)),
                g.import_image("shadow prop depth", prop_depth, Tracked(a1)),
                g.import_image("shadow layers", layers, Tracked(a2)),
            ],
            volumes: g.import_address_buffers("density volumes"),
            oit_nodes,
            oit_tail,
            peel_depth,
            peel_accum,
            peel_image: t
                .peel_image
                .clone()
                .map(|d| g.create_image("peel layer depth", d)),
            soft_segments,
            soft_tiles,
            soft_entries,
            soft_depth,
            soft_shadow_depth,
            soft_shadow_layers,
            visibility,
            temporal: temporal.map(|t| t.1),
            skinned: g.import_buffer("skinned vertices", src.skinned),
            args_buffer: w.args,
            images: FrameImages {
                color,
                depth: &*depth,
                resolved,
                output: resolved.unwrap_or(color),
                shadow: [&*hair_depth, &*prop_depth, &*layers],
            },
        }
    }
}

impl FrameRes<'_> {
    /// The uses of a pass that shades strands (`strand_radiance.glsl`) in the shader stage of
    /// `read` (a storage read): the light's maps, sampled, and the density volumes, read by
    /// device address.
    pub fn shading_uses<'g, 'a>(
        &self,
        p: crate::render::core::graph::PassBuilder<'g, 'a>,
        read: Access,
    ) -> crate::render::core::graph::PassBuilder<'g, 'a> {
        p.read_all(&self.shadow, Access::SampledRead)
            .read(self.volumes, read)
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
    pub(in crate::render) hair_dynamics: hair_dynamics::HairDynamicsPass,
    /// The LHS baseline's skinning.
    pub(in crate::render) lhs_skin: lhs_skin::LhsSkin,
    /// Density volume builds.
    pub(in crate::render) density_volume: density_volume::DensityVolumePass,
    /// Far hair drawn from density volumes.
    pub(in crate::render) volume_hair: volume_hair::VolumeHairDraw,
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

/// Add the pass that zeroes `args` (indirect arguments and statistics).
pub(crate) fn add_clear_args<'a>(g: &mut FrameGraph<'a>, r: &FrameRes<'a>) {
    let args = r.args_buffer;
    g.pass("clear args")
        .discard(r.args, Access::TransferWrite)
        .record(move |rec, _| {
            rec.fill_buffer(args, 0, size_of::<GenerateArgs>() as u64, 0);
            Ok(())
        });
}

/// After the light's view: keep its statistics in `GenerateArgs::light_stats`, then clear the
/// rest for the camera's.
pub(crate) fn add_clear_args_for_camera<'a>(g: &mut FrameGraph<'a>, r: &FrameRes<'a>) {
    let args = r.args_buffer;
    let bytes = size_of::<super::shared::FrameStats>() as u64;
    g.pass("keep light statistics")
        .read(r.args, Access::TransferRead)
        .write(r.args, Access::TransferWrite)
        .record(move |rec, _| {
            let (from, to) = (GenerateArgs::STATS_OFFSET, GenerateArgs::LIGHT_STATS_OFFSET);
            rec.copy_buffer(args, from, args, to, bytes);
            Ok(())
        });
    g.pass("clear args")
        .write(r.args, Access::TransferWrite)
        .record(move |rec, _| {
            rec.fill_buffer(args, 0, GenerateArgs::LIGHT_STATS_OFFSET, 0);
            Ok(())
        });
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
            hair_dynamics: hair_dynamics::HairDynamicsPass::new(ctx)?,
            lhs_skin: lhs_skin::LhsSkin::new(ctx)?,
            density_volume: density_volume::DensityVolumePass::new(ctx, layout)?,
            volume_hair: volume_hair::VolumeHairDraw::new(ctx, layout, targets)?,
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
