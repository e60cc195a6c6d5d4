//! The CPU/GPU contract, defined once: constants, binding numbers and every struct the shaders
//! share with Rust. [`glsl_header`] emits them as the GLSL include `shared.glsl` that every
//! shader is compiled with (a copy is kept in `glsl/generated/shared.glsl` for reading; a test
//! keeps it current). `tests/glsl_layout.rs` checks that the std430 layout of each emitted
//! struct equals the Rust `#[repr(C)]` layout, field by field.

use bytemuck::{Pod, Zeroable};

use crate::bake::blue_noise::MAX_STRANDS_PER_BUNDLE;
use crate::bake::{BundleDesc, MeshInfo, SLICES_PER_SEGMENT};
use crate::model::style::HairStyle;

/// Threads of a strand-building workgroup (`s` of paper 003 sec. 3.6.2), both paths.
pub const STRAND_GROUP_SIZE: u32 = 32;
/// Largest vertex level: `2^6 = 64` segments (2 vertices per thread of a strand workgroup).
pub const MAX_VERTS_LOG2: u32 = 6;
/// Segments of a strand at the largest vertex level.
pub const MAX_SEGMENTS: u32 = 1 << MAX_VERTS_LOG2;
/// Bundles one task-shader workgroup can cull and compact (payload capacity).
pub const TASK_PAYLOAD_BUNDLES: u32 = 32;
/// Low bits of a payload place ([`TaskPayload::place`]) that hold the lane: a strand
/// workgroup's strands are lanes `0..STRAND_GROUP_SIZE`.
pub const PAYLOAD_LANE_BITS: u32 = 5;
const _: () = assert!(STRAND_GROUP_SIZE <= 1 << PAYLOAD_LANE_BITS);
/// Invocations of a cull workgroup (one bundle each).
pub const CULL_GROUP_SIZE: u32 = 64;
/// Threads of a scan workgroup.
pub const SCAN_THREADS: u32 = 256;
/// Elements one scan workgroup sums (4 per thread).
pub const SCAN_BLOCK: u32 = 1024;
/// Workgroups per dispatch row (Vulkan guarantees 65535 in x); larger counts use y.
pub const DISPATCH_ROW: u32 = 65535;
/// `CharacterRecord::flags`: the character is drawn this frame.
pub const CHARACTER_VISIBLE: u32 = 1;
/// `CharacterRecord::flags`: the character's hair is drawn as its density volume only (the
/// volume tier's far characters): no strands in any view.
pub const CHARACTER_VOLUME_ONLY: u32 = 2;
/// `CharacterRecord::volume.w` bit: the record's density volume fields are valid.
pub const VOLUME_BUILT: u32 = 1;
/// `CharacterRecord::volume.w` bit: the ambient term of this character's strands is
/// occluded by its density volume (`shade::volume::ambient_visibility`).
pub const VOLUME_OCCLUSION: u32 = 2;
/// `CharacterRecord::volume.w` bit: the far hair's march skips the volume's empty bricks
/// (`VolumeTier::skip_empty`).
pub const VOLUME_SKIP_EMPTY: u32 = 4;

pub use crate::shade::lut::{
    MARSCHNER_LUT_D, MARSCHNER_LUT_PHI, MARSCHNER_LUT_TRT_SCALE, SCATTER_LUT_THETA,
    SHADING_LUT_HEIGHT, SHADING_LUT_WIDTH,
};

/// Software rasterizer: side of a square screen tile in pixels (one raster workgroup).
pub const SOFT_TILE: u32 = 16;
/// Software rasterizer: most fragments per pixel it keeps sorted in a tile's shared memory
/// (`256 x 8 x 8` bytes; the rest merge into the tail).
pub const SOFT_MAX_K: u32 = 8;
/// K-buffer tail: fixed-point scale of its sums (`oit.glsl`): integer adds make the tail
/// independent of the order fragments arrive in. One fragment adds at most 5.6 `OIT_FIXED` per
/// lane (optical depth is capped by the 8-bit alpha), so a 32-bit lane holds about 740 000
/// evicted fragments per pixel.
pub const OIT_FIXED: f32 = 1024.0;
/// Software rasterizer: a fragment behind fragments of its pixel whose transmittance together
/// is below this is hidden and dropped (`render::soft_pixel::PixelFragments`, `soft_raster.comp`):
/// under half an 8-bit step of light comes through.
pub const SOFT_HIDDEN_TRANSMITTANCE: f32 = 1.0 / 512.0;
/// Threads of the software rasterizer's binning workgroups (one segment each).
pub const SOFT_BIN_GROUP: u32 = 256;
/// `bundle_lods[].y` bit: the bundle is drawn by the software rasterizer (the low byte is the
/// vertex level e).
pub const LOD_SOFT: u32 = 256;

pub use crate::reference::lod::{LOD_DEMAND_UNIT, LOD_LEAST_PRESSURE};

/// Opacity of one strand to the light: fibres pass part of the light (the TT lobe), so one
/// strand does not block it all.
pub const STRAND_SHADOW_OPACITY: f32 = 0.5;
/// Invocations of one `hair_mesh_update.comp` workgroup.
pub const DEFORM_GROUP_SIZE: u32 = 64;
/// Invocations of one `hair_dynamics.comp` workgroup (one workgroup simulates one character)
/// on a GPU: a character's columns and constraints spread over more lanes, for less latency.
pub const DYNAMICS_GROUP_SIZE_GPU: u32 = 128;
/// The same on a CPU device (lavapipe): each barrier switches between the workgroup's 8-lane
/// vectors, so fewer invocations cost less (measured on lavapipe: 16 threads 0.93-1.01x the
/// CPU solver's time, 64 threads 1.23x).
pub const DYNAMICS_GROUP_SIZE_CPU: u32 = 16;

/// Fixed-point scale of the density volume's cells: a cell adds `round(length * VOLUME_FIXED)`
/// for strand length `length` (object units), and the same for each component of its flow.
pub const VOLUME_FIXED: f32 = 16384.0;
/// Bits per axis of `CharacterRecord::volume.z` (the volume's cell counts, packed).
pub const VOLUME_DIMS_BITS: u32 = 10;
/// Invocations of one `density_volume.comp` workgroup (one bundle; a strand each).
pub const VOLUME_GROUP_SIZE: u32 = 32;
/// The density build's second dispatch (push constant `w`): each job's occupancy mask
/// (`reference::volume::occupancy_of`), one bit per brick, as words after its cells.
pub const DENSITY_PASS_OCCUPANCY: u32 = 1;
/// Most colliders one simulated character may have (the solver keeps them in shared memory).
pub const MAX_SIM_COLLIDERS: u32 = 16;
/// `SimCollider::shape.x`: an ellipsoid (`a`: centre, `b`: radii).
pub const COLLIDER_ELLIPSOID: u32 = 0;
/// `SimCollider::shape.x`: a capsule (`a`, `b`: axis ends; `a.w`: radius).
pub const COLLIDER_CAPSULE: u32 = 1;
/// `SimCollider::shape.x`: a radial-map head (`a.w`: margin; `b`: map centre; the job's head
/// map).
pub const COLLIDER_HEAD: u32 = 2;
/// Largest k-buffer budget (nodes per pixel).
pub const MAX_OIT_BUDGET: u32 = 16;
/// Opacity of one full-detail strand over the part of a pixel it covers.
pub const STRAND_OPACITY: f32 = 0.7;
/// `SoftFields::mode`: hardware strips.
pub const RASTER_HARDWARE: u32 = 0;
/// `SoftFields::mode`: the software rasterizer.
pub const RASTER_SOFTWARE: u32 = 1;
/// `SoftFields::mode`: software or hardware per bundle.
pub const RASTER_AUTO: u32 = 2;
/// `SoftFields::mode` of the light's view: every bundle to the software rasterizer, as
/// depth and coverage only (no shading).
pub const RASTER_LIGHT: u32 = 3;
/// Fixed-point scale of the software shadow pass's opacity sums (`soft_shadow.comp`): opacity
/// `o` adds `round(o * SHADOW_OPACITY_FIXED)`.
pub const SHADOW_OPACITY_FIXED: f32 = 4096.0;
/// Temporal: the visibility id of a pixel no surface covers (the background).
pub const VISIBILITY_EMPTY: u32 = u32::MAX;
/// Temporal: visibility ids with this bit are prop instances (the rest, characters).
pub const VISIBILITY_PROP: u32 = 1 << 31;
/// Temporal: a character's solid surface (its scalp), not its hair.
pub const VISIBILITY_SOLID: u32 = 1 << 30;
/// Temporal: the character slot or prop instance of a visibility id (16 bits: the software
/// rasterizer's segments carry it in half a word).
pub const VISIBILITY_INDEX: u32 = (1 << 16) - 1;
/// Temporal: the visibility word (`temporal.glsl`, `render::temporal::VisibilityWord`) keeps
/// the depth's float bits shifted right by this (24 bits: depths lie in [0, 1], so the top two
/// bits are zero).
pub const VISIBILITY_DEPTH_SHIFT: u32 = 6;
/// Temporal: steps per pixel of the visibility word's deformation residual (two signed 11-bit
/// fields: +-128 pixels in eighths).
pub const VISIBILITY_RESIDUAL_STEPS: f32 = 8.0;
/// Temporal: the current frame's weight on a solid surface (scalp, prop) moving by
/// [`TEMPORAL_SOLID_MOTION`] pixels a frame or more (still ones take the tuning's weight; in
/// between it grows linearly): a long history blurs and lags moving solid edges, which do not
/// flicker like strands.
pub const TEMPORAL_SOLID_MOVING_WEIGHT: f32 = 0.5;
/// Temporal: the motion, pixels a frame, from which a solid surface takes
/// [`TEMPORAL_SOLID_MOVING_WEIGHT`].
pub const TEMPORAL_SOLID_MOTION: f32 = 0.25;
/// Temporal: threads per side of the temporal passes' square workgroups.
pub const TEMPORAL_GROUP: u32 = 16;
/// `TransparencyFields::mode`: opaque strands.
pub const TRANSPARENCY_OPAQUE: u32 = 0;
/// `TransparencyFields::mode`: k-buffer OIT.
pub const TRANSPARENCY_KBUFFER: u32 = 1;
/// `TransparencyFields::mode`: depth peeling.
pub const TRANSPARENCY_PEELING: u32 = 2;
/// `ShadowFields::mode`: no shadows.
pub const SHADOW_OFF: u32 = 0;
/// `ShadowFields::mode`: deep opacity maps.
pub const SHADOW_DEEP_OPACITY: u32 = 1;
/// `ShadowFields::mode`: approximate deep shadow maps.
pub const SHADOW_APPROXIMATE: u32 = 2;
/// `GpuBundleLod::y` (`bundle_lods[].y`): the vertex level `e` is the low byte.
pub const LOD_LEVEL_MASK: u32 = 255;
/// Invocations of one LHS skinning workgroup (`lhs_skin.comp`).
pub const LHS_GROUP_SIZE: u32 = 64;

