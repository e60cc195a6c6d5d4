#version 460
// Software rasterizer, raster (src/render/soft.rs): one workgroup per 16x16 tile, one thread
// per pixel for the setup and the merge, one thread per segment of the tile in between. Each
// segment's footprint inside the tile is walked pixel row by pixel row; a pixel gets the
// exact area of its square under the segment's rectangle (soft_raster.glsl), the depth and
// colour at the centre line point nearest its centre, and, in front of the opaque depth, is
// inserted into the pixel's K nearest fragments in shared memory (64-bit atomicMin of depth
// bits << 32 | packed colour, as oit.frag) or merged into its tail. At the end every pixel
// merges its list with the frame's k-buffer (oit.glsl), nearest first.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "bindings.glsl"
layout(local_size_x = SOFT_TILE, local_size_y = SOFT_TILE) in;
#include "soft_raster.glsl"
#define OIT_COMPUTE
#include "oit.glsl"
#include "lod_appearance.glsl"

#define TILE_PIXELS (SOFT_TILE * SOFT_TILE)

shared uint64_t s_nodes[TILE_PIXELS * SOFT_MAX_K];
shared uint s_tail[TILE_PIXELS * 4u];
shared float s_depth[TILE_PIXELS];

void insert(uint lp, uint k, float z, vec3 c, float alpha) {
    uint64_t v = (uint64_t(floatBitsToUint(z)) << 32) | uint64_t(pack_fragment(c, alpha));
    for (uint i = 0u; i < k; i++) {
        // A plain read first: nodes only ever get nearer, so a node already nearer than v
        // stays so, and the atomic (a compare-and-swap loop on some GPUs, slow where hundreds
        // of fragments meet in one pixel) is spent only where v displaces something.
        if (v >= s_nodes[lp * SOFT_MAX_K + i]) {
            continue;
        }
        uint64_t old = atomicMin(s_nodes[lp * SOFT_MAX_K + i], v);
        if (old == OIT_EMPTY) {
            return;
        }
        v = max(old, v);
    }
    vec4 f = unpack_fragment(uint(v & 0xFFFFFFFFul));
    float tau = optical_depth(f.a);
    uvec4 add = uvec4(round(vec4(f.rgb * tau, tau) * OIT_FIXED));
    atomicAdd(s_tail[lp * 4u], add.x);
    atomicAdd(s_tail[lp * 4u + 1u], add.y);
    atomicAdd(s_tail[lp * 4u + 2u], add.z);
    atomicAdd(s_tail[lp * 4u + 3u], add.w);
}

// Rasterize segment `s` inside the tile whose first pixel is `origin` (`extent` pixels of it
// inside the image).
void raster_segment(Segment s, ivec2 origin, ivec2 extent, uint k) {
    float h = s.half_width;
    // The coverage frame once per segment, not per pixel.
    SegmentFrame frame_ab = segment_frame(s.a, s.b);
    vec2 d = s.b - s.a;
    float len2 = dot(d, d);
    vec4 ca = unpack_fragment(s.color_a);
    vec4 cb = unpack_fragment(s.color_b);
    float opacity = frame.soft_params.y;
    int y0 = max(int(floor(min(s.a.y, s.b.y) - h)), origin.y);
    int y1 = min(int(floor(max(s.a.y, s.b.y) + h)), origin.y + extent.y - 1);
    for (int y = y0; y <= y1; y++) {
        vec2 t = clip_param(s.a, s.b, 1, float(y) - h, float(y + 1) + h);
        if (t.x > t.y) {
            continue;
        }
        float xa = mix(s.a.x, s.b.x, t.x);
        float xb = mix(s.a.x, s.b.x, t.y);
        int x0 = max(int(floor(min(xa, xb) - h)), origin.x);
        int x1 = min(int(floor(max(xa, xb) + h)), origin.x + extent.x - 1);
        for (int x = x0; x <= x1; x++) {
            vec2 pmin = vec2(x, y);
            float cov = pixel_coverage(frame_ab, h, pmin);
            if (cov <= 0.0) {
                continue;
            }
            // Depth and colour at the centre line point nearest the pixel centre.
            float u = clamp(dot(pmin + 0.5 - s.a, d) / len2, 0.0, 1.0);
            float z = mix(s.za, s.zb, u);
            uint lp = uint(y - origin.y) * SOFT_TILE + uint(x - origin.x);
            if (!(z < s_depth[lp])) {
                continue;
            }
            vec4 c = mix(ca, cb, u);
            float alpha = cluster_opacity(opacity * cov * c.a, s.thickness);
            if (alpha < 0.5 / 255.0) {
                continue;
            }
            insert(lp, k, z, c.rgb, alpha);
        }
    }
}

void main() {
    uint cols = tiles_per_row();
    uint tile = gl_WorkGroupID.y * cols + gl_WorkGroupID.x;
    uvec4 info = soft_tiles[tile];
    if (info.w == 0u) {
        return;
    }
    uint lp = gl_LocalInvocationIndex;
    uint k = frame.soft.y;
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * int(SOFT_TILE);
    ivec2 extent = min(ivec2(SOFT_TILE), size - origin);
    ivec2 pixel = origin + ivec2(gl_LocalInvocationID.xy);
    bool inside = all(lessThan(pixel, size));
    uint p = uint(pixel.y) * uint(size.x) + uint(pixel.x);
    for (uint i = 0u; i < SOFT_MAX_K; i++) {
        s_nodes[lp * SOFT_MAX_K + i] = OIT_EMPTY;
    }
    for (uint i = 0u; i < 4u; i++) {
        s_tail[lp * 4u + i] = 0u;
    }
    s_depth[lp] = inside ? soft_depth[p] : 0.0;
    barrier();
    for (uint e = lp; e < info.w; e += TILE_PIXELS) {
        raster_segment(load_segment(soft_entries[info.y + e]), origin, extent, k);
    }
    barrier();
    if (!inside) {
        return;
    }
    // Insert the tile's fragments into the k-buffer's sorted list (the pixel is this
    // thread's alone now): the nearest frame.transparency.y stay nodes, the others join the
    // tail.
    uint kg = frame.transparency.y;
    uvec4 tail = uvec4(s_tail[lp * 4u], s_tail[lp * 4u + 1u], s_tail[lp * 4u + 2u], s_tail[lp * 4u + 3u]);
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
