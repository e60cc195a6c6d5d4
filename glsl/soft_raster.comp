#version 460
// Software rasterizer, raster (src/render/soft.rs): one workgroup per 16x16 tile, one thread
// per pixel for the setup and the merge, one thread per segment of the tile in between. Each
// segment's footprint inside the tile is walked pixel row by pixel row; a pixel in front of the
// opaque depth gets the area of its square under the segment's rectangle (soft_raster.glsl),
// the depth and colour at the centre line point nearest its centre, and is inserted into the
// pixel's K nearest fragments in shared memory (64-bit atomicMin of depth bits << 32 | packed
// colour, as oit.frag) or merged into its fixed-point tail. At the end every pixel merges its
// list with the frame's k-buffer (oit.glsl), nearest first. A fragment behind fragments of the
// pixel whose transmittance together is below SOFT_HIDDEN_TRANSMITTANCE is hidden (insert):
// it is dropped before its coverage is computed, as behind the opaque depth. The result does
// not depend on the order of arrival but for what hiding takes out of the tail (CPU twin:
// render::soft_pixel::PixelFragments).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "bindings.glsl"
layout(local_size_x = SOFT_TILE, local_size_y = SOFT_TILE) in;
#include "soft_raster.glsl"
#define OIT_COMPUTE
#include "oit.glsl"
#include "lod_appearance.glsl"
#include "temporal.glsl"
#include "volume_shading.glsl"

#define TILE_PIXELS (SOFT_TILE * SOFT_TILE)

shared uint64_t s_nodes[TILE_PIXELS * SOFT_MAX_K];
// Per pixel: the tail's fixed-point sums, (r, g) and (b, optical depth) in the low and high
// halves of two 64-bit lanes.
shared uint64_t s_tail[TILE_PIXELS * 2u];
// Per pixel: the depth (float bits; depths are not negative, so their bits order as the
// floats do) from which fragments are hidden: the opaque depth, then nearer where the
// pixel's own fragments hide what lies behind them (insert).
shared uint s_depth[TILE_PIXELS];
// Per pixel row of the tile: its farthest opaque depth (tile_far).
shared float s_row_far[SOFT_TILE];
// optical_depth of each 8-bit fragment alpha (a log per evicted fragment otherwise).
shared float s_optical_depth[256];
#ifdef VISIBILITY
// Per pixel: the nearest fragment's visibility word (temporal.glsl), noted into the frame's
// visibility once per pixel at the end.
shared uint64_t s_visible[TILE_PIXELS];
#endif

// Add fragment `v` to pixel lp's K nearest (k of them), or its tail. The walk down the list
// multiplies the light the nodes it passes or leaves behind it let through (a product of
// 1 - alpha: no table lookup, which cost 3 % of the crowd's raster); once that is below
// SOFT_HIDDEN_TRANSMITTANCE, everything behind the farthest of them is hidden: the pixel's
// hiding depth comes nearer (shade_pixel drops what lies behind it) and the fragment still
// carried, which lies behind them, is dropped. Every node counted is a fragment already deposited, so what
// is dropped lies behind fragments of transmittance below SOFT_HIDDEN_TRANSMITTANCE whatever
// the order of arrival.
void insert(uint lp, uint k, uint64_t v) {
    uint first = lp * SOFT_MAX_K;
    // Nodes only ever get nearer and stay sorted once every insert has passed: a fragment
    // not nearer than the K-th node now is not among the K nearest at the end either, so it
    // goes straight to the tail (most fragments, where hair is dense) without the walk.
    if (v < s_nodes[first + k - 1u]) {
        float light = 1.0;
        uint far = 0u;
        for (uint i = 0u; i < k; i++) {
            // A plain read first: a node already nearer than v stays so, and the atomic (a
            // compare-and-swap loop on some GPUs, slow where hundreds of fragments meet in
            // one pixel) is spent only where v displaces something.
            uint64_t node = s_nodes[first + i];
            if (v < node) {
                uint64_t old = atomicMin(s_nodes[first + i], v);
                node = min(old, v);
                v = max(old, v);
            }
            light *= 1.0 - float(uint(node) >> 24) * (1.0 / 255.0);
            far = max(far, uint(node >> 32));
            if (light < SOFT_HIDDEN_TRANSMITTANCE) {
                atomicMin(s_depth[lp], far);
                if (uint(v >> 32) >= far) {
                    return;
                }
            }
            if (v == OIT_EMPTY) {
                return;
            }
        }
    }
    // Two 32-bit sums in each 64-bit lane: a low half carries into the high half only past
    // 2^32, where the frame's 32-bit k-buffer tail would overflow anyway (oit.glsl).
    uint packed = uint(v & 0xFFFFFFFFul);
    vec4 f = unpack_fragment(packed);
    float tau = s_optical_depth[packed >> 24];
    uvec4 add = uvec4(round(vec4(f.rgb * tau, tau) * OIT_FIXED));
    atomicAdd(s_tail[lp * 2u], uint64_t(add.x) | (uint64_t(add.y) << 32));
    atomicAdd(s_tail[lp * 2u + 1u], uint64_t(add.z) | (uint64_t(add.w) << 32));
}

