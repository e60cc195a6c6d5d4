// Resources of every hair pass. Binding numbers, constants and structs come from the generated
// include shared.glsl (src/render/core/shared.rs); nothing here restates them.
#ifndef BINDINGS_GLSL
#define BINDINGS_GLSL
#extension GL_EXT_nonuniform_qualifier : require
#include "shared.glsl"

layout(set = SET_FRAME, binding = BINDING_FRAME, std140) uniform FrameUbo { FrameBlock frame; };
layout(set = SET_FRAME, binding = BINDING_CHARACTERS, std430) readonly buffer Characters { CharacterRecord characters[]; };
layout(set = SET_FRAME, binding = BINDING_BUNDLES, std430) readonly buffer Bundles { GpuBundle bundles[]; };
// Root samples: [0, MAX_STRANDS_PER_BUNDLE) quad set, then the triangle set.
layout(set = SET_FRAME, binding = BINDING_ROOT_SAMPLES, std430) readonly buffer RootSamples { vec2 root_samples[]; };
// Per bundle: LoD decision (x strands, y vertex level e, z gamma bits, w thickness bits) and
// exclusive prefix sums (x first strand, y first vertex slot, z first draw vertex,
// w first strand workgroup).
layout(set = SET_FRAME, binding = BINDING_BUNDLE_LODS, std430) buffer BundleLods { uvec4 bundle_lods[]; };
layout(set = SET_FRAME, binding = BINDING_BUNDLE_OFFSETS, std430) buffer BundleOffsets { uvec4 bundle_offsets[]; };
layout(set = SET_FRAME, binding = BINDING_SCAN_SCRATCH, std430) buffer ScanScratch { uvec4 scan_scratch[]; };
layout(set = SET_FRAME, binding = BINDING_ARGS, std430) buffer Args { GenerateArgs args; };
layout(set = SET_FRAME, binding = BINDING_VERTICES, std430) buffer Vertices { HairVertex hair_vertices[]; };

// The five textures of every character (paper 003 Table 1), indexed by texture slot.
layout(set = SET_TEXTURES, binding = BINDING_TEX_POSITION) uniform sampler3D tex_position[];
layout(set = SET_TEXTURES, binding = BINDING_TEX_UV) uniform sampler2D tex_uv[];
layout(set = SET_TEXTURES, binding = BINDING_TEX_W) uniform sampler3D tex_w[];
layout(set = SET_TEXTURES, binding = BINDING_TEX_U) uniform sampler3D tex_u[];
layout(set = SET_TEXTURES, binding = BINDING_TEX_V) uniform sampler3D tex_v[];

// Small per-dispatch parameters (scan levels).
layout(push_constant) uniform Push { uvec4 params; } push;

// The character this invocation works on, loaded by bind_character().
MeshInfo mesh;
HairStyle style;
mat4 model;
float model_scale;
uint tex_slot;
uint ch_prev_slot;  // texture slot of the previous frame's pose (tex_slot unless it changed)
uint ch_strands;    // N of eq. 8
uint ch_emax;       // full-detail vertex level e
bool ch_visible;
bool ch_volume_only;  // drawn as its density volume alone: no strands
float ch_strand_share;  // share of its strands drawn: 1 - the volume tier's weight (its band)

void bind_character(uint c) {
    mesh = characters[c].mesh;
    style = characters[c].style;
    model = characters[c].model;
    model_scale = characters[c].model_scale;
    tex_slot = characters[c].texture_slot;
    ch_prev_slot = characters[c].prev_texture_slot;
    ch_strands = characters[c].strands_per_bundle;
    ch_emax = characters[c].verts_log2;
    ch_visible = (characters[c].flags & CHARACTER_VISIBLE) != 0u;
    ch_volume_only = (characters[c].flags & CHARACTER_VOLUME_ONLY) != 0u;
    // volume_shading.z is 0 unless the character's volume is built (render::volume).
    ch_strand_share = clamp(1.0 - characters[c].volume_shading.z, 0.0, 1.0);
}

// The hair mesh texture is read where neighbouring invocations belong to different characters
// (cull, task, scalp): non-uniform index. The w, u and v textures are read only by the strand
// builders (generate.comp, strands.mesh), whose whole workgroup works on one bundle, so their
// index is dynamically uniform. (Marking those non-uniform too made lavapipe 25.0 return the
// u-texture's value for the v-texture: caught by tests/gpu_oracle.rs.)
#define TEX_POSITION tex_position[nonuniformEXT(tex_slot)]
#define TEX_W tex_w[tex_slot]
#define TEX_U tex_u[tex_slot]
#define TEX_V tex_v[tex_slot]

// bundle_lods[].y: vertex level e in the low byte, LOD_SOFT when the software rasterizer
// draws the bundle, the newest strand's width share in the high half (lod_strand_fade).
uint lod_segments(uint y) {
    return 1u << (y & LOD_LEVEL_MASK);
}

bool lod_is_soft(uint y) {
    return (y & LOD_SOFT) != 0u;
}

// Width factor of strand `strand` of a bundle with LoD decision `lod`: the newest strand
// (lod.x - 1) is drawn as wide as eq. 8's fractional part (bundle_lods[].y bits 16..31, 16-bit
// fixed point), the others whole; src/reference/lod.rs: newest_strand_fade.
float lod_strand_fade(uvec4 lod, uint strand) {
    return strand + 1u == lod.x ? float(lod.y >> 16u) / 65535.0 : 1.0;
}

// The bundle of strand workgroup g: the last bundle whose first workgroup is <= g (never an
// empty one for g below the total; generate.comp, pool_segments.comp).
uint group_bundle(uint g) {
    uint lo = 0u;
    uint hi = frame.counts.bundles - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) / 2u;
        if (bundle_offsets[mid].w <= g) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

vec3 style_color() {
    return vec3(style.color[0], style.color[1], style.color[2]);
}

#endif
