#version 460
// Both paths, every view, before the strands are built: one invocation per bundle of the
// whole crowd decides culling and LoD (bundle_lod.glsl) and writes bundle_lods[], which the
// compute path's scan and generate passes and the mesh path's task shaders read. Each
// workgroup also adds up what its bundles ask of the frame's buffers (software segments,
// vertex-pool slots, and the slack eq. 8's ceiling can add), in units of LOD_DEMAND_UNIT, so
// lod_pressure.comp can thin every bundle evenly when a buffer would run full.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = CULL_GROUP_SIZE) in;
#include "common.glsl"
#include "strand_eval.glsl"
#include "bundle_lod.glsl"

// Software segments, their slack, vertex slots, their slack.
shared uint s_demand[4];

void main() {
    uint g = gl_WorkGroupID.y * (DISPATCH_ROW * uint(CULL_GROUP_SIZE)) + gl_GlobalInvocationID.x;
    if (gl_LocalInvocationIndex < 4u) {
        s_demand[gl_LocalInvocationIndex] = 0u;
    }
    barrier();
    if (g < frame.counts.bundles) {
        bind_character(bundles[g].character);
        BundleLod r = bundle_lod(g, 1.0);
        bundle_lods[g] = encode_lod(r);
        if (r.strands > 0u) {
            atomicAdd(args.stats.bundles_visible, 1u);
            uint segments = 1u << r.e;
            uint per_strand = r.soft ? segments : segments + 1u;
            uint kind = r.soft ? 0u : 2u;
            atomicAdd(s_demand[kind], r.strands * per_strand);
            atomicAdd(s_demand[kind + 1u], per_strand);
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        uint unit = LOD_DEMAND_UNIT;
        if (s_demand[0] > 0u) {
            atomicAdd(args.stats.soft_demand, (s_demand[0] + unit - 1u) / unit);
            atomicAdd(args.stats.soft_slack, (s_demand[1] + unit - 1u) / unit);
        }
        if (s_demand[2] > 0u) {
            atomicAdd(args.stats.pool_demand, (s_demand[2] + unit - 1u) / unit);
            atomicAdd(args.stats.pool_slack, (s_demand[3] + unit - 1u) / unit);
        }
    }
}