// What the raster needs of a segment, computed once per segment: its coverage frame, half
// width, end depths and unpacked end colours, and the strands it stands for.
struct SegmentRaster {
    SegmentFrame f;
    float h;
    vec2 z;
    vec4 ca;
    vec4 cb;
    float thickness;
    uint id;
    vec2 residual;  // deformation residual (temporal.glsl)
};

// The fragment of segment `s` in pixel `pixel` of the tile at `origin`: inserted when it lies
// in front of the opaque depth and covers part of the pixel.
void shade_pixel(SegmentRaster s, ivec2 pixel, ivec2 origin, uint k) {
    vec2 pmin = vec2(pixel);
    // Depth and colour at the centre line point nearest the pixel centre.
    float u = clamp(dot(pmin + 0.5 - s.f.a, s.f.d) / s.f.len, 0.0, 1.0);
    float depth = mix(s.z.x, s.z.y, u);
    uint lp = uint(pixel.y - origin.y) * SOFT_TILE + uint(pixel.x - origin.x);
    if (!(depth < uintBitsToFloat(s_depth[lp]))) {
        return;
    }
    float cov = pixel_coverage(s.f, s.h, pmin);
    if (cov <= 0.0) {
        return;
    }
    vec4 c = mix(s.ca, s.cb, u);
    float alpha = cluster_opacity(frame.soft.strand_opacity * cov * c.a, s.thickness);
    if (alpha < 0.5 / 255.0) {
        return;
    }
    uint64_t v = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(pack_fragment(c.rgb, alpha));
#ifdef VISIBILITY
    if (frame.temporal.motion != 0u) {
        atomicMin(s_visible[lp], visibility_word(depth, s.id, s.residual));
    }
#endif
    insert(lp, k, v);
}

// Rows [y0, y1] and columns [x0, x1] of the tile at `origin` (`extent` pixels of it inside
// the image) that segment s's rectangle can touch.
ivec4 footprint_box(Segment s, ivec2 origin, ivec2 extent) {
    float h = s.half_width;
    ivec2 lo = max(ivec2(floor(min(s.a, s.b) - h)), origin);
    ivec2 hi = min(ivec2(floor(max(s.a, s.b) + h)), origin + extent - 1);
    return ivec4(lo, hi);
}

// The farthest opaque depth of the tile: a segment nearer nowhere than it is hidden in all of
// the tile (a pixel's depth lies between its segment's end depths).
float tile_far;

// Rasterize segment `s` alone, walking its footprint inside the tile row by row.
void raster_segment(Segment s, vec2 residual, ivec2 origin, ivec2 extent, uint k) {
    if (min(s.za, s.zb) > tile_far) {
        return;
    }
    float h = s.half_width;
    SegmentRaster r = SegmentRaster(segment_frame(s.a, s.b), h, vec2(s.za, s.zb), unpack_fragment(s.color_a),
                                    unpack_fragment(s.color_b), s.thickness, s.id, residual);
    ivec4 box = footprint_box(s, origin, extent);
    for (int y = box.y; y <= box.w; y++) {
        vec2 t = clip_param(s.a, s.b, 1, float(y) - h, float(y + 1) + h);
        if (t.x > t.y) {
            continue;
        }
        float xa = mix(s.a.x, s.b.x, t.x);
        float xb = mix(s.a.x, s.b.x, t.y);
        int x0 = max(int(floor(min(xa, xb) - h)), box.x);
        int x1 = min(int(floor(max(xa, xb) + h)), box.z);
        for (int x = x0; x <= x1; x++) {
            shade_pixel(r, ivec2(x, y), origin, k);
        }
    }
}

