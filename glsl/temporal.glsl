// The nearest surface of each pixel, the source of the motion vectors (src/render/temporal.rs):
// every camera pass that draws a surface notes depth bits << 32 | visibility id with a 64-bit
// atomicMin, so the nearest wins whatever the order (ties: the smaller id). Compiled in with
// VISIBILITY (devices with 64-bit buffer atomics);
// frame.temporal.x says whether this frame wants it (never in the light's views).
#ifndef TEMPORAL_GLSL
#define TEMPORAL_GLSL

#ifdef VISIBILITY
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
layout(set = SET_FRAME, binding = BINDING_VISIBILITY, std430) buffer VisibilityWords { uint64_t visibility[]; };
#endif

void note_visible(uvec2 pixel, float depth, uint id) {
#ifdef VISIBILITY
    if (frame.temporal.x == 0u) {
        return;
    }
    uint p = pixel.y * uint(frame.viewport.x) + pixel.x;
    atomicMin(visibility[p], (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(id));
#endif
}

// A fragment shader's own pixel and depth (a macro: gl_FragCoord exists in fragment shaders
// only).
#define note_fragment(id) note_visible(uvec2(gl_FragCoord.xy), gl_FragCoord.z, (id))

#endif