/// Descriptor set 0: per-frame data and the crowd's tables.
pub const SET_FRAME: u32 = 0;
/// Descriptor set 1: the bindless texture arrays (one element per character slot).
pub const SET_TEXTURES: u32 = 1;

/// Bindings of set 0 ([`SET_FRAME`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum FrameBinding {
    /// `FrameBlock` uniform: camera, planes, LoD settings, light, counts.
    Frame = 0,
    /// `CharacterRecord[]`: one per character slot.
    Characters = 1,
    /// `GpuBundle[]`: every bundle of every character.
    Bundles = 2,
    /// `vec2[]` root samples: quad set, then triangle set.
    RootSamples = 3,
    /// `uvec4[]` per-bundle LoD decision (strands, e, gamma bits, thickness bits).
    BundleLods = 4,
    /// `uvec4[]` per-bundle exclusive prefix sums (strand, vertex slot, draw vertex, group).
    BundleOffsets = 5,
    /// `uvec4[]` block sums of the multi-level scan.
    ScanScratch = 6,
    /// `GenerateArgs`: indirect arguments and frame statistics.
    Args = 7,
    /// `HairVertex[]`: the compute path's generated-vertex pool.
    Vertices = 8,
    /// `PropVertex[]`: static triangle meshes (bodies, ground).
    PropVertices = 9,
    /// `PropInstance[]`: this frame's placed props.
    PropInstances = 10,
    /// Shadow map: depth of the hair nearest the light (sampled, `shadow_lookup.glsl`).
    ShadowHairDepth = 11,
    /// Shadow map: depth of the opaque props nearest the light.
    ShadowPropDepth = 12,
    /// Deep opacity map: hair opacity in 4 layers behind the hair depth (RGBA).
    ShadowLayers = 13,
    /// K-buffer OIT: `K` nodes per pixel (`uint64`: depth bits << 32 | packed colour), kept
    /// sorted nearest first by `oit.frag` (`oit.glsl`).
    OitNodes = 14,
    /// K-buffer OIT: per pixel, the fixed-point sums of the fragments evicted past the budget
    /// (premultiplied rgb, optical depth).
    OitTail = 15,
    /// Depth peeling: per pixel, the previous layer's depth, then (second half) the opaque
    /// depth.
    PeelDepth = 16,
    /// Depth peeling: per pixel, premultiplied colour and opacity composited front to back.
    PeelAccum = 17,
    /// The Marschner lookup texture (`shade::lut`, sampled bilinearly).
    ShadingLut = 18,
    /// Software rasterizer: `SoftSegment[]` projected, shaded strand segments (bounded by
    /// `SoftFields::segment_budget`).
    SoftSegments = 19,
    /// Software rasterizer: per screen tile `uvec4` (segments touching it, first entry,
    /// scatter cursor, entries kept).
    SoftTiles = 20,
    /// Software rasterizer: `uint[]` segment indices, tile by tile (bounded by
    /// `SoftFields::tile_entry_budget`).
    SoftEntries = 21,
    /// Software rasterizer: per pixel, the opaque depth (`float`) the strands are tested
    /// against.
    SoftDepth = 22,
    /// Software shadows: per light texel, the depth of the nearest hair (`float` bits),
    /// copied into the hair depth map.
    SoftShadowDepth = 23,
    /// Software shadows: per light texel, the deep opacity layers (4 halves in a `uvec2`,
    /// the RGBA16F texel), copied into the layers map.
    SoftShadowLayers = 24,
    /// Temporal: per pixel, the nearest surface (`uint64` visibility word: depth, visibility
    /// id, deformation residual; `temporal.glsl`), the motion vectors' source.
    Visibility = 25,
    /// Temporal: per pixel, the screen motion to the previous frame (`uvec4`: motion x and y
    /// bits in pixels, visibility id, depth bits), written when read back.
    Motion = 26,
    /// Temporal: per pixel, the frame's colour (`uint`: RGBA8 sRGB, as the output image), then
    /// per pixel the accumulated colour (the same encoding).
    FrameColor = 27,
    /// Temporal: the accumulated history read: per pixel the colour (`uvec2`: rg and b
    /// halves), then per pixel the surface it showed (`uvec2`: visibility id, depth bits).
    HistoryIn = 28,
    /// Temporal: per pixel, the accumulated history written this frame.
    HistoryOut = 29,
    /// Temporal: per slot of the vertex pool, the deformation residual of the vertex (`uint`:
    /// two halves, pixels; `temporal.glsl`), written by the compute path with its vertices.
    VertexMotion = 30,
    /// Temporal: per software segment, its deformation residual (as `VertexMotion`).
    SegmentMotion = 31,
    /// `SkinRestVertex[]`: every skinned mesh's vertices at bind time.
    SkinRest = 32,
    // 33 was the skinned meshes' indices, read by props.vert until the skinned props were
    // drawn indexed (the indices are the index buffer now).
    /// `mat4[]`: this frame's skin matrices, character after character.
    SkinMatrices = 34,
    /// `SkinJob[]`: this frame's skinned mesh instances.
    SkinJobs = 35,
    /// `SkinnedVertex[]`: this frame's posed vertices, written by `skin.comp`, read by
    /// `props.vert`.
    SkinnedVertices = 36,
    /// `vec4[]` per crowd bundle: the root of its first strand placed by the GPU (w:
    /// character slot + 1), written by `root_probe.comp` when the frame probes roots.
    RootProbe = 37,
}

