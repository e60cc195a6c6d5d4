// K-buffer order-independent transparency (src/render/transparency.rs): per pixel, K 64-bit
// nodes (depth bits << 32 | colour packed by pack_fragment) kept sorted nearest first, and a
// tail of fixed-point sums for the fragments pushed past the K-th node. Used by oit.frag
// (insert) and oit_resolve.frag.
#ifndef OIT_GLSL
#define OIT_GLSL
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "fragment_pack.glsl"

layout(set = SET_FRAME, binding = BINDING_OIT_NODES, std430) buffer OitNodes { uint64_t oit_nodes[]; };
// x, y, z: sum of colour x optical depth; w: sum of optical depth; all times OIT_FIXED.
layout(set = SET_FRAME, binding = BINDING_OIT_TAIL, std430) buffer OitTail { uvec4 oit_tail[]; };

#define OIT_EMPTY 0xFFFFFFFFFFFFFFFFul
// OIT_FIXED (shared.glsl): the fixed-point scale of the tail sums.

// The fragment's pixel (fragment shaders; the software rasterizer, a compute shader, defines
// OIT_COMPUTE and indexes pixels itself).
#ifndef OIT_COMPUTE
uint oit_pixel() {
    return uint(gl_FragCoord.y) * uint(frame.viewport.x) + uint(gl_FragCoord.x);
}
#endif

// Optical depth of one fragment's alpha (capped below 1 by the 8-bit alpha).
float optical_depth(float a) {
    return -log(max(1.0 - a, 1.0 / 256.0));
}

#endif
