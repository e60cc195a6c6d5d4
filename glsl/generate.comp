#version 460
// Compute path, pass 4: one workgroup of S threads per group of strands (one long strand, or
// several short ones) builds them in shared memory (strand_build.glsl, shared with the mesh
// shader) and writes HairVertex records into the pool, never past the kept slots; a bundle
// the software rasterizer draws appends its segments instead (soft_segments.glsl).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = STRAND_GROUP_SIZE) in;
#include "common.glsl"
#include "strand_eval.glsl"
#include "strand_build.glsl"
// Camera pipelines only (the light's passes draw hardware strips, and its maps are
// attachments while they draw).
#ifdef SOFT_RASTER
#include "soft_segments.glsl"
#endif

void main() {
    uint g = gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x;
    if (g >= args.stats.groups) {
        return;
    }
    uint bundle = group_bundle(g);
    bind_character(bundles[bundle].character);
    uvec4 lod = bundle_lods[bundle];
    uint segments = lod_segments(lod.y);
    uint per = strands_per_group(segments);
    uint first = (g - bundle_offsets[bundle].w) * per;
    uint t = gl_LocalInvocationID.x;
    build_strands(bundle, first, segments, uintBitsToFloat(lod.z), t);
    float width_scale = model_scale * uintBitsToFloat(lod.w);
    uint stride = segments + 1u;
    uint count = min(per, lod.x - first);
#ifdef SOFT_RASTER
    if (lod_is_soft(lod.y)) {
        if (t < per) {
            float cap = model_scale * bundles[bundle].rest_size;
            set_soft_strand(t, width_scale * lod_strand_fade(lod, first + t), uintBitsToFloat(lod.w), cap);
        }
        emit_soft_segments(count, segments, style_color(), bundles[bundle].character, t);
        return;
    }
#endif
    uint limit = args.stats.vertex_slots_written;
    for (uint idx = t; idx < count * stride; idx += S) {
        uint j = idx / stride;
        uint k = idx - j * stride;
        float s = float(k) / float(segments);
        uint out_index = bundle_offsets[bundle].y + (first + j) * stride + k;
        if (out_index < limit) {
            float fade = lod_strand_fade(lod, first + j);
            hair_vertices[out_index].pos_width = vec4(sp[idx], width_scale * fade * strand_width_at(s));
            hair_vertices[out_index].tangent_s = vec4(st[idx], s);
#ifdef VISIBILITY
            if (frame.temporal.residuals != 0u) {
                vertex_motion[out_index] = packHalf2x16(entry_residual(idx, bundles[bundle].character));
            }
#endif
        }
    }
}
