#version 460
// Compute path, pass 2 (down-sweep): add each block's scanned block sum to its elements.
// push.params: x element count, y element offset into scan_scratch, z block-sum offset,
// w level (0: elements are bundle_offsets).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = SCAN_THREADS) in;

void main() {
    uint i = (gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x) * uint(SCAN_THREADS) + gl_LocalInvocationID.x;
    if (i >= push.params.x) {
        return;
    }
    uvec4 add = scan_scratch[push.params.z + i / SCAN_BLOCK];
    if (push.params.w == 0u) {
        bundle_offsets[i] += add;
    } else {
        scan_scratch[push.params.y + i] += add;
    }
}
