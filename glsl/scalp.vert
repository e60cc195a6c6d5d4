#version 460
// Opaque scalps of the whole crowd in one draw: two triangles per bundle pulled from the root
// slice of each character's hair mesh texture.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "common.glsl"
#include "strand_eval.glsl"

layout(location = 0) out vec3 out_normal;
layout(location = 1) flat out vec3 out_color;
layout(location = 2) flat out uint out_character;

vec3 corner_pos(GpuBundle b, int c) {
    ivec3 t = ivec3(ivec2(b.origin) + ivec2(c & 1, c >> 1), 0);
    return (model * vec4(decode_position(texelFetch(TEX_POSITION, t, 0).xyz), 1.0)).xyz;
}

void main() {
    uint g = uint(gl_VertexIndex) / 6u;
    uint corner = uint(gl_VertexIndex) % 6u;
    GpuBundle b = bundles[g];
    bind_character(b.character);
    out_color = style_color() * 0.6;
    out_character = b.character;
    if (!ch_visible) {
        out_normal = vec3(0.0, 1.0, 0.0);
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // outside the depth range: clipped
        return;
    }
    // Cell corners (0,0) (1,0) (1,1) (0,1) as indices 0 1 3 2; triangles (0,1,3) and (0,3,2).
    const int order[6] = int[6](0, 1, 3, 0, 3, 2);
    vec3 p00 = corner_pos(b, 0);
    vec3 p10 = corner_pos(b, 1);
    vec3 p01 = corner_pos(b, 2);
    vec3 p11 = corner_pos(b, 3);
    vec3 n = cross(p11 - p00, p01 - p10);
    out_normal = length(n) > 0.0 ? normalize(n) : vec3(0.0, 1.0, 0.0);
    gl_Position = frame.view_proj * vec4(corner_pos(b, order[corner]), 1.0);
}
