#version 460
// Compute-path draw: pull generated vertices and expand each segment into a camera-facing quad
// (2 triangles; a strand of ns segments gives 2ns triangles). One draw for the whole crowd.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "strip.glsl"
#include "temporal.glsl"

layout(location = 0) out vec3 out_tangent;
layout(location = 1) out float out_s;
layout(location = 2) out vec3 out_pos;
layout(location = 3) flat out vec3 out_color;
layout(location = 4) flat out uint out_character;
layout(location = 5) out float out_coverage;
layout(location = 6) flat out float out_thickness;
layout(location = 7) out vec2 out_residual;

void main() {
    uint idx = uint(gl_VertexIndex);
    // Bundle owning this draw vertex: last bundle whose first draw vertex is <= idx.
    uint lo = 0u;
    uint hi = frame.counts.bundles - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) / 2u;
        if (bundle_offsets[mid].z <= idx) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    bind_character(bundles[lo].character);
    uint segments = lod_segments(bundle_lods[lo].y);
    uint local = idx - bundle_offsets[lo].z;
    uint strand = local / (segments * 6u);
    uint seg = (local / 6u) % segments;
    uint corner = local % 6u;
    // Triangles (a-, a+, b-) and (b-, a+, b+).
    uint end = (corner == 2u || corner == 3u || corner == 5u) ? 1u : 0u;
    float side = (corner == 1u || corner == 4u || corner == 5u) ? 1.0 : -1.0;
    uint slot = bundle_offsets[lo].y + strand * (segments + 1u) + seg + end;
    HairVertex v = hair_vertices[slot];
    float thickness = uintBitsToFloat(bundle_lods[lo].w);
    float drawn = drawn_width(v.pos_width.xyz, v.pos_width.w, thickness, model_scale * bundles[lo].rest_size);
    vec3 world = strip_offset(v.pos_width.xyz, v.tangent_s.xyz, drawn, side);
    gl_Position = frame.view_proj * vec4(world, 1.0);
    out_tangent = v.tangent_s.xyz;
    out_s = v.tangent_s.w;
    out_pos = world;
    out_color = style_color();
    out_character = bundles[lo].character;
    out_coverage = strip_coverage(v.pos_width.w, drawn);
    out_thickness = thickness;
    out_residual = vec2(0.0);
#ifdef VISIBILITY
    // Frames with motion on the compute path: generate.comp wrote every vertex's residual.
    if (frame.temporal.motion != 0u && frame.temporal.residuals != 0u) {
        out_residual = unpackHalf2x16(vertex_motion[slot]);
    }
#endif
}
