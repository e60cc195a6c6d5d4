#version 460
// Software rasterizer, binning (src/render/soft.rs): one thread per stored segment walks the
// 16x16-pixel tiles its footprint touches, tile row by tile row (the centre line clipped to
// the row's band, widened by the half width), so a long diagonal segment visits only its own
// tiles. Compiled twice: SCATTER undefined counts segments per tile; SCATTER defined writes
// the segment index into the tile's range (soft_tile_scan.comp made the ranges), never past
// the entries the tile kept.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = SOFT_BIN_GROUP) in;
#include "soft_raster.glsl"

void main() {
    uint i = (gl_WorkGroupID.y * DISPATCH_ROW + gl_WorkGroupID.x) * uint(SOFT_BIN_GROUP) + gl_LocalInvocationID.x;
    if (i >= args.stats.segments_written) {
        return;
    }
    Segment s = load_segment(i);
    float h = s.half_width;
    float tile = float(SOFT_TILE);
    int cols = int(tiles_per_row());
    int rows = int(tile_rows());
    float ylo = min(s.a.y, s.b.y) - h;
    float yhi = max(s.a.y, s.b.y) + h;
    int r0 = max(int(floor(ylo / tile)), 0);
    int r1 = min(int(floor(yhi / tile)), rows - 1);
    for (int r = r0; r <= r1; r++) {
        vec2 t = clip_param(s.a, s.b, 1, float(r) * tile - h, float(r + 1) * tile + h);
        if (t.x > t.y) {
            continue;
        }
        float xa = mix(s.a.x, s.b.x, t.x);
        float xb = mix(s.a.x, s.b.x, t.y);
        int c0 = max(int(floor((min(xa, xb) - h) / tile)), 0);
        int c1 = min(int(floor((max(xa, xb) + h) / tile)), cols - 1);
        for (int c = c0; c <= c1; c++) {
            uint id = uint(r) * uint(cols) + uint(c);
#ifdef SCATTER
            uint slot = atomicAdd(soft_tiles[id].z, 1u);
            if (slot < soft_tiles[id].w) {
                soft_entries[soft_tiles[id].y + slot] = i;
            }
#else
            atomicAdd(soft_tiles[id].x, 1u);
#endif
        }
    }
}
