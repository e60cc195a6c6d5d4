// What one bundle's LoD decision costs: strands, vertex slots (strands x (2^e + 1)), draw
// vertices (strands x 2^e x 6) and strand workgroups (strand_build.glsl packs
// max(S / 2^e, 1) strands per workgroup). A bundle the software rasterizer draws needs no
// vertex slots and no draw vertices (its segments are appended, soft_segments.glsl). Shared
// by scan.comp, finalize.comp and the task shader.
#ifndef BUNDLE_SIZES_GLSL
#define BUNDLE_SIZES_GLSL

uint strands_per_workgroup(uint segments) {
    return max(uint(STRAND_GROUP_SIZE) / segments, 1u);
}

uvec4 bundle_sizes(uvec4 lod) {
    uint segments = lod_segments(lod.y);
    uint per = strands_per_workgroup(segments);
    uint groups = (lod.x + per - 1u) / per;
    if (lod_is_soft(lod.y)) {
        return uvec4(lod.x, 0u, 0u, groups);
    }
    return uvec4(lod.x, lod.x * (segments + 1u), lod.x * segments * 6u, groups);
}

#endif
