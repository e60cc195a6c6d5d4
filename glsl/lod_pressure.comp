#version 460
// Both paths, every view, after cull.comp: when the bundles' LoD asks for more software
// segments than the segment budget (frame.soft.segment_budget), or on the compute path (push.params.x != 0)
// more vertex slots than the pool holds (frame.counts.vertex_budget), every bundle of that kind keeps the
// same share of its strands (eq. 7's strand level times the share, eq. 8's thickness widened
// to keep its coverage: bundle_lod's pressure), so the frame fits and no character loses its hair to the order in which its
// strands were appended. CPU twin: reference::lod::{lod_pressure, strand_lod}.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = CULL_GROUP_SIZE) in;
#include "common.glsl"
#include "strand_eval.glsl"
#include "bundle_lod.glsl"

void main() {
    uint g = gl_WorkGroupID.y * (DISPATCH_ROW * uint(CULL_GROUP_SIZE)) + gl_GlobalInvocationID.x;
    if (g >= frame.counts.bundles) {
        return;
    }
    uvec4 lod = bundle_lods[g];
    if (lod.x == 0u) {
        return;
    }
    float p = 1.0;
    if (lod_is_soft(lod.y)) {
        p = lod_pressure(args.stats.soft_demand, args.stats.soft_slack, frame.soft.segment_budget);
    } else if (push.params.x != 0u) {
        p = lod_pressure(args.stats.pool_demand, args.stats.pool_slack, frame.counts.vertex_budget);
    }
    if (p < 1.0) {
        // The decision again with the lower level; the bundle stays with the rasterizer
        // whose budget the pressure answers.
        bind_character(bundles[g].character);
        BundleLod r = bundle_lod(g, p);
        r.soft = lod_is_soft(lod.y);
        bundle_lods[g] = encode_lod(r);
    }
}