impl FrameBinding {
    /// Every binding, with its GLSL macro name.
    pub const ALL: [(FrameBinding, &'static str); 37] = [
        (FrameBinding::Frame, "BINDING_FRAME"),
        (FrameBinding::Characters, "BINDING_CHARACTERS"),
        (FrameBinding::Bundles, "BINDING_BUNDLES"),
        (FrameBinding::RootSamples, "BINDING_ROOT_SAMPLES"),
        (FrameBinding::BundleLods, "BINDING_BUNDLE_LODS"),
        (FrameBinding::BundleOffsets, "BINDING_BUNDLE_OFFSETS"),
        (FrameBinding::ScanScratch, "BINDING_SCAN_SCRATCH"),
        (FrameBinding::Args, "BINDING_ARGS"),
        (FrameBinding::Vertices, "BINDING_VERTICES"),
        (FrameBinding::PropVertices, "BINDING_PROP_VERTICES"),
        (FrameBinding::PropInstances, "BINDING_PROP_INSTANCES"),
        (FrameBinding::ShadowHairDepth, "BINDING_SHADOW_HAIR_DEPTH"),
        (FrameBinding::ShadowPropDepth, "BINDING_SHADOW_PROP_DEPTH"),
        (FrameBinding::ShadowLayers, "BINDING_SHADOW_LAYERS"),
        (FrameBinding::OitNodes, "BINDING_OIT_NODES"),
        (FrameBinding::OitTail, "BINDING_OIT_TAIL"),
        (FrameBinding::PeelDepth, "BINDING_PEEL_DEPTH"),
        (FrameBinding::PeelAccum, "BINDING_PEEL_ACCUM"),
        (FrameBinding::ShadingLut, "BINDING_SHADING_LUT"),
        (FrameBinding::SoftSegments, "BINDING_SOFT_SEGMENTS"),
        (FrameBinding::SoftTiles, "BINDING_SOFT_TILES"),
        (FrameBinding::SoftEntries, "BINDING_SOFT_ENTRIES"),
        (FrameBinding::SoftDepth, "BINDING_SOFT_DEPTH"),
        (FrameBinding::SoftShadowDepth, "BINDING_SOFT_SHADOW_DEPTH"),
        (FrameBinding::SoftShadowLayers, "BINDING_SOFT_SHADOW_LAYERS"),
        (FrameBinding::Visibility, "BINDING_VISIBILITY"),
        (FrameBinding::Motion, "BINDING_MOTION"),
        (FrameBinding::FrameColor, "BINDING_FRAME_COLOR"),
        (FrameBinding::HistoryIn, "BINDING_HISTORY_IN"),
        (FrameBinding::HistoryOut, "BINDING_HISTORY_OUT"),
        (FrameBinding::VertexMotion, "BINDING_VERTEX_MOTION"),
        (FrameBinding::SegmentMotion, "BINDING_SEGMENT_MOTION"),
        (FrameBinding::SkinRest, "BINDING_SKIN_REST"),
        (FrameBinding::SkinMatrices, "BINDING_SKIN_MATRICES"),
        (FrameBinding::SkinJobs, "BINDING_SKIN_JOBS"),
        (FrameBinding::SkinnedVertices, "BINDING_SKINNED_VERTICES"),
        (FrameBinding::RootProbe, "BINDING_ROOT_PROBE"),
    ];

    /// What the binding holds.
    pub fn kind(self) -> crate::vk::DescriptorKind {
        use crate::vk::DescriptorKind;
        match self {
            FrameBinding::Frame => DescriptorKind::UniformBuffer,
            FrameBinding::ShadowHairDepth
            | FrameBinding::ShadowPropDepth
            | FrameBinding::ShadowLayers
            | FrameBinding::ShadingLut => DescriptorKind::SampledImage,
            _ => DescriptorKind::StorageBuffer,
        }
    }
}

/// Bindings of the hair mesh update pass's own set (`passes/hair_mesh_update.rs`,
/// `glsl/hair_mesh_update.comp`): one set per animated character and frame slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum DeformBinding {
    /// `DeformParams`: decode box and counts.
    Params = 0,
    /// `vec4[]` layer vertex positions, layer-major (written by the CPU each frame).
    Positions = 1,
    /// `uint[]` root-slice texel -> vertex column (`EMPTY_TEXEL` where none).
    TexelVertex = 2,
    /// `uint[]` first styling term of each vertex (vertices + 1 entries).
    StylingOffsets = 3,
    /// `StylingTerm[]`.
    StylingTerms = 4,
    /// `uvec2[]` out: hair mesh texture texels (RGBA16 UNORM packed), copied into the texture.
    PositionTexels = 5,
    /// `uvec2[]` out: u-texture texels (RGBA16 SNORM packed).
    UTexels = 6,
    /// `uvec2[]` out: v-texture texels.
    VTexels = 7,
}

impl DeformBinding {
    /// Every binding, with its GLSL macro name.
    pub const ALL: [(DeformBinding, &'static str); 8] = [
        (DeformBinding::Params, "DEFORM_PARAMS"),
        (DeformBinding::Positions, "DEFORM_POSITIONS"),
        (DeformBinding::TexelVertex, "DEFORM_TEXEL_VERTEX"),
        (DeformBinding::StylingOffsets, "DEFORM_STYLING_OFFSETS"),
        (DeformBinding::StylingTerms, "DEFORM_STYLING_TERMS"),
        (DeformBinding::PositionTexels, "DEFORM_POSITION_TEXELS"),
        (DeformBinding::UTexels, "DEFORM_U_TEXELS"),
        (DeformBinding::VTexels, "DEFORM_V_TEXELS"),
    ];
}

/// Bindings of the LHS skinning pass's own set (`glsl/lhs_skin.comp`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum LhsBinding {
    /// `HairVertex[]` the stored strands at rest.
    Rest = 0,
    /// `LhsWeights[]` per strand.
    Weights = 1,
    /// `vec4[]` per guide vertex: its displacement from rest this frame.
    GuideDelta = 2,
    /// `HairVertex[]` out: the vertex pool.
    Out = 3,
}

impl LhsBinding {
    /// Every binding, with its GLSL macro name.
    pub const ALL: [(LhsBinding, &'static str); 4] = [
        (LhsBinding::Rest, "LHS_REST"),
        (LhsBinding::Weights, "LHS_WEIGHTS"),
        (LhsBinding::GuideDelta, "LHS_GUIDE_DELTA"),
        (LhsBinding::Out, "LHS_OUT"),
    ];
}

/// One stored strand's guides (slots) and weights (`reference::lhs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LhsWeights {
    /// Guide slots (xyz; w unused).
    pub guides: [u32; 4],
    /// Weights (xyz, sum 1; w unused).
    pub weights: [f32; 4],
}

/// Decode box and sizes of one animated character (`DeformBinding::Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DeformParams {
    /// xyz: position of texel value 0 (`MeshInfo::pos_origin`).
    pub origin: [f32; 4],
    /// xyz: extent of the box.
    pub extent: [f32; 4],
    /// x root-slice texels, y layers, z vertices per layer, w unused.
    pub counts: [u32; 4],
}

/// Bindings of set 1 ([`SET_TEXTURES`]): the five textures of paper 003 Table 1, each a
/// bindless array indexed by the character's texture slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum TextureBinding {
    /// Hair mesh texture (3D).
    Position = 0,
    /// uv-texture (2D).
    Uv = 1,
    /// w-texture (3D).
    W = 2,
    /// u-texture (3D).
    U = 3,
    /// v-texture (3D).
    V = 4,
}

impl TextureBinding {
    /// Every binding in Table 1 order, with its GLSL macro name.
    pub const ALL: [(TextureBinding, &'static str); 5] = [
        (TextureBinding::Position, "BINDING_TEX_POSITION"),
        (TextureBinding::Uv, "BINDING_TEX_UV"),
        (TextureBinding::W, "BINDING_TEX_W"),
        (TextureBinding::U, "BINDING_TEX_U"),
        (TextureBinding::V, "BINDING_TEX_V"),
    ];
}

/// One field of a struct shared with GLSL.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuField {
    /// Field name (same in Rust and GLSL).
    pub name: &'static str,
    /// GLSL type: a scalar/vector/matrix type or another shared struct's name.
    pub glsl: &'static str,
    /// Array length, 0 for a plain field.
    pub array: usize,
    /// Byte offset in the Rust `#[repr(C)]` struct.
    pub offset: usize,
}

/// A `#[repr(C)]` struct that GLSL declares from [`GpuStruct::fields`].
pub trait GpuStruct: Pod {
    /// GLSL struct name.
    const GLSL_NAME: &'static str;
    /// Fields in declaration order.
    fn fields() -> Vec<GpuField>;
}

/// Implement [`GpuStruct`] for a `#[repr(C)]` type from its field list; field names are
/// checked by `offset_of!` at compile time, offsets and size by `tests/glsl_layout.rs`.
macro_rules! gpu_struct {
    ($ty:ty as $name:literal { $($field:ident : $glsl:literal $([$n:expr])?),* $(,)? }) => {
        impl GpuStruct for $ty {
            const GLSL_NAME: &'static str = $name;
            fn fields() -> Vec<GpuField> {
                vec![$(GpuField {
                    name: stringify!($field),
                    glsl: $glsl,
                    array: gpu_struct!(@len $($n)?),
                    offset: std::mem::offset_of!($ty, $field),
                }),*]
            }
        }
    };
    (@len) => { 0 };
    (@len $n:expr) => { $n as usize };
}

gpu_struct!(MeshInfo as "MeshInfo" {
    pos_origin: "vec4", pos_extent: "vec4", uv_origin_extent: "vec4", root_size: "uvec2",
    layers: "uint", bundle_count: "uint",
});

gpu_struct!(HairStyle as "HairStyle" {
    seed: "uint", strand_width: "float", tip_width_ratio: "float", taper_power: "float",
    length_variation: "float", root_ramp: "float", clump_strength: "float", clump_power: "float",
    curl_radius: "float", curl_frequency: "float", curl_phase_jitter: "float",
    wave_amplitude: "float", wave_frequency: "float", wave_angle: "float",
    wave_phase_jitter: "float", frizz_amplitude: "float", frizz_frequency: "float",
    frizz_power: "float", density_by_area: "uint", color: "float"[3], roughness: "float",
    cuticle_tilt_degrees: "float",
});

gpu_struct!(BundleDesc as "BundleDesc" {
    origin: "uvec2", flags: "uint", rest_size: "float", density: "float", _pad: "uint"[3],
});

