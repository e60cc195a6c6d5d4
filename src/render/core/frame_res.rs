//! The frame's resources in its graph: what a frame imports (targets, shadow maps, working
//! buffers, history) and creates (transients sized for its settings), as handles every pass
//! declares its uses with. Features size their transients; this table only holds them.

use super::graph::{FrameGraph, Res, TransientBuffer};
use super::shared::GenerateArgs;
use super::targets::{RenderTargets, ShadowMaps};
use super::workspace::Workspace;
use crate::vk::{Access, Buffer, Image, ImageDesc};

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

impl FrameTransients {
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

/// The temporal passes' resources besides the visibility words (graph handles).
#[derive(Clone, Copy)]
pub struct TemporalRes {
    /// Motion vectors.
    pub motion: Res,
    /// The frame's colour as a buffer (accumulation).
    pub frame_color: Res,
    /// Deformation residuals of the compute path's vertices.
    pub vertex_motion: Res,
    /// Deformation residuals of the software rasterizer's segments.
    pub segment_motion: Res,
    /// The history read and the one written (placeholders without accumulation).
    pub history: (Res, Res),
}

impl TemporalRes {
    /// The vertex residuals of `t`, if the frame has motion vectors.
    pub fn vertex_motion(t: Option<Self>) -> Option<Res> {
        t.map(|t| t.vertex_motion)
    }

    /// The segment residuals of `t`, if the frame has motion vectors.
    pub fn segment_motion(t: Option<Self>) -> Option<Res> {
        t.map(|t| t.segment_motion)
    }

    /// Create the temporal transients (`buffers`, from `render::temporal::transient_buffers`:
    /// visibility, motion, frame colour, residuals) and import the history buffers: the
    /// visibility words and the rest, in frames with motion vectors (`motion`).
    pub fn create<'a>(
        g: &mut FrameGraph<'a>,
        buffers: &[TransientBuffer; 5],
        motion: bool,
        history: Option<(&'a Buffer, &'a Buffer)>,
    ) -> Option<(Res, Self)> {
        let [
            visibility,
            motion_vectors,
            frame_color,
            vertex_motion,
            segment_motion,
        ] = buffers.map(|d| g.create_buffer(d));
        let history = history.map(|(read, write)| {
            (
                g.import_buffer("temporal history read", read),
                g.import_buffer("temporal history written", write),
            )
        });
        motion.then_some((
            visibility,
            TemporalRes {
                motion: motion_vectors,
                frame_color,
                vertex_motion,
                segment_motion,
                history: history.unwrap_or((frame_color, frame_color)),
            },
        ))
    }
}

/// Add the pass that zeroes `args` (indirect arguments and statistics).
pub fn add_clear_args<'a>(g: &mut FrameGraph<'a>, r: &FrameRes<'a>) {
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
pub fn add_clear_args_for_camera<'a>(g: &mut FrameGraph<'a>, r: &FrameRes<'a>) {
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

/// Add a pass named `name` copying the camera's depth target into the soft depth buffer
/// (`glsl/soft_depth.glsl`: a float per pixel, row by row), which exists when the camera's
/// strands go through the software rasterizer. Single-sampled targets only: MSAA frames draw
/// no software strands.
pub fn add_depth_copy<'a>(g: &mut FrameGraph<'a>, r: &FrameRes<'a>, name: &'static str) {
    let (depth, soft_depth) = (r.images.depth, r.soft_depth);
    g.pass(name)
        .read(r.depth, Access::TransferRead)
        .discard(r.soft_depth, Access::TransferWrite)
        .record(move |rec, res| {
            rec.copy_image_to_buffer_at(depth, res.buffer(soft_depth)?, 0);
            Ok(())
        });
}