// Deformation residual of segment si (temporal.glsl), in frames with motion vectors.
vec2 segment_residual(uint si) {
#ifdef VISIBILITY
    if (frame.temporal.motion != 0u) {
        return unpackHalf2x16(segment_motion[si]);
    }
#endif
    return vec2(0.0);
}

void main() {
    uint cols = tiles_per_row();
    uint tile = gl_WorkGroupID.y * cols + gl_WorkGroupID.x;
    uvec4 info = soft_tiles[tile];
    if (info.w == 0u) {
        return;
    }
    uint lp = gl_LocalInvocationIndex;
    uint k = frame.soft.k;
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * int(SOFT_TILE);
    ivec2 extent = min(ivec2(SOFT_TILE), size - origin);
    ivec2 pixel = origin + ivec2(gl_LocalInvocationID.xy);
    bool inside = all(lessThan(pixel, size));
    uint p = uint(pixel.y) * uint(size.x) + uint(pixel.x);
    for (uint i = 0u; i < SOFT_MAX_K; i++) {
        s_nodes[lp * SOFT_MAX_K + i] = OIT_EMPTY;
    }
    s_tail[lp * 2u] = 0ul;
    s_tail[lp * 2u + 1u] = 0ul;
#ifdef VISIBILITY
    s_visible[lp] = OIT_EMPTY;
#endif
    s_depth[lp] = floatBitsToUint(inside ? soft_depth[p] : 0.0);
    if (lp < SOFT_TILE) {
        // The farthest opaque depth of tile row lp, read from the buffer (so no barrier is
        // needed before it); rows below the image stay 0.
        uint row = uint(origin.y) + lp;
        float far = 0.0;
        for (uint x = 0u; x < uint(extent.x) && lp < uint(extent.y); x++) {
            far = max(far, soft_depth[row * uint(size.x) + uint(origin.x) + x]);
        }
        s_row_far[lp] = far;
    }
    for (uint a = lp; a < 256u; a += TILE_PIXELS) {
        s_optical_depth[a] = optical_depth(float(a) / 255.0);
    }
    barrier();
    tile_far = 0.0;
    // Only threads with a segment to draw need it (most, in sparse tiles, have none).
    for (uint y = 0u; y < SOFT_TILE && lp < info.w; y++) {
        tile_far = max(tile_far, s_row_far[y]);
    }
    for (uint e = lp; e < info.w; e += TILE_PIXELS) {
        uint si = soft_entries[info.y + e];
        raster_segment(load_segment(si), segment_residual(si), origin, extent, k);
    }
    barrier();
    if (!inside) {
        return;
    }
#ifdef VISIBILITY
    uint64_t nearest = s_visible[lp];
    if (nearest != OIT_EMPTY) {
        note_visible_word(uvec2(pixel), nearest);
    }
#endif
    // Insert the tile's fragments into the k-buffer's sorted list (the pixel is this
    // thread's alone now): the nearest frame.transparency.kbuffer_nodes stay nodes, the others join the
    // tail.
    uint kg = frame.transparency.kbuffer_nodes;
    uint64_t rg = s_tail[lp * 2u];
    uint64_t ba = s_tail[lp * 2u + 1u];
    uvec4 tail = uvec4(uint(rg), uint(rg >> 32), uint(ba), uint(ba >> 32));
    uint start = 0u;
    for (uint j = 0u; j < k; j++) {
        uint64_t v = s_nodes[lp * SOFT_MAX_K + j];
        if (v == OIT_EMPTY) {
            break;
        }
        // Nodes before `start` are nearer than this fragment (both lists are sorted); the
        // fragment lands at the first farther node, which moves on down the list.
        bool placed = false;
        for (uint i = start; i < kg && v != OIT_EMPTY; i++) {
            uint64_t old = oit_nodes[p * kg + i];
            if (v < old) {
                oit_nodes[p * kg + i] = v;
                v = old;
                if (!placed) {
                    start = i + 1u;
                    placed = true;
                }
            } else if (!placed) {
                start = i + 1u;
            }
        }
        if (v != OIT_EMPTY) {
            vec4 f = unpack_fragment(uint(v & 0xFFFFFFFFul));
            float tau = optical_depth(f.a);
            tail += uvec4(round(vec4(f.rgb * tau, tau) * OIT_FIXED));
        }
    }
    if (any(notEqual(tail, uvec4(0u)))) {
        oit_tail[p] += tail;
    }
}
