#version 460
// Compute path, pass 1: one invocation per bundle of the whole crowd: culling and LoD
// (bundle_lod.glsl, shared with the task shader). Writes bundle_lods[].
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = CULL_GROUP_SIZE) in;
#include "common.glsl"
#include "strand_eval.glsl"
#include "bundle_lod.glsl"

void main() {
    uint g = gl_WorkGroupID.y * (DISPATCH_ROW * uint(CULL_GROUP_SIZE)) + gl_GlobalInvocationID.x;
    if (g >= frame.counts.x) {
        return;
    }
    bind_character(bundles[g].character);
    BundleLod r = bundle_lod(g);
    bundle_lods[g] = encode_lod(r);
    if (r.strands > 0u) {
        atomicAdd(args.stats.bundles_visible, 1u);
    }
}
