#version 460
// Compute path, pass 1b: one workgroup. Exclusive prefix sums over bundles of strands, vertex
// slots (strands x (2^e + 1)) and draw vertices (strands x 2^e x 6), plus the indirect
// dispatch / draw arguments and triangle statistics.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 256) in;
#include "bindings.glsl"

shared uvec4 partial[256];

#define S 32u

// Strands, vertex slots, draw vertices and workgroups (strand_build.glsl packs
// max(S / segments, 1) strands per workgroup) of bundle i.
uvec4 bundle_sizes(uint i) {
    uvec4 l = bundle_lods[i];
    uint segments = 1u << l.y;
    uint per = max(S / segments, 1u);
    return uvec4(l.x, l.x * (segments + 1u), l.x * segments * 6u, (l.x + per - 1u) / per);
}

void main() {
    uint count = frame.params.z;
    uint t = gl_LocalInvocationID.x;
    uint chunk = (count + 255u) / 256u;
    uint begin = min(t * chunk, count);
    uint end = min(begin + chunk, count);
    uvec4 sum = uvec4(0u);
    for (uint i = begin; i < end; i++) {
        sum += bundle_sizes(i);
    }
    partial[t] = sum;
    barrier();
    if (t == 0u) {
        uvec4 run = uvec4(0u);
        for (uint i = 0u; i < 256u; i++) {
            uvec4 v = partial[i];
            partial[i] = run;
            run += v;
        }
        indirect.total_strands = run.x;
        indirect.total_vertex_slots = run.y;
        indirect.total_triangles = run.z / 3u;
        indirect.total_groups = run.w;
        indirect.dispatch_x = min(run.w, DISPATCH_ROW);
        indirect.dispatch_y = (run.w + DISPATCH_ROW - 1u) / DISPATCH_ROW;
        indirect.dispatch_z = 1u;
        indirect.draw_vertex_count = run.z;
        indirect.draw_instance_count = 1u;
        indirect.draw_first_vertex = 0u;
        indirect.draw_first_instance = 0u;
    }
    barrier();
    uvec4 run = partial[t];
    for (uint i = begin; i < end; i++) {
        bundle_offsets[i] = run;
        run += bundle_sizes(i);
    }
}
