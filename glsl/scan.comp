#version 460
// Compute path, pass 1b: one workgroup. Exclusive prefix sum of bundle_strands into
// bundle_offsets and the indirect dispatch / draw arguments.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 256) in;
#include "bindings.glsl"

shared uint partial[256];

void main() {
    uint count = frame.params.z;
    uint t = gl_LocalInvocationID.x;
    // Each thread sums one contiguous chunk, then the chunk sums are scanned.
    uint chunk = (count + 255u) / 256u;
    uint begin = min(t * chunk, count);
    uint end = min(begin + chunk, count);
    uint sum = 0u;
    for (uint i = begin; i < end; i++) {
        sum += bundle_strands[i];
    }
    partial[t] = sum;
    barrier();
    if (t == 0u) {
        uint run = 0u;
        for (uint i = 0u; i < 256u; i++) {
            uint v = partial[i];
            partial[i] = run;
            run += v;
        }
        uint segments = 1u << frame.params.y;
        indirect.total_strands = run;
        indirect.dispatch_x = min(run, DISPATCH_ROW);
        indirect.dispatch_y = (run + DISPATCH_ROW - 1u) / DISPATCH_ROW;
        indirect.dispatch_z = 1u;
        indirect.draw_vertex_count = run * segments * 6u;
        indirect.draw_instance_count = 1u;
        indirect.draw_first_vertex = 0u;
        indirect.draw_first_instance = 0u;
    }
    barrier();
    uint run = partial[t];
    for (uint i = begin; i < end; i++) {
        bundle_offsets[i] = run;
        run += bundle_strands[i];
    }
}
