// The nearest surface of each pixel, the source of the motion vectors (src/render/temporal.rs):
// every camera pass that draws a surface notes a visibility word (depth, visibility id,
// deformation residual) with a 64-bit atomicMin, so the nearest wins whatever the order (ties:
// the smaller id). Compiled in with VISIBILITY (devices with 64-bit buffer atomics);
// frame.temporal.motion says whether this frame wants it (never in the light's views).
#ifndef TEMPORAL_GLSL
#define TEMPORAL_GLSL

#ifdef VISIBILITY
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
layout(set = SET_FRAME, binding = BINDING_VISIBILITY, std430) buffer VisibilityWords { uint64_t visibility[]; };
// Deformation residuals (packHalf2x16, pixels) of the compute path's vertices, by pool slot,
// and of the software rasterizer's segments.
layout(set = SET_FRAME, binding = BINDING_VERTEX_MOTION, std430) buffer VertexMotion { uint vertex_motion[]; };
layout(set = SET_FRAME, binding = BINDING_SEGMENT_MOTION, std430) buffer SegmentMotion { uint segment_motion[]; };

// The visibility id field (18 bits) of an empty pixel.
#define VISIBILITY_ID_EMPTY 0x3FFFFu

// From the top: 24 bits of the depth's float bits, the id in 18 bits (16 of index, then the
// solid and prop bits), the residual in two signed 11-bit fields of VISIBILITY_RESIDUAL_STEPS
// per pixel (CPU twin: render::temporal::VisibilityWord::pack).
uint64_t visibility_word(float depth, uint id, vec2 residual) {
    uint d = floatBitsToUint(clamp(depth, 0.0, 1.0)) >> VISIBILITY_DEPTH_SHIFT;
    uint kind = ((id & VISIBILITY_SOLID) != 0u ? 1u : 0u) | ((id & VISIBILITY_PROP) != 0u ? 2u : 0u);
    uint id18 = id == VISIBILITY_EMPTY ? VISIBILITY_ID_EMPTY : (id & VISIBILITY_INDEX) | (kind << 16);
    ivec2 steps = clamp(ivec2(floor(residual * VISIBILITY_RESIDUAL_STEPS + 0.5)), ivec2(-1024), ivec2(1023)) + 1024;
    uint low = (uint(steps.x) << 11) | uint(steps.y);
    return (uint64_t(d) << 40) | (uint64_t(id18) << 22) | uint64_t(low);
}

// Whether the word is an empty pixel's.
bool visibility_empty(uint64_t w) {
    return (uint(w >> 22) & VISIBILITY_ID_EMPTY) == VISIBILITY_ID_EMPTY;
}

// The word's visibility id and depth bits (VisibilityWord::unpack); empty: depth 1.
uvec2 visibility_surface(uint64_t w) {
    uint id18 = uint(w >> 22) & VISIBILITY_ID_EMPTY;
    if (id18 == VISIBILITY_ID_EMPTY) {
        return uvec2(VISIBILITY_EMPTY, floatBitsToUint(1.0));
    }
    uint kind = id18 >> 16;
    uint id = (id18 & VISIBILITY_INDEX) | ((kind & 1u) != 0u ? VISIBILITY_SOLID : 0u) | ((kind & 2u) != 0u ? VISIBILITY_PROP : 0u);
    return uvec2(id, uint(w >> 40) << VISIBILITY_DEPTH_SHIFT);
}

// The word's deformation residual, pixels (none for an empty pixel).
vec2 visibility_residual(uint64_t w) {
    if (visibility_empty(w)) {
        return vec2(0.0);
    }
    uint low = uint(w);
    return (vec2(ivec2((low >> 11) & 0x7FFu, low & 0x7FFu)) - 1024.0) / VISIBILITY_RESIDUAL_STEPS;
}
#endif

void note_visible(uvec2 pixel, float depth, uint id, vec2 residual) {
#ifdef VISIBILITY
    if (frame.temporal.motion == 0u) {
        return;
    }
    uint p = pixel.y * uint(frame.viewport.x) + pixel.x;
    atomicMin(visibility[p], visibility_word(depth, id, residual));
#endif
}

#ifdef VISIBILITY
// Note a word made by visibility_word (the software rasterizer's nearest per pixel).
void note_visible_word(uvec2 pixel, uint64_t word) {
    atomicMin(visibility[pixel.y * uint(frame.viewport.x) + pixel.x], word);
}
#endif

// A fragment shader's own pixel and depth (a macro: gl_FragCoord exists in fragment shaders
// only).
#define note_fragment(id, residual) note_visible(uvec2(gl_FragCoord.xy), gl_FragCoord.z, (id), (residual))

// Whether this frame's strands of the bound character need their previous pose evaluated:
// motion vectors are wanted and the pose changed this frame (its previous texture set differs).
bool deform_motion() {
    return frame.temporal.motion != 0u && ch_prev_slot != tex_slot;
}

// Where a strand point at `world` (this pose) was in the previous frame's pixels, relative to
// where its rigid motion puts it: `displacement` (previous pose minus this one, world space
// through this frame's model) carried through this frame's unjittered view-projection and the
// character's clip_to_prev, which together are the previous frame's view-projection and model.
vec2 deformation_residual(uint character, vec3 world, vec3 displacement) {
    mat4 to_prev = characters[character].clip_to_prev * frame.unjittered_view_proj;
    vec4 a = to_prev * vec4(world, 1.0);
    vec4 b = to_prev * vec4(world + displacement, 1.0);
    if (a.w <= 1e-6 || b.w <= 1e-6) {
        return vec2(0.0);
    }
    return (b.xy / b.w - a.xy / a.w) * 0.5 * frame.viewport.xy;
}

#endif
