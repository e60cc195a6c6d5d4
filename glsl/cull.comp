#version 460
// Compute path, pass 1a: one invocation per bundle: culling and LoD (bundle_lod.glsl, shared
// with the task shader). Writes bundle_lods[].
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;
#include "bindings.glsl"
#include "common.glsl"
#include "strand_eval.glsl"
#include "bundle_lod.glsl"

void main() {
    uint b = gl_GlobalInvocationID.x;
    if (b >= frame.params.z) {
        return;
    }
    BundleLod r = bundle_lod(b);
    bundle_lods[b] = uvec4(r.strands, r.e, floatBitsToUint(r.gamma), floatBitsToUint(r.thickness));
}
