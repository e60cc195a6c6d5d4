//! One file per pass. Each pass owns its pipelines and adds itself to the frame graph with
//! `add`, declaring what it reads and writes; the graph derives the synchronisation.

pub mod bundle_lod;
pub mod compute_generate;
pub mod density_volume;
pub mod hair_dynamics;
pub mod hair_mesh_update;
pub mod host_targets;
pub mod lhs_skin;
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
use super::features::temporal::{TemporalFeature, TemporalInputs, TemporalRes, TemporalWork};
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
use compute_generate::{ComputeGenerate, GenerateView};
use props::{PropList, PropPass};
use scalp::ScalpPass;
use shadow::{ShadowDraw, ShadowPass};
use strands::StrandDraw;
use transparency::{TransparencyPass, TransparentDraw};

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

/// The pipelines of every pass of a frame; [`FramePasses::add`] adds them to the frame graph
/// in order: statistics reset; with shadows, the light's generation (compute path) and passes,
/// then a second reset; generation (compute path); the opaque pass (props, scalps, and opaque
/// strands; the mesh path generates inside it); with transparency, the transparent strand
/// passes; the software rasterizer; the resolve.
pub struct FramePasses {
    /// Culling, LoD and LoD pressure per view (both paths).
    lod: bundle_lod::BundleLodPass,
    generate: ComputeGenerate,
    shadow: ShadowPass,
    props: PropPass,
    skin: skin::SkinPass,
    root_probe: root_probe::RootProbePass,
    scalp: ScalpPass,
    strands: StrandDraw,
    transparency: TransparencyPass,
    /// The software rasterizer's passes, on devices with 64-bit shared and buffer atomics.
    soft: Option<SoftPasses>,
    hair_mesh_update: hair_mesh_update::HairMeshUpdate,
    hair_dynamics: hair_dynamics::HairDynamicsPass,
    lhs_skin: lhs_skin::LhsSkin,
    density_volume: density_volume::DensityVolumePass,
    volume_hair: volume_hair::VolumeHairDraw,
}