/// Per-view data of one frame (uniform block). Every field group is 16 bytes (or a multiple)
/// and 16-byte aligned, so std140 and std430 lay it out alike; shaders read every value by
/// name (`frame.lod.area_below`), never by a swizzle's position.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameBlock {
    /// World to clip.
    pub view_proj: [[f32; 4]; 4],
    /// The eye (world).
    pub eye: [f32; 3],
    /// Vertical resolution in pixels.
    pub pixels_high: f32,
    /// Unit direction toward the light.
    pub to_light: [f32; 3],
    /// `1 / tan(fov_y / 2)` of the view (0: orthographic).
    pub cot_half_fov: f32,
    /// width, height, 1/width, 1/height.
    pub viewport: [f32; 4],
    /// Frustum planes (inside where `dot(n, p) + d >= 0`).
    pub planes: [[f32; 4]; 6],
    /// Level of detail (eq. 7 and the strand caps).
    pub lod: LodFields,
    /// Sizes of the frame's tables.
    pub counts: CountFields,
    /// How strands are shaded.
    pub shading: ShadingFields,
    /// World to the light's clip space (the shadow maps; camera views only).
    pub light_view_proj: [[f32; 4]; 4],
    /// The hair's shadow maps.
    pub shadow: ShadowFields,
    /// How strands are composited.
    pub transparency: TransparencyFields,
    /// The software rasterizer (`render::StrandRaster`).
    pub soft: SoftFields,
    /// Motion vectors and temporal accumulation (`render::Temporal`).
    pub temporal: TemporalFields,
    /// Temporal: unjittered clip space of this frame to the previous frame's, for surfaces
    /// that did not move (the background; `CharacterRecord::clip_to_prev` for hair).
    pub clip_to_prev: [[f32; 4]; 4],
    /// Temporal: the unjittered world to clip of this frame.
    pub unjittered_view_proj: [[f32; 4]; 4],
    /// World to the light's clip space of the bodies' map (`render::shadow::LightView::fit_bodies`:
    /// fitted to the bodies the camera sees; the light's prop pass draws with it).
    pub body_view_proj: [[f32; 4]; 4],
    /// The bodies' shadow map.
    pub body_shadow: BodyShadowFields,
}

/// [`FrameBlock::lod`]: eq. 7's terms and the strand caps (`render::LodSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LodFields {
    /// Alpha of eq. 7 for strands.
    pub alpha_strands: f32,
    /// Alpha of eq. 7 for vertices.
    pub alpha_verts: f32,
    /// Lambda of eq. 7.
    pub lambda: f32,
    /// `tan(fov_y)` of eq. 7 (0: orthographic).
    pub tan_fov: f32,
    /// View height of orthographic views (world units).
    pub ortho_height: f32,
    /// The strand level's area term below this extent in pixels (`LodSettings::area_below`;
    /// 0 off).
    pub area_below: f32,
    /// Strands per square pixel of a bundle's extent (`LodSettings::strands_per_pixel`; 0
    /// off).
    pub strands_per_pixel: f32,
    /// Padding.
    pub _pad: f32,
}

/// [`FrameBlock::counts`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct CountFields {
    /// Bundles of all characters.
    pub bundles: u32,
    /// Character slots.
    pub slots: u32,
    /// LoD on (1) or off (0).
    pub lod_on: u32,
    /// Vertex pool budget (compute path, in `HairVertex` slots).
    pub vertex_budget: u32,
}

/// [`FrameBlock::shading`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ShadingFields {
    /// Shading model (`shade::ShadingModel`).
    pub model: u32,
    /// Thick-strand appearance term on (seed 000, `lod_appearance.glsl`).
    pub lod_appearance: u32,
    /// Multiple scattering on (`shade::scattering`).
    pub multiple_scattering: u32,
    /// Padding.
    pub _pad: u32,
}

/// [`FrameBlock::shadow`]: the hair's shadow maps.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ShadowFields {
    /// Shadow mode (`render::ShadowMode`: [`SHADOW_OFF`], [`SHADOW_DEEP_OPACITY`],
    /// [`SHADOW_APPROXIMATE`]).
    pub mode: u32,
    /// Shadow map resolution.
    pub resolution: u32,
    /// Padding.
    pub _pad: [u32; 2],
    /// Deep-opacity layer thickness (world units).
    pub layer_thickness: f32,
    /// Light depth range (far - near, world units).
    pub depth_range: f32,
    /// Opacity of one strand.
    pub strand_opacity: f32,
    /// Depth bias (world units).
    pub bias: f32,
}

/// [`FrameBlock::transparency`] (`render::Transparency`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct TransparencyFields {
    /// Mode: [`TRANSPARENCY_OPAQUE`], [`TRANSPARENCY_KBUFFER`], [`TRANSPARENCY_PEEL`].
    pub mode: u32,
    /// k-buffer nodes per pixel.
    pub kbuffer_nodes: u32,
    /// Samples per pixel of the targets.
    pub samples: u32,
    /// Padding.
    pub _pad: u32,
}

/// [`FrameBlock::soft`]: the software rasterizer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SoftFields {
    /// Mode: [`RASTER_HARDWARE`], [`RASTER_SOFTWARE`], [`RASTER_AUTO`], [`RASTER_LIGHT`].
    pub mode: u32,
    /// Fragments kept sorted per pixel.
    pub k: u32,
    /// Segment budget.
    pub segment_budget: u32,
    /// Tile entry budget.
    pub tile_entry_budget: u32,
    /// Auto split: bundles whose strands are drawn at most this many pixels wide go to
    /// software.
    pub auto_split_pixels: f32,
    /// Opacity of one strand.
    pub strand_opacity: f32,
    /// Padding.
    pub _pad: [u32; 2],
    /// Tiles per row.
    pub tiles_x: u32,
    /// Tile rows.
    pub tiles_y: u32,
    /// Padding.
    pub _pad2: [u32; 2],
}

/// [`FrameBlock::temporal`] (`render::Temporal`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct TemporalFields {
    /// Passes note the nearest surface per pixel (motion vectors).
    pub motion: u32,
    /// Accumulation on.
    pub accumulate: u32,
    /// History valid.
    pub history_valid: u32,
    /// The compute path's vertices carry deformation residuals.
    pub residuals: u32,
    /// This frame's sub-pixel jitter (pixels, in `view_proj`).
    pub jitter: [f32; 2],
    /// History weight of a fully trusted pixel.
    pub history_weight: f32,
    /// Colour clamp width for hair (standard deviations).
    pub hair_clamp: f32,
}

/// [`FrameBlock::body_shadow`]: the bodies' map.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BodyShadowFields {
    /// Resolution (0: no map this frame).
    pub resolution: f32,
    /// Depth range (world units).
    pub depth_range: f32,
    /// Depth bias (world units).
    pub bias: f32,
    /// Texel size (world units).
    pub texel: f32,
}

gpu_struct!(LodFields as "LodFields" {
    alpha_strands: "float", alpha_verts: "float", lambda: "float", tan_fov: "float",
    ortho_height: "float", area_below: "float", strands_per_pixel: "float", _pad: "float",
});
gpu_struct!(CountFields as "CountFields" {
    bundles: "uint", slots: "uint", lod_on: "uint", vertex_budget: "uint",
});
gpu_struct!(ShadingFields as "ShadingFields" {
    model: "uint", lod_appearance: "uint", multiple_scattering: "uint", _pad: "uint",
});
gpu_struct!(ShadowFields as "ShadowFields" {
    mode: "uint", resolution: "uint", _pad: "uvec2", layer_thickness: "float",
    depth_range: "float", strand_opacity: "float", bias: "float",
});
gpu_struct!(TransparencyFields as "TransparencyFields" {
    mode: "uint", kbuffer_nodes: "uint", samples: "uint", _pad: "uint",
});
gpu_struct!(SoftFields as "SoftFields" {
    mode: "uint", k: "uint", segment_budget: "uint", tile_entry_budget: "uint",
    auto_split_pixels: "float", strand_opacity: "float", _pad: "uvec2", tiles_x: "uint",
    tiles_y: "uint", _pad2: "uvec2",
});
gpu_struct!(TemporalFields as "TemporalFields" {
    motion: "uint", accumulate: "uint", history_valid: "uint", residuals: "uint",
    jitter: "vec2", history_weight: "float", hair_clamp: "float",
});
gpu_struct!(BodyShadowFields as "BodyShadowFields" {
    resolution: "float", depth_range: "float", bias: "float", texel: "float",
});
gpu_struct!(FrameBlock as "FrameBlock" {
    view_proj: "mat4", eye: "vec3", pixels_high: "float", to_light: "vec3",
    cot_half_fov: "float", viewport: "vec4", planes: "vec4"[6], lod: "LodFields",
    counts: "CountFields", shading: "ShadingFields", light_view_proj: "mat4",
    shadow: "ShadowFields", transparency: "TransparencyFields", soft: "SoftFields",
    temporal: "TemporalFields", clip_to_prev: "mat4", unjittered_view_proj: "mat4",
    body_view_proj: "mat4", body_shadow: "BodyShadowFields",
});

