#version 460
// Compute path, pass 2 (up-sweep of a multi-level exclusive scan, any number of bundles):
// each workgroup scans SCAN_BLOCK elements in place and writes its block total.
// push.params: x element count, y input offset into scan_scratch, z block-sum offset into
// scan_scratch, w level (0: input is the bundle sizes, output bundle_offsets).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = SCAN_THREADS) in;
#include "bundle_sizes.glsl"

shared uvec4 partial[SCAN_THREADS];

#define PER_THREAD (SCAN_BLOCK / uint(SCAN_THREADS))

uvec4 load(uint i) {
    return push.params.w == 0u ? bundle_sizes(bundle_lods[i]) : scan_scratch[push.params.y + i];
}

void store(uint i, uvec4 v) {
    if (push.params.w == 0u) {
        bundle_offsets[i] = v;
    } else {
        scan_scratch[push.params.y + i] = v;
    }
}

void main() {
    uint count = push.params.x;
    uint block = gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x;
    uint t = gl_LocalInvocationID.x;
    uint base = block * SCAN_BLOCK + t * PER_THREAD;
    uvec4 v[PER_THREAD];
    uvec4 sum = uvec4(0u);
    for (uint i = 0u; i < PER_THREAD; i++) {
        v[i] = base + i < count ? load(base + i) : uvec4(0u);
        sum += v[i];
    }
    // Hillis-Steele inclusive scan of the per-thread sums.
    partial[t] = sum;
    barrier();
    for (uint step = 1u; step < uint(SCAN_THREADS); step <<= 1u) {
        uvec4 add = t >= step ? partial[t - step] : uvec4(0u);
        barrier();
        partial[t] += add;
        barrier();
    }
    uvec4 run = partial[t] - sum;
    for (uint i = 0u; i < PER_THREAD; i++) {
        if (base + i < count) {
            store(base + i, run);
        }
        run += v[i];
    }
    if (t == uint(SCAN_THREADS) - 1u) {
        scan_scratch[push.params.z + block] = partial[t];
    }
}
