#version 460
// Compute path, pass 2: one workgroup of S threads per strand builds it in shared memory
// (strand_build.glsl, shared with the mesh shader) and writes HairVertex records.
#extension GL_GOOGLE_include_directive : require
#define S 32u
#define MAX_SEGMENTS 64u
layout(local_size_x = 32) in;
#include "bindings.glsl"
#include "common.glsl"
#include "strand_eval.glsl"
#include "strand_build.glsl"

// Last bundle whose first strand is <= g (never an empty one for g < total).
uint find_bundle(uint g) {
    uint lo = 0u;
    uint hi = frame.params.z - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) / 2u;
        if (bundle_offsets[mid].x <= g) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

void main() {
    uint g = gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x;
    if (g >= indirect.total_strands) {
        return;
    }
    uint bundle = find_bundle(g);
    uvec4 lod = bundle_lods[bundle];
    uint segments = 1u << lod.y;
    uint strand = g - bundle_offsets[bundle].x;
    StrandInfo si = strand_info(bundle, strand);
    uint t = gl_LocalInvocationID.x;
    build_strand(si, segments, uintBitsToFloat(lod.z), t);
    float width_scale = length(push.model[0].xyz) * uintBitsToFloat(lod.w);
    uint base = bundle_offsets[bundle].y + strand * (segments + 1u);
    for (uint k = t; k <= segments; k += S) {
        float s = float(k) / float(segments);
        hair_vertices[base + k].pos_width = vec4(sp[k], width_scale * strand_width_at(s));
        hair_vertices[base + k].tangent_s = vec4(st[k], s);
    }
}