/// One character: where its bundles and textures are, how it is placed and styled.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CharacterRecord {
    /// Object to world.
    pub model: [[f32; 4]; 4],
    /// Texture decode constants.
    pub mesh: MeshInfo,
    /// Styling.
    pub style: HairStyle,
    /// Element of the bindless texture arrays (the character's slot, or its slot plus the
    /// crowd's capacity where an animated character's other texture set is current).
    pub texture_slot: u32,
    /// First bundle in the crowd's bundle table.
    pub first_bundle: u32,
    /// Number of bundles.
    pub bundle_count: u32,
    /// Strands per average bundle (`N` of eq. 8).
    pub strands_per_bundle: u32,
    /// Full-detail vertex level `e` (`2^e` segments).
    pub verts_log2: u32,
    /// [`CHARACTER_VISIBLE`].
    pub flags: u32,
    /// Uniform scale of `model` (widths and styling margins).
    pub model_scale: f32,
    /// Element of the textures of the previous frame's pose: `texture_slot` unless the hair
    /// mesh changed pose this frame (the generators then evaluate both for exact motion
    /// vectors).
    pub prev_texture_slot: u32,
    /// This frame's unjittered clip space to the previous frame's, for this character's
    /// surfaces (hair and scalp): the camera's motion and the character's own.
    pub clip_to_prev: [[f32; 4]; 4],
    /// World to the density volume's grid (cell `i` spans `[i, i + 1)` on each axis).
    pub world_to_volume: [[f32; 4]; 4],
    /// Density volume: xy its cells' device address ([`VolumeCell`]s, x fastest), z its cell
    /// counts packed ([`VOLUME_DIMS_BITS`] per axis, x lowest), w [`VOLUME_BUILT`] |
    /// [`VOLUME_OCCLUSION`] | [`VOLUME_SKIP_EMPTY`].
    pub volume: [u32; 4],
    /// Density volume shading: x strand width over a cell's volume and [`VOLUME_FIXED`]
    /// (a cell's fixed-point length times x is density times width, object units), y mean
    /// cell side (object units), z the volume tier's weight (0: strands only, 1: the volume
    /// only; between, a screen-door blend), w unused.
    pub volume_shading: [f32; 4],
}

gpu_struct!(CharacterRecord as "CharacterRecord" {
    model: "mat4", mesh: "MeshInfo", style: "HairStyle", texture_slot: "uint",
    first_bundle: "uint", bundle_count: "uint", strands_per_bundle: "uint", verts_log2: "uint",
    flags: "uint", model_scale: "float", prev_texture_slot: "uint", clip_to_prev: "mat4",
    world_to_volume: "mat4", volume: "uvec4", volume_shading: "vec4",
});

/// One cell of a density volume: x strand length, yzw flow (two's complement), all in units
/// of 1 / [`VOLUME_FIXED`] (object units); `reference::volume::DensityVolume`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct VolumeCell {
    /// Strand length.
    pub len: u32,
    /// Flow (`DensityVolume::flow` times the cell's volume), as `i32` bits.
    pub flow: [u32; 3],
}

gpu_struct!(VolumeCell as "VolumeCell" { len: "uint", flow: "uint"[3] });

/// One bundle of the crowd's bundle table: the baked [`BundleDesc`] plus its owner.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuBundle {
    /// Root-slice texel of the cell corner `(0, 0)`.
    pub origin: [u32; 2],
    /// Bit 0: triangle bundle.
    pub flags: u32,
    /// `h` of eq. 7.
    pub rest_size: f32,
    /// Strand density weight.
    pub density: f32,
    /// Character slot.
    pub character: u32,
    /// Bundle index within its mesh (seeds per-strand randomness, as in the CPU oracle).
    pub local_index: u32,
    /// Padding.
    pub _pad: u32,
}

gpu_struct!(GpuBundle as "GpuBundle" {
    origin: "uvec2", flags: "uint", rest_size: "float", density: "float", character: "uint",
    local_index: "uint", _pad: "uint",
});

impl GpuBundle {
    /// Bundle `local_index` of a mesh, owned by character slot `character`.
    pub fn new(b: &BundleDesc, character: u32, local_index: u32) -> Self {
        GpuBundle {
            origin: b.origin,
            flags: b.flags,
            rest_size: b.rest_size,
            density: b.density,
            character,
            local_index,
            _pad: 0,
        }
    }
}

/// What one frame generated; written by the GPU, read back after the frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct FrameStats {
    /// Bundles that passed culling.
    pub bundles_visible: u32,
    /// Strands LoD asked for.
    pub strands_demanded: u32,
    /// Strands drawn (less than demanded when the compute path's vertex pool overflowed).
    pub strands_drawn: u32,
    /// Strand triangles LoD asked for.
    pub triangles_demanded: u32,
    /// Strand triangles drawn.
    pub triangles_drawn: u32,
    /// Compute path: vertex slots asked for.
    pub vertex_slots_demanded: u32,
    /// Compute path: vertex slots written (<= the budget).
    pub vertex_slots_written: u32,
    /// Compute path: strand workgroups dispatched.
    pub groups: u32,
    /// Software rasterizer: segments generated for it.
    pub segments_demanded: u32,
    /// Software rasterizer: segments stored (<= the segment budget; the rest are dropped).
    pub segments_written: u32,
    /// Software rasterizer: (tile, segment) pairs the binning found.
    pub tile_entries_demanded: u32,
    /// Software rasterizer: (tile, segment) pairs stored (<= the entry budget).
    pub tile_entries_written: u32,
    /// The bundle LoD pass (`cull.comp`): segments the software bundles' LoD asks for at
    /// most (strands times segments), in units of [`LOD_DEMAND_UNIT`], rounded up per
    /// workgroup.
    pub soft_demand: u32,
    /// The same pass: one strand's segments per visible software bundle (what eq. 8's
    /// ceiling can add), in units of [`LOD_DEMAND_UNIT`].
    pub soft_slack: u32,
    /// The same pass: vertex slots the hardware bundles' LoD asks for (the compute path's
    /// pool), in units of [`LOD_DEMAND_UNIT`].
    pub pool_demand: u32,
    /// The same pass: one strand's vertex slots per visible hardware bundle, in units of
    /// [`LOD_DEMAND_UNIT`].
    pub pool_slack: u32,
}

gpu_struct!(FrameStats as "FrameStats" {
    bundles_visible: "uint", strands_demanded: "uint", strands_drawn: "uint",
    triangles_demanded: "uint", triangles_drawn: "uint", vertex_slots_demanded: "uint",
    vertex_slots_written: "uint", groups: "uint", segments_demanded: "uint",
    segments_written: "uint", tile_entries_demanded: "uint", tile_entries_written: "uint",
    soft_demand: "uint", soft_slack: "uint", pool_demand: "uint", pool_slack: "uint",
});

/// Indirect arguments of the compute path and the frame statistics of both paths.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GenerateArgs {
    /// `VkDispatchIndirectCommand` of `generate.comp` (xyz; w unused).
    pub dispatch: [u32; 4],
    /// `VkDrawIndirectCommand` of `strands.vert`.
    pub draw: [u32; 4],
    /// `VkDispatchIndirectCommand` of the software rasterizer's binning passes (one thread
    /// per stored segment; w unused).
    pub soft_dispatch: [u32; 4],
    /// Statistics of the view being drawn (the camera's at the end of a frame).
    pub stats: FrameStats,
    /// The light's view's statistics, kept here before the camera's start from zero.
    pub light_stats: FrameStats,
}

gpu_struct!(GenerateArgs as "GenerateArgs" {
    dispatch: "uvec4", draw: "uvec4", soft_dispatch: "uvec4", stats: "FrameStats",
    light_stats: "FrameStats",
});

impl GenerateArgs {
    /// Byte offset of the dispatch arguments.
    pub const DISPATCH_OFFSET: u64 = std::mem::offset_of!(GenerateArgs, dispatch) as u64;
    /// Byte offset of the draw arguments.
    pub const DRAW_OFFSET: u64 = std::mem::offset_of!(GenerateArgs, draw) as u64;
    /// Byte offset of the software rasterizer's binning dispatch.
    pub const SOFT_DISPATCH_OFFSET: u64 = std::mem::offset_of!(GenerateArgs, soft_dispatch) as u64;
    /// Byte offset of `stats`.
    pub const STATS_OFFSET: u64 = std::mem::offset_of!(GenerateArgs, stats) as u64;
    /// Byte offset of `light_stats`.
    pub const LIGHT_STATS_OFFSET: u64 = std::mem::offset_of!(GenerateArgs, light_stats) as u64;
    /// Byte offset of `stats.segments_demanded`.
    pub const SEGMENTS_DEMANDED_OFFSET: u64 = (std::mem::offset_of!(GenerateArgs, stats)
        + std::mem::offset_of!(FrameStats, segments_demanded))
        as u64;
}

/// A generated strand vertex (compute path).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct HairVertex {
    /// xyz world position, w strand width.
    pub pos_width: [f32; 4],
    /// xyz unit tangent, w parameter `s` along the strand.
    pub tangent_s: [f32; 4],
}

gpu_struct!(HairVertex as "HairVertex" { pos_width: "vec4", tangent_s: "vec4" });

/// One projected, shaded strand segment for the software rasterizer (32 bytes), written by
/// the strand builders (`soft_segments.glsl`) and read by the binning and raster passes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SoftSegment {
    /// End a in pixels (y down, as `gl_FragCoord`).
    pub a: [f32; 2],
    /// Depth (0..1) of end a.
    pub za: f32,
    /// Low half: `packHalf2x16` of end b's depth minus end a's; high half: the visibility id
    /// of the segment's character (`temporal.glsl`).
    pub dz_id: u32,
    /// x: `packHalf2x16(b.xy - a.xy)`; y, z: colour of ends a and b (`pack_fragment`: sqrt
    /// RGB, alpha = the share of the drawn width the strand covers); w:
    /// `packHalf2x16(drawn width in pixels, strands it stands for)`.
    pub b: [u32; 4],
}

gpu_struct!(SoftSegment as "SoftSegment" { a: "vec2", za: "float", dz_id: "uint", b: "uvec4" });

