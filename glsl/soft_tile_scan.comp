#version 460
// Software rasterizer: exclusive prefix sum of the per-tile segment counts into each tile's
// first entry (one workgroup; each thread owns a run of consecutive tiles). Entries past the
// budget (frame.soft.tile_entry_budget) are dropped from the tiles at the end of the order and counted.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
// One workgroup, dispatched alone: its width has no Rust twin.
#define TILE_SCAN_THREADS 256
layout(local_size_x = TILE_SCAN_THREADS) in;
#include "soft_raster.glsl"

shared uint s_sum[TILE_SCAN_THREADS];

void main() {
    uint t = gl_LocalInvocationID.x;
    uint tiles = tiles_per_row() * tile_rows();
    uint run = (tiles + TILE_SCAN_THREADS - 1u) / uint(TILE_SCAN_THREADS);
    uint first = min(t * run, tiles);
    uint last = min(first + run, tiles);
    uint mine = 0u;
    for (uint i = first; i < last; i++) {
        mine += soft_tiles[i].x;
    }
    s_sum[t] = mine;
    barrier();
    // Hillis-Steele inclusive scan over the 256 run totals.
    for (uint step = 1u; step < uint(TILE_SCAN_THREADS); step <<= 1u) {
        uint add = t >= step ? s_sum[t - step] : 0u;
        barrier();
        s_sum[t] += add;
        barrier();
    }
    uint budget = frame.soft.tile_entry_budget;
    uint offset = s_sum[t] - mine;
    for (uint i = first; i < last; i++) {
        uint count = soft_tiles[i].x;
        uint start = min(offset, budget);
        soft_tiles[i] = uvec4(count, start, 0u, min(offset + count, budget) - start);
        offset += count;
    }
    if (t == 255u) {
        args.stats.tile_entries_demanded = s_sum[255];
        args.stats.tile_entries_written = min(s_sum[255], budget);
    }
}
