#version 460
// Draw: pull generated vertices and expand each segment into a camera-facing quad
// (2 triangles; a strand of ns segments gives 2ns triangles). Widths below one pixel are
// widened to one pixel so thin strands do not break up into dots.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"

layout(location = 0) out vec3 out_tangent;
layout(location = 1) out float out_s;
layout(location = 2) out vec3 out_pos;

void main() {
    uint segments = 1u << frame.params.y;
    uint idx = uint(gl_VertexIndex);
    uint strand = idx / (segments * 6u);
    uint seg = (idx / 6u) % segments;
    uint corner = idx % 6u;
    // Triangles (a-, a+, b-) and (b-, a+, b+).
    uint end = (corner == 2u || corner == 3u || corner == 5u) ? 1u : 0u;
    float side = (corner == 1u || corner == 4u || corner == 5u) ? 1.0 : -1.0;
    HairVertex v = hair_vertices[strand * (segments + 1u) + seg + end];
    vec3 pos = v.pos_width.xyz;
    vec3 tangent = v.tangent_s.xyz;
    vec3 to_eye = frame.camera_pos.xyz - pos;
    float dist = length(to_eye);
    vec3 across = cross(tangent, to_eye / max(dist, 1e-6));
    across = length(across) > 1e-6 ? normalize(across) : normalize(cross(tangent, vec3(0.0, 0.0, 1.0)) + 1e-6);
    float pixel = frame.light_dir.w > 0.0 ? 2.0 * dist / (frame.camera_pos.w * frame.light_dir.w) : 0.0;
    float half_width = 0.5 * max(v.pos_width.w, pixel);
    vec3 world = pos + across * (side * half_width);
    gl_Position = frame.view_proj * vec4(world, 1.0);
    out_tangent = tangent;
    out_s = v.tangent_s.w;
    out_pos = world;
}