/// The software rasterizer's passes (they need 64-bit shared and buffer atomics).
struct SoftPasses {
    /// Binning and raster (and the mesh path's segment pass).
    raster: soft_raster::SoftRasterPass,
    /// The light's maps.
    shadow: soft_shadow::SoftShadowPass,
    /// The static and LHS paths' stored strands as segments.
    pool: pool_segments::PoolSegments,
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
fn add_clear_args_for_camera<'a>(g: &mut FrameGraph<'a>, r: &FrameRes<'a>) {
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
        let camera = DrawTarget::Camera(targets);
        Ok(FramePasses {
            lod: bundle_lod::BundleLodPass::new(ctx, layout)?,
            generate: ComputeGenerate::new(ctx, layout)?,
            shadow: ShadowPass::new(ctx, layout, task_bundles)?,
            props: PropPass::new(ctx, layout, camera)?,
            skin: skin::SkinPass::new(ctx, layout)?,
            root_probe: root_probe::RootProbePass::new(ctx, layout)?,
            scalp: ScalpPass::new(ctx, layout, targets)?,
            strands: StrandDraw::new(ctx, layout, camera, task_bundles)?,
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

    /// Add this frame's hair dynamics (the steps in `table`, of the characters in
    /// `simulated`) and hair mesh texture rebuilds (before [`Self::add`]).
    pub fn add_updates<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes,
        jobs: &'a [hair_mesh_update::UpdateJob<'a>],
        dynamics: Option<(&'a Buffer, &[hair_dynamics::SimulatedCharacter<'a>])>,
    ) {
        let poses = match dynamics {
            Some((table, simulated)) => self.hair_dynamics.add(g, table, simulated),
            None => Vec::new(),
        };
        self.hair_mesh_update.add(g, r, jobs, &poses);
    }

    /// Add the builds of this frame's requested density volumes (after the updates, before
    /// [`Self::add`]): `volumes` are their cells, in the order of the jobs in `table`.
    pub fn add_density_volumes<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes,
        sets: PassSets<'a>,
        (table, volumes, most_bundles): (&'a Buffer, &[&'a Buffer], u32),
    ) {
        self.density_volume
            .add(g, r, sets, table, volumes, most_bundles);
    }

    /// Add the LHS baseline's skinning for frame slot `slot` (before [`Self::add`]).
    pub fn add_lhs_skin<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes,
        state: &'a mut lhs_skin::LhsState,
        slot: usize,
    ) -> GpuResult<()> {
        self.lhs_skin.add(g, r, state, slot)
    }

    /// Check and compile what `mode` needs, before a frame uses it.
    pub fn prepare_transparency(&mut self, mode: super::Transparency) -> GpuResult<()> {
        self.transparency.prepare(mode)
    }

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.strands.has_mesh_path()
    }

    /// Whether the software rasterizer is available.
    pub fn has_software_raster(&self) -> bool {
        self.soft.is_some()
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

    /// Add the frame's passes to `g`.
    pub fn add<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        mut inp: FrameInputs<'a>,
    ) -> GpuResult<()> {
        self.add_before_drawing(g, r, &inp)?;
        TemporalFeature::add_clear(g, r.visibility);
        let soft = inp.bundles > 0 && inp.raster.uses_software();
        // Bundles drawn as hardware strips: every one without the software rasterizer, the
        // thick ones with `auto` (never the static and LHS paths' stored strands, which all go
        // to software). They are drawn in the opaque pass, or with transparency in its passes.
        let stored = matches!(inp.path, RenderPath::Static | RenderPath::Lhs);
        let hardware = inp.bundles > 0
            && match inp.raster {
                super::soft::StrandRaster::Hardware => true,
                super::soft::StrandRaster::Auto { .. } => !stored,
                super::soft::StrandRaster::Software { .. } => false,
            };
        let transparent = hardware && inp.transparency != super::Transparency::Opaque;
        let query = inp.mesh_query.take();
        // Far hair drawn from density volumes goes over the opaque pass, and then takes over
        // its MSAA resolve.
        let opaque_strands = hardware && !transparent;
        let volumes = inp.volume_slots > 0;
        let query = self.add_opaque(
            g,
            r,
            &inp,
            (opaque_strands, opaque_strands && !volumes),
            query,
        );
        if volumes {
            let flags = (opaque_strands, inp.raster.uses_software());
            self.volume_hair
                .add(g, r, inp.sets, inp.volume_slots, flags);
        }
        if transparent {
            let draw = TransparentDraw {
                mode: inp.transparency,
                sets: inp.sets,
                bundles: inp.bundles,
                path: inp.path,
                size: inp.size,
                mesh_query: query,
            };
            self.transparency.add_layers(g, r, draw)?;
        } else if soft {
            let pixels = inp.size.0 as u64 * inp.size.1 as u64;
            TransparencyPass::add_kbuffer_clear(g, r, inp.kbuffer_budget, pixels);
        }
        if soft {
            self.add_software(g, r, &inp)?;
        }
        if transparent || soft {
            let peel = matches!(inp.transparency, super::Transparency::DepthPeeling { .. });
            self.transparency.add_resolve(g, r, peel, inp.sets)?;
        }
        inp.temporal_feature.add(g, temporal_inputs(r, &inp));
        Ok(())
    }

    /// What runs before the camera draws: statistics cleared, skinning, the root probe, the
    /// light's passes, the camera's culling and LoD and, on the compute path, its generation.
    fn add_before_drawing<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
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
        self.skin.add(g, r, inp.sets, inp.skin);
        if let Some(probe) = inp.probe {
            self.root_probe.add(g, r, inp.sets, probe);
        }
        if let Some(mode) = inp.shadow {
            self.add_light(g, r, inp, mode)?;
            // The camera's statistics start from zero again; the light's are kept.
            if !keep_args {
                add_clear_args_for_camera(g, r);
            }
        }
        if inp.bundles > 0 && !keep_args {
            self.lod.add(g, r, (inp.sets, "cull"), inp.bundles, compute);
        }
        if compute {
            let view = GenerateView::Camera;
            self.generate.add(g, r, inp.sets, inp.bundles, view);
        }
        Ok(())
    }

    /// The light's passes of a frame with shadows in `mode`: the light's generation (compute
    /// path), then its hardware or software map passes.
    fn add_light<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        inp: &FrameInputs<'a>,
        mode: ShadowMode,
    ) -> GpuResult<()> {
        let soft_light = inp.light_raster == LightRaster::Software;
        if inp.bundles > 0 && matches!(inp.path, RenderPath::Mesh | RenderPath::Compute) {
            let pool = inp.path == RenderPath::Compute;
            self.lod
                .add(g, r, (inp.light_sets, "shadow cull"), inp.bundles, pool);
        }
        if inp.bundles > 0 && inp.path == RenderPath::Compute {
            let view = match soft_light {
                true => GenerateView::LightSoftware,
                false => GenerateView::Light,
            };
            self.generate.add(g, r, inp.light_sets, inp.bundles, view);
        }
        let draw = ShadowDraw {
            mode,
            sets: inp.light_sets,
            bundles: inp.bundles,
            path: inp.path,
            props: inp.light_props,
        };
        if soft_light {
            let soft = self.soft.as_ref().ok_or_else(no_soft)?;
            soft.shadow.add(g, r, (&self.shadow, &soft.raster), draw);
        } else {
            self.shadow.add(g, r, draw);
        }
        Ok(())
    }

    /// The software rasterizer's camera passes: the segments not yet appended (the mesh
    /// path's segment pass; the static and LHS paths' stored strands), binning and raster.
    fn add_software<'a>(
        &'a self,
        g: &mut FrameGraph<'a>,
        r: &FrameRes<'a>,
        inp: &FrameInputs<'a>,
    ) -> GpuResult<()> {
        let soft = self.soft.as_ref().ok_or_else(no_soft)?;
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

    /// The opaque pass: props, scalps and, with `strands`, the hardware-drawn strands; with
    /// `resolve`, the colour's MSAA resolve ends here (MSAA frames draw no software strands).
    /// Returns the mesh query when this pass did not use it.
    fn add_opaque<'a>(
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
