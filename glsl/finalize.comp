#version 460
// Compute path, pass 3 (one invocation): totals, the vertex-pool budget and the indirect
// arguments. When the frame needs more vertex slots than the pool holds (frame.counts.vertex_budget),
// whole strands are kept in crowd order up to the budget: they are a prefix of every prefix
// sum, so generate.comp and strands.vert need no other change; the rest is reported.
// push.params.x: offset of the grand total in scan_scratch.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = 1) in;
#include "bundle_sizes.glsl"

void main() {
    uint bundles = frame.counts.bundles;
    uint budget = frame.counts.vertex_budget;
    uvec4 total = scan_scratch[push.params.x];
    uvec4 kept = total;
    if (total.y > budget) {
        // Last bundle whose first vertex slot is <= budget.
        uint lo = 0u;
        uint hi = bundles - 1u;
        while (lo < hi) {
            uint mid = (lo + hi + 1u) / 2u;
            if (bundle_offsets[mid].y <= budget) {
                lo = mid;
            } else {
                hi = mid - 1u;
            }
        }
        uvec4 off = bundle_offsets[lo];
        uvec4 lod = bundle_lods[lo];
        uint segments = lod_segments(lod.y);
        uint fit = lod_is_soft(lod.y) ? lod.x : min(lod.x, (budget - off.y) / (segments + 1u));
        kept = off + bundle_sizes(uvec4(fit, lod.yzw));
    }
    args.dispatch = uvec4(min(kept.w, DISPATCH_ROW), (kept.w + DISPATCH_ROW - 1u) / DISPATCH_ROW, 1u, 0u);
    args.draw = uvec4(kept.z, 1u, 0u, 0u);
    args.stats.strands_demanded = total.x;
    args.stats.strands_drawn = kept.x;
    args.stats.triangles_demanded = total.z / 3u;
    args.stats.triangles_drawn = kept.z / 3u;
    args.stats.vertex_slots_demanded = total.y;
    args.stats.vertex_slots_written = kept.y;
    args.stats.groups = kept.w;
}
