#version 460
// Static and LHS paths through the software rasterizer: the stored strands in the vertex pool
// (the last compute-path frame's, skinned by lhs_skin.comp on the LHS path) become segments.
// One workgroup of S threads per strand workgroup of that frame (dispatched with its indirect
// arguments) loads its strands' vertices (only whole strands inside the slots that frame
// wrote) into the shared arrays generate.comp builds strands in, and hands them to
// emit_soft_segments, which shades, projects and appends them as for generated strands.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = STRAND_GROUP_SIZE) in;
#include "common.glsl"
#include "strand_eval.glsl"
#include "strand_build.glsl"
#define SOFT_POOL
#include "soft_segments.glsl"

void main() {
    uint g = gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x;
    if (g >= args.stats.groups) {
        return;
    }
    uint bundle = group_bundle(g);
    bind_character(bundles[bundle].character);
    uvec4 lod = bundle_lods[bundle];
    uint segments = lod_segments(lod.y);
    uint stride = segments + 1u;
    uint per = strands_per_group(segments);
    uint first = (g - bundle_offsets[bundle].w) * per;
    uint base = bundle_offsets[bundle].y + first * stride;
    uint limit = args.stats.vertex_slots_written;
    uint count = base < limit ? min(min(per, lod.x - first), (limit - base) / stride) : 0u;
    uint t = gl_LocalInvocationID.x;
    for (uint idx = t; idx < count * stride; idx += S) {
        HairVertex v = hair_vertices[base + idx];
        sp[idx] = v.pos_width.xyz;
        st[idx] = v.tangent_s.xyz;
        sw[idx] = v.pos_width.w;
    }
    barrier();
    if (t < per) {
        // The stored widths (sw) carry the width scale and the newest strand's share.
        set_soft_strand(t, 1.0, uintBitsToFloat(lod.w), model_scale * bundles[bundle].rest_size);
    }
    emit_soft_segments(count, segments, style_color(), bundles[bundle].character, t);
}
