// 32-bit packed fragment colour of the k-buffer nodes (oit.glsl) and the software
// rasterizer's segment ends (soft_segments.glsl).
#ifndef FRAGMENT_PACK_GLSL
#define FRAGMENT_PACK_GLSL

// Colour in [0, 1] with a square-root curve (more codes for dark hair), alpha linear.
uint pack_fragment(vec3 c, float a) {
    return packUnorm4x8(vec4(sqrt(clamp(c, 0.0, 1.0)), a));
}

vec4 unpack_fragment(uint p) {
    vec4 v = unpackUnorm4x8(p);
    return vec4(v.rgb * v.rgb, v.a);
}

#endif