/// A vertex of a prop mesh (bodies, ground): triangle lists, object space.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct PropVertex {
    /// xyz position, w 1.
    pub position: [f32; 4],
    /// xyz unit normal, w 0.
    pub normal: [f32; 4],
}

gpu_struct!(PropVertex as "PropVertex" { position: "vec4", normal: "vec4" });

/// One placed prop: transform and colour.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct PropInstance {
    /// Object to world.
    pub model: [[f32; 4]; 4],
    /// rgb linear colour, a unused.
    pub color: [f32; 4],
    /// This frame's unjittered clip space to the previous frame's for this prop (filled in
    /// by the renderer each frame).
    pub clip_to_prev: [[f32; 4]; 4],
    /// x: first posed vertex of a skinned instance in `SkinnedVertices` ([`SKIN_NONE`]: a
    /// static prop, pulled from `PropVertices`); yzw unused.
    pub skin: [u32; 4],
}

gpu_struct!(PropInstance as "PropInstance" { model: "mat4", color: "vec4", clip_to_prev: "mat4", skin: "uvec4" });

/// `PropInstance::skin.x` of a static prop.
pub const SKIN_NONE: u32 = u32::MAX;
/// Invocations per workgroup of `skin.comp`.
pub const SKIN_GROUP_SIZE: u32 = 64;

/// A skinned mesh's vertex at bind time (`skin::SkinVertex` on the GPU).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct SkinRestVertex {
    /// Position, mesh frame.
    pub position: [f32; 3],
    /// Linear RGB colour, unorm8 packed (`packUnorm4x8`).
    pub color: u32,
    /// Unit normal.
    pub normal: [f32; 3],
    /// Joints 0 and 1 (16 bits each, 0 low).
    pub joints01: u32,
    /// Weights of the four joints.
    pub weights: [f32; 4],
    /// x: joints 2 and 3; yzw unused.
    pub joints23: [u32; 4],
}

gpu_struct!(SkinRestVertex as "SkinRestVertex" {
    position: "vec3", color: "uint", normal: "vec3", joints01: "uint", weights: "vec4", joints23: "uvec4",
});

/// A posed vertex (written by `skin.comp`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct SkinnedVertex {
    /// Position, character frame.
    pub position: [f32; 3],
    /// The rest vertex's packed colour: RGBA8, linear RGB and the GGX roughness in alpha.
    pub color: u32,
    /// Unit normal.
    pub normal: [f32; 3],
    /// Unused.
    pub pad: u32,
}

gpu_struct!(SkinnedVertex as "SkinnedVertex" { position: "vec3", color: "uint", normal: "vec3", pad: "uint" });

/// One skinned mesh instance of a frame: which rest vertices, which matrices, where to.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct SkinJob {
    /// First rest vertex of the mesh in `SkinRest`.
    pub rest_first: u32,
    /// Its vertices.
    pub vertex_count: u32,
    /// First skin matrix of its character in `SkinMatrices`.
    pub matrix_first: u32,
    /// First posed vertex in `SkinnedVertices`.
    pub out_first: u32,
}

gpu_struct!(SkinJob as "SkinJob" { rest_first: "uint", vertex_count: "uint", matrix_first: "uint", out_first: "uint" });

/// Task shader -> mesh shader payload: up to [`TASK_PAYLOAD_BUNDLES`] visible bundles of one
/// task workgroup, compacted, with where each one's strands start among the mesh workgroups.
/// Bundles of one character and one vertex level may share a workgroup (the software
/// passes', `glsl/strands.task`): a run of them fills workgroups lane by lane.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TaskPayload {
    /// Per visible bundle: strands, vertex level e, gamma bits, thickness bits.
    pub lods: [[u32; 4]; TASK_PAYLOAD_BUNDLES as usize],
    /// Global bundle index of each visible bundle.
    pub bundle: [u32; TASK_PAYLOAD_BUNDLES as usize],
    /// Where each visible bundle's first strand is built: mesh workgroup `<<`
    /// [`PAYLOAD_LANE_BITS`] `|` lane; element `count` is the workgroups in all (lane 0).
    pub place: [u32; TASK_PAYLOAD_BUNDLES as usize + 1],
    /// Visible bundles.
    pub count: u32,
    /// Padding to a 16-byte multiple (std430 struct size).
    pub _pad: [u32; 2],
}

gpu_struct!(TaskPayload as "TaskPayload" {
    lods: "uvec4"[TASK_PAYLOAD_BUNDLES], bundle: "uint"[TASK_PAYLOAD_BUNDLES],
    place: "uint"[TASK_PAYLOAD_BUNDLES + 1], count: "uint", _pad: "uint"[2],
});

/// std430 `(size, alignment)` of a GLSL scalar, vector or matrix type.
pub fn std430_type(ty: &str) -> Option<(usize, usize)> {
    Some(match ty {
        "float" | "uint" | "int" => (4, 4),
        "vec2" | "uvec2" | "ivec2" => (8, 8),
        "vec3" | "uvec3" => (12, 16),
        "vec4" | "uvec4" => (16, 16),
        "mat4" => (64, 16),
        _ => return None,
    })
}

/// A struct's name and fields, for layout checks and emission.
pub struct StructInfo {
    /// GLSL name.
    pub name: &'static str,
    /// Fields.
    pub fields: Vec<GpuField>,
    /// Rust `size_of`.
    pub rust_size: usize,
}
/// One simulated hair mesh vertex at rest (`glsl/hair_dynamics.comp`, `dynamics::HairTopology`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SimVertex {
    /// xyz: authored position, character frame; w: the pose's w (the root thinning's cube root
    /// on the scalp layer, as `DeformState::set_pose` writes it; 0 above).
    pub rest: [f32; 4],
    /// x: rest distance to the vertex below; y: to the vertex two layers below; zw unused.
    pub lengths: [f32; 4],
}

/// One spacing constraint between two vertices of a layer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SimConstraint {
    /// First vertex.
    pub a: u32,
    /// Second vertex.
    pub b: u32,
    /// Rest distance.
    pub rest: f32,
    /// Padding.
    pub _pad: u32,
}

/// A collider in the character's frame ([`COLLIDER_ELLIPSOID`], [`COLLIDER_CAPSULE`],
/// [`COLLIDER_HEAD`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SimCollider {
    /// x: the kind; yzw unused.
    pub shape: [u32; 4],
    /// Per kind (see the kinds).
    pub a: [f32; 4],
    /// Per kind.
    pub b: [f32; 4],
    /// Head: character frame to the map's canonical frame.
    pub to_canonical: [[f32; 4]; 4],
    /// Head: the map's canonical frame to the character's.
    pub to_person: [[f32; 4]; 4],
    /// Character frame: a sphere (xyz centre, w radius) outside which the push-out is the
    /// identity (`Collider::bounding_sphere`).
    pub bound: [f32; 4],
}

/// One simulated vertex's state, world frame (w unused). The state buffer holds one per
/// vertex, then a `vec4` per vertex for the substep's positions being solved (`SimJob::solve`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SimState {
    /// Position.
    pub x: [f32; 4],
    /// Velocity.
    pub v: [f32; 4],
}

/// One character's strand density volume to build this frame (`glsl/density_volume.comp`,
/// the twin of `reference::volume::density_volume`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DensityJob {
    /// [`VolumeCell`]`[]`: the cells (x fastest), then one more whose length is what fell
    /// outside, then the occupancy mask's words (`reference::volume::occupancy_words`).
    pub cells: [u32; 2],
    /// Padding.
    pub _pad: [u32; 2],
    /// xyz: corner of cell (0, 0, 0), object units; w unused.
    pub origin: [f32; 4],
    /// xyz: size of a cell; w unused.
    pub cell: [f32; 4],
    /// xyz: cells along x, y, z; w: the character's slot.
    pub dims: [u32; 4],
    /// First bundle in the crowd's table, bundles, strands generated per bundle at most,
    /// segments per strand (log2). The volume stands for the character's own strands per
    /// bundle (`CharacterRecord::strands_per_bundle`).
    pub bundles: [u32; 4],
}

/// One character's step this frame: where its buffers are (device addresses, low word first)
/// and its `dynamics::StepPlan` and settings.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SimJob {
    /// `SimVertex[]`.
    pub vertices: [u32; 2],
    /// `SimConstraint[]`, grouped by colour.
    pub spacing: [u32; 2],
    /// `uint[]`: first constraint of each colour, then the total.
    pub spacing_colours: [u32; 2],
    /// `SimCollider[]`.
    pub colliders: [u32; 2],
    /// `SimState[]`.
    pub state: [u32; 2],
    /// `vec4[]`: the pose the texture rebuild reads (character frame).
    pub pose: [u32; 2],
    /// `float[]`: the head collider's radial map (rows x columns), if any.
    pub head_map: [u32; 2],
    /// `vec4[]`: the substep's positions being solved (the state buffer's second part).
    pub solve: [u32; 2],
    /// Vertices per layer, layers, substeps (0: only the pose), colliders.
    pub counts: [u32; 4],
    /// Spacing colours, head map rows, head map columns, unused.
    pub colours: [u32; 4],
    /// Rotation (quaternion xyzw) at the step's start.
    pub from_rotation: [f32; 4],
    /// Rotation at its end.
    pub to_rotation: [f32; 4],
    /// xyz: translation at the start; w: simulation time at the start.
    pub from_translation: [f32; 4],
    /// xyz: translation at the end; w: seconds per substep.
    pub to_translation: [f32; 4],
    /// xyz: scale at the start; w: velocity kept per substep (damping).
    pub from_scale: [f32; 4],
    /// xyz: scale at the end; w unused.
    pub to_scale: [f32; 4],
    /// xyz: gravity, m/s^2; w: wind gustiness.
    pub gravity: [f32; 4],
    /// xyz: unit wind direction; w: wind strength.
    pub wind: [f32; 4],
    /// Shape stiffness, spacing compliance, bend compliance, follow-the-leader damping.
    pub stiffness: [f32; 4],
}

