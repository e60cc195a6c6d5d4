#version 460
// Compute path, pass 1b: one workgroup. Exclusive prefix sums over bundles of strands, vertex
// slots (strands x (2^e + 1)) and draw vertices (strands x 2^e x 6), plus the indirect
// dispatch / draw arguments and triangle statistics.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 256) in;
#include "bindings.glsl"

shared uvec3 partial[256];

uvec3 bundle_sizes(uint i) {
    uvec4 l = bundle_lods[i];
    uint segments = 1u << l.y;
    return uvec3(l.x, l.x * (segments + 1u), l.x * segments * 6u);
}

void main() {
    uint count = frame.params.z;
    uint t = gl_LocalInvocationID.x;
    uint chunk = (count + 255u) / 256u;
    uint begin = min(t * chunk, count);
    uint end = min(begin + chunk, count);
    uvec3 sum = uvec3(0u);
    for (uint i = begin; i < end; i++) {
        sum += bundle_sizes(i);
    }
    partial[t] = sum;
    barrier();
    if (t == 0u) {
        uvec3 run = uvec3(0u);
        for (uint i = 0u; i < 256u; i++) {
            uvec3 v = partial[i];
            partial[i] = run;
            run += v;
        }
        indirect.total_strands = run.x;
        indirect.total_vertex_slots = run.y;
        indirect.total_triangles = run.z / 3u;
        indirect.dispatch_x = min(run.x, DISPATCH_ROW);
        indirect.dispatch_y = (run.x + DISPATCH_ROW - 1u) / DISPATCH_ROW;
        indirect.dispatch_z = 1u;
        indirect.draw_vertex_count = run.z;
        indirect.draw_instance_count = 1u;
        indirect.draw_first_vertex = 0u;
        indirect.draw_first_instance = 0u;
    }
    barrier();
    uvec3 run = partial[t];
    for (uint i = begin; i < end; i++) {
        bundle_offsets[i] = uvec4(run, 0u);
        run += bundle_sizes(i);
    }
}