gpu_struct!(SimVertex as "SimVertex" { rest: "vec4", lengths: "vec4" });
gpu_struct!(SimConstraint as "SimConstraint" { a: "uint", b: "uint", rest: "float", _pad: "uint" });
gpu_struct!(SimCollider as "SimCollider" {
    shape: "uvec4", a: "vec4", b: "vec4", to_canonical: "mat4", to_person: "mat4", bound: "vec4",
});
gpu_struct!(SimState as "SimState" { x: "vec4", v: "vec4" });
gpu_struct!(DensityJob as "DensityJob" {
    cells: "uvec2", _pad: "uvec2", origin: "vec4", cell: "vec4", dims: "uvec4", bundles: "uvec4",
});
gpu_struct!(SimJob as "SimJob" {
    vertices: "uvec2", spacing: "uvec2", spacing_colours: "uvec2", colliders: "uvec2",
    state: "uvec2", pose: "uvec2", head_map: "uvec2", solve: "uvec2", counts: "uvec4",
    colours: "uvec4", from_rotation: "vec4", to_rotation: "vec4", from_translation: "vec4",
    to_translation: "vec4", from_scale: "vec4", to_scale: "vec4", gravity: "vec4", wind: "vec4",
    stiffness: "vec4",
});
gpu_struct!(LhsWeights as "LhsWeights" { guides: "uvec4", weights: "vec4" });
gpu_struct!(DeformParams as "DeformParams" { origin: "vec4", extent: "vec4", counts: "uvec4" });
gpu_struct!(crate::bake::deform::StylingTerm as "StylingTerm" {
    i1: "uint", i2: "uint", u: "vec2", v: "vec2",
});

fn info<T: GpuStruct>() -> StructInfo {
    StructInfo {
        name: T::GLSL_NAME,
        fields: T::fields(),
        rust_size: size_of::<T>(),
    }
}

/// Every shared struct, dependencies first.
pub fn shared_structs() -> Vec<StructInfo> {
    vec![
        info::<MeshInfo>(),
        info::<HairStyle>(),
        info::<BundleDesc>(),
        info::<LodFields>(),
        info::<CountFields>(),
        info::<ShadingFields>(),
        info::<ShadowFields>(),
        info::<TransparencyFields>(),
        info::<SoftFields>(),
        info::<TemporalFields>(),
        info::<BodyShadowFields>(),
        info::<FrameBlock>(),
        info::<CharacterRecord>(),
        info::<GpuBundle>(),
        info::<FrameStats>(),
        info::<GenerateArgs>(),
        info::<HairVertex>(),
        info::<SoftSegment>(),
        info::<PropVertex>(),
        info::<PropInstance>(),
        info::<SkinRestVertex>(),
        info::<SkinnedVertex>(),
        info::<SkinJob>(),
        info::<TaskPayload>(),
        info::<DeformParams>(),
        info::<LhsWeights>(),
        info::<crate::bake::deform::StylingTerm>(),
        info::<SimVertex>(),
        info::<SimConstraint>(),
        info::<SimCollider>(),
        info::<SimState>(),
        info::<SimJob>(),
        info::<DensityJob>(),
        info::<VolumeCell>(),
    ]
}

/// `(size, alignment)` of field `f` of `s`: a GLSL type, or a struct laid out in `known`.
fn field_type(s: &StructInfo, f: &GpuField, known: &[(String, usize, usize)]) -> (usize, usize) {
    std430_type(f.glsl)
        .or_else(|| {
            known
                .iter()
                .find(|(n, ..)| n == f.glsl)
                .map(|(_, s, a)| (*s, *a))
        })
        .unwrap_or_else(|| panic!("{}: unknown GLSL type {}", s.name, f.glsl))
}

/// std430 layout of `s`: `(field offsets, size, alignment)`, using the layouts of the structs
/// before it in `known`.
pub fn std430_layout(
    s: &StructInfo,
    known: &[(String, usize, usize)],
) -> (Vec<usize>, usize, usize) {
    let (mut offset, mut align_max, mut offsets) = (0usize, 4usize, Vec::new());
    for f in &s.fields {
        let (size, align) = field_type(s, f, known);
        offset = offset.next_multiple_of(align);
        offsets.push(offset);
        // std430 arrays: stride is the element size rounded up to its alignment.
        offset += if f.array > 0 {
            size.next_multiple_of(align) * f.array
        } else {
            size
        };
        align_max = align_max.max(align);
    }
    (offsets, offset.next_multiple_of(align_max), align_max)
}

/// std140 layout of `s` (uniform blocks): `(field offsets, size, alignment)`, using the
/// std140 layouts of the structs before it in `known`. As std430, but a struct's alignment and
/// every array's stride round up to 16 bytes.
pub fn std140_layout(
    s: &StructInfo,
    known: &[(String, usize, usize)],
) -> (Vec<usize>, usize, usize) {
    let (mut offset, mut align_max, mut offsets) = (0usize, 16usize, Vec::new());
    for f in &s.fields {
        let (size, align) = field_type(s, f, known);
        let align = if f.array > 0 { align.max(16) } else { align };
        offset = offset.next_multiple_of(align);
        offsets.push(offset);
        offset += if f.array > 0 {
            size.next_multiple_of(16) * f.array
        } else {
            size
        };
        align_max = align_max.max(align);
    }
    (offsets, offset.next_multiple_of(align_max), align_max)
}

/// Integer constants shared with GLSL. Those used in layout qualifiers (set numbers, local
/// sizes, mesh output limits) are written as `int`, the rest as `uint`.
fn int_constants() -> Vec<(&'static str, u32, bool)> {
    let mut all = sizes_and_flags();
    all.extend(enum_numbers());
    all
}

/// Sizes, limits and flag bits shared with GLSL (`true`: usable in layout qualifiers).
fn sizes_and_flags() -> Vec<(&'static str, u32, bool)> {
    let layout = |n, v| (n, v, true);
    let uint = |n, v| (n, v, false);
    vec![
        layout("STRAND_GROUP_SIZE", STRAND_GROUP_SIZE),
        layout("VOLUME_GROUP_SIZE", VOLUME_GROUP_SIZE),
        layout("DYNAMICS_GROUP_SIZE_GPU", DYNAMICS_GROUP_SIZE_GPU),
        layout("DYNAMICS_GROUP_SIZE_CPU", DYNAMICS_GROUP_SIZE_CPU),
        uint("MAX_VERTS_LOG2", MAX_VERTS_LOG2),
        uint("MAX_SEGMENTS", MAX_SEGMENTS),
        // The mesh shader's outputs: two vertices per strand vertex, two triangles per
        // segment.
        layout("MESH_MAX_VERTICES", 2 * (MAX_SEGMENTS + 1)),
        layout("MESH_MAX_PRIMITIVES", 2 * MAX_SEGMENTS),
        uint("MAX_STRANDS_PER_BUNDLE", MAX_STRANDS_PER_BUNDLE as u32),
        uint("SLICES_PER_SEGMENT", SLICES_PER_SEGMENT),
        uint("BUNDLE_TRIANGLE", crate::bake::BUNDLE_TRIANGLE),
        layout("TASK_PAYLOAD_BUNDLES", TASK_PAYLOAD_BUNDLES),
        uint("PAYLOAD_LANE_BITS", PAYLOAD_LANE_BITS),
        layout("CULL_GROUP_SIZE", CULL_GROUP_SIZE),
        layout("SCAN_THREADS", SCAN_THREADS),
        uint("SCAN_BLOCK", SCAN_BLOCK),
        uint("DISPATCH_ROW", DISPATCH_ROW),
        layout("DEFORM_GROUP_SIZE", DEFORM_GROUP_SIZE),
        layout("LHS_GROUP_SIZE", LHS_GROUP_SIZE),
        layout("SKIN_GROUP_SIZE", SKIN_GROUP_SIZE),
        uint("SKIN_NONE", SKIN_NONE),
        layout("MAX_SIM_COLLIDERS", MAX_SIM_COLLIDERS),
        uint("COLLIDER_ELLIPSOID", COLLIDER_ELLIPSOID),
        uint("COLLIDER_CAPSULE", COLLIDER_CAPSULE),
        uint("COLLIDER_HEAD", COLLIDER_HEAD),
        uint("BEND_COLOURS", crate::dynamics::BEND_COLOURS as u32),
        uint("COLLISION_ROUNDS", crate::dynamics::COLLISION_ROUNDS),
        uint(
            "MAX_SPLAT_POINTS",
            crate::reference::volume::MAX_SPLAT_POINTS,
        ),
        uint("CHARACTER_VISIBLE", CHARACTER_VISIBLE),
        uint("CHARACTER_VOLUME_ONLY", CHARACTER_VOLUME_ONLY),
        uint("VOLUME_BUILT", VOLUME_BUILT),
        uint("VOLUME_OCCLUSION", VOLUME_OCCLUSION),
        uint("VOLUME_SKIP_EMPTY", VOLUME_SKIP_EMPTY),
        uint("VOLUME_DIMS_BITS", VOLUME_DIMS_BITS),
        uint("BRICK_CELLS", crate::reference::volume::BRICK_CELLS),
        uint("DENSITY_PASS_OCCUPANCY", DENSITY_PASS_OCCUPANCY),
        uint("MARSCHNER_LUT_PHI", MARSCHNER_LUT_PHI),
        uint("MARSCHNER_LUT_D", MARSCHNER_LUT_D),
        uint("SCATTER_LUT_THETA", SCATTER_LUT_THETA),
        uint("SHADING_LUT_WIDTH", SHADING_LUT_WIDTH),
        uint("SHADING_LUT_HEIGHT", SHADING_LUT_HEIGHT),
        layout("SET_FRAME", SET_FRAME),
        layout("SET_TEXTURES", SET_TEXTURES),
        uint("SOFT_TILE", SOFT_TILE),
        uint("SOFT_MAX_K", SOFT_MAX_K),
        layout("SOFT_BIN_GROUP", SOFT_BIN_GROUP),
        uint("LOD_SOFT", LOD_SOFT),
        uint("LOD_DEMAND_UNIT", LOD_DEMAND_UNIT),
        uint("LOD_LEVEL_MASK", LOD_LEVEL_MASK),
        uint("MAX_OIT_BUDGET", MAX_OIT_BUDGET),
        uint(
            "STRAND_RAND_THINNING",
            crate::reference::generate::STRAND_RAND_THINNING,
        ),
        uint("EMPTY_TEXEL", crate::bake::layout::EMPTY_TEXEL),
    ]
}

/// Enum numbers the frame block carries, and the visibility word's constants.
fn enum_numbers() -> Vec<(&'static str, u32, bool)> {
    use crate::shade::ShadingModel;
    let uint = |n, v| (n, v, false);
    vec![
        uint("SHADING_PLACEHOLDER", ShadingModel::Placeholder as u32),
        uint("SHADING_KAJIYA_KAY", ShadingModel::KajiyaKay as u32),
        uint("SHADING_MARSCHNER", ShadingModel::Marschner as u32),
        uint("SHADOW_OFF", SHADOW_OFF),
        uint("SHADOW_DEEP_OPACITY", SHADOW_DEEP_OPACITY),
        uint("SHADOW_APPROXIMATE", SHADOW_APPROXIMATE),
        uint("RASTER_HARDWARE", RASTER_HARDWARE),
        uint("RASTER_SOFTWARE", RASTER_SOFTWARE),
        uint("RASTER_AUTO", RASTER_AUTO),
        uint("RASTER_LIGHT", RASTER_LIGHT),
        uint("TRANSPARENCY_OPAQUE", TRANSPARENCY_OPAQUE),
        uint("TRANSPARENCY_KBUFFER", TRANSPARENCY_KBUFFER),
        uint("TRANSPARENCY_PEELING", TRANSPARENCY_PEELING),
        uint("VISIBILITY_EMPTY", VISIBILITY_EMPTY),
        uint("VISIBILITY_PROP", VISIBILITY_PROP),
        uint("VISIBILITY_SOLID", VISIBILITY_SOLID),
        uint("VISIBILITY_INDEX", VISIBILITY_INDEX),
        uint("TEMPORAL_GROUP", TEMPORAL_GROUP),
        uint("VISIBILITY_DEPTH_SHIFT", VISIBILITY_DEPTH_SHIFT),
    ]
}

/// Float constants shared with GLSL.
fn float_constants() -> Vec<(&'static str, f32)> {
    vec![
        ("STRAND_OPACITY", STRAND_OPACITY),
        ("SOFT_HIDDEN_TRANSMITTANCE", SOFT_HIDDEN_TRANSMITTANCE),
        ("OIT_FIXED", OIT_FIXED),
        ("LOD_LEAST_PRESSURE", LOD_LEAST_PRESSURE),
        ("SHAPE_TIP_LOSS", crate::dynamics::SHAPE_TIP_LOSS),
        ("BOUND_SLACK", crate::dynamics::BOUND_SLACK),
        ("BOUND_PAD", crate::dynamics::BOUND_PAD),
        ("VISIBILITY_RESIDUAL_STEPS", VISIBILITY_RESIDUAL_STEPS),
        ("TEMPORAL_SOLID_MOVING_WEIGHT", TEMPORAL_SOLID_MOVING_WEIGHT),
        ("TEMPORAL_SOLID_MOTION", TEMPORAL_SOLID_MOTION),
        ("MARSCHNER_LUT_TRT_SCALE", MARSCHNER_LUT_TRT_SCALE),
        (
            "ROOT_PHONG_SHAPE",
            crate::reference::root_surface::ROOT_PHONG_SHAPE,
        ),
        ("HAIR_ETA", crate::shade::HAIR_ETA),
        ("KAJIYA_KAY_EXPONENT", crate::shade::KAJIYA_KAY_EXPONENT),
        ("MARSCHNER_ENERGY_SCALE", crate::shade::ENERGY_SCALE),
        ("LIGHT_IRRADIANCE", crate::shade::LIGHT_IRRADIANCE),
        ("AMBIENT", crate::shade::AMBIENT),
        ("PROP_ROUGHNESS", crate::shade::PROP_ROUGHNESS),
        ("PROP_IRRADIANCE", crate::shade::PROP_IRRADIANCE),
        ("PROP_AMBIENT", crate::shade::PROP_AMBIENT),
        ("FORWARD_DENSITY", crate::shade::scattering::FORWARD_DENSITY),
        (
            "BACKWARD_DENSITY",
            crate::shade::scattering::BACKWARD_DENSITY,
        ),
        ("GAP_DENSITY", crate::shade::scattering::GAP_DENSITY),
        ("SHADOW_OPACITY_FIXED", SHADOW_OPACITY_FIXED),
        ("VOLUME_FIXED", VOLUME_FIXED),
        ("SPLAT_SPACING", crate::reference::volume::SPLAT_SPACING),
        ("AO_RADIUS_CELLS", crate::shade::volume::AO_RADIUS_CELLS),
        ("MARCH_STEP_CELLS", crate::shade::volume::MARCH_STEP_CELLS),
        (
            "MARCH_MIN_TRANSMITTANCE",
            crate::shade::volume::MARCH_MIN_TRANSMITTANCE,
        ),
        ("STRAND_SHADOW_OPACITY", STRAND_SHADOW_OPACITY),
    ]
}

/// Colour constants shared with GLSL.
fn vec3_constants() -> Vec<(&'static str, [f32; 3])> {
    vec![
        ("SKY_TINT", crate::shade::SKY_TINT),
        ("GROUND_TINT", crate::shade::GROUND_TINT),
    ]
}

/// The GLSL include `shared.glsl`: constants, enum numbers, binding numbers and shared
/// structs.
pub fn glsl_header() -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// GENERATED from src/render/core/shared.rs by render::shared::glsl_header(); do not edit.\n\
         // Shaders are compiled with this text; this copy is for reading.\n\
         #ifndef SHARED_GLSL\n#define SHARED_GLSL\n"
    );
    for (name, v, layout) in int_constants() {
        let suffix = if layout { "" } else { "u" };
        let _ = writeln!(out, "#define {name} {v}{suffix}");
    }
    for (name, v) in float_constants() {
        let _ = writeln!(out, "#define {name} {v:?}");
    }
    for (name, [x, y, z]) in vec3_constants() {
        let _ = writeln!(out, "#define {name} vec3({x:?}, {y:?}, {z:?})");
    }
    let bindings = FrameBinding::ALL.iter().map(|(b, n)| (*b as u32, *n));
    let bindings = bindings
        .chain(TextureBinding::ALL.iter().map(|(b, n)| (*b as u32, *n)))
        .chain(DeformBinding::ALL.iter().map(|(b, n)| (*b as u32, *n)))
        .chain(LhsBinding::ALL.iter().map(|(b, n)| (*b as u32, *n)));
    for (b, name) in bindings {
        let _ = writeln!(out, "#define {name} {b}");
    }
    let _ = writeln!(
        out,
        "// Depth of the hair mesh texture: SLICES_PER_SEGMENT (L - 1) + 1 slices.\n\
         #define POSITION_DEPTH(layers) (SLICES_PER_SEGMENT * ((layers) - 1u) + 1u)\n"
    );
    for s in shared_structs() {
        let _ = writeln!(out, "struct {} {{", s.name);
        for f in &s.fields {
            if f.array > 0 {
                let _ = writeln!(out, "    {} {}[{}];", f.glsl, f.name, f.array);
            } else {
                let _ = writeln!(out, "    {} {};", f.glsl, f.name);
            }
        }
        let _ = writeln!(out, "}};\n");
    }
    out.push_str("#endif\n");
    out
}
