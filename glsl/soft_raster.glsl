// Software rasterizer: what the binning (soft_bin.comp) and raster (soft_raster.comp) passes
// share: the segment buffers, decoding a SoftSegment, the footprint walk and the pixel
// coverage. CPU twin of the coverage: src/render/soft.rs (pixel_coverage). Requires bindings.glsl.
#ifndef SOFT_RASTER_GLSL
#define SOFT_RASTER_GLSL
#include "fragment_pack.glsl"
#include "soft_depth.glsl"

layout(set = SET_FRAME, binding = BINDING_SOFT_SEGMENTS, std430) readonly buffer SoftSegments { SoftSegment soft_segments[]; };
// Per tile: x segments touching it, y first entry, z scatter cursor, w entries kept.
layout(set = SET_FRAME, binding = BINDING_SOFT_TILES, std430) buffer SoftTiles { uvec4 soft_tiles[]; };
layout(set = SET_FRAME, binding = BINDING_SOFT_ENTRIES, std430) buffer SoftEntries { uint soft_entries[]; };

struct Segment {
    vec2 a;          // end a, pixels
    vec2 b;          // end b, pixels
    float za;        // depths (0..1)
    float zb;
    float half_width; // half the drawn width, pixels
    float thickness;  // strands it stands for (lod_appearance.glsl)
    uint id;          // visibility id of its character (temporal.glsl)
    uint color_a;     // pack_fragment: colour, covered share of the drawn width
    uint color_b;
};

Segment load_segment(uint i) {
    SoftSegment s = soft_segments[i];
    Segment r;
    r.a = s.a;
    r.b = s.a + unpackHalf2x16(s.b.x);
    r.za = s.za;
    r.zb = s.za + unpackHalf2x16(s.dz_id & 0xFFFFu).x;
    r.id = s.dz_id >> 16;
    vec2 wk = unpackHalf2x16(s.b.w);
    r.half_width = 0.5 * wk.x;
    r.thickness = wk.y;
    r.color_a = s.b.y;
    r.color_b = s.b.z;
    return r;
}

uint tiles_per_row() {
    return frame.soft.tiles_x;
}

uint tile_rows() {
    return frame.soft.tiles_y;
}

// The range of the parameter t in [0, 1] where the centre line a + t (b - a) has its
// coordinate `axis` in [lo, hi]; empty when x > y.
vec2 clip_param(vec2 a, vec2 b, int axis, float lo, float hi) {
    float pa = a[axis];
    float d = b[axis] - pa;
    if (abs(d) < 1e-12) {
        return (pa >= lo && pa <= hi) ? vec2(0.0, 1.0) : vec2(1.0, 0.0);
    }
    float t0 = (lo - pa) / d;
    float t1 = (hi - pa) / d;
    return vec2(max(min(t0, t1), 0.0), min(max(t0, t1), 1.0));
}

// A segment's frame for the coverage, computed once per segment: end a, unit direction d,
// its normal n, length len, and the box-filtered edge constants of both directions (their
// larger and smaller absolute components e = max(|d.x|, |d.y|), f = min(...), 1 / e and
// 1 / (2 e f); d and n share them).
struct SegmentFrame {
    vec2 a;
    vec2 d;
    vec2 n;
    float len;
    vec4 edge;
};

SegmentFrame segment_frame(vec2 a, vec2 b) {
    vec2 d = b - a;
    float len = length(d);
    d = len > 0.0 ? d / len : vec2(1.0, 0.0);
    float e = max(abs(d.x), abs(d.y));
    float f = min(abs(d.x), abs(d.y));
    return SegmentFrame(a, d, vec2(-d.y, d.x), len, vec4(e, f, 1.0 / e, 1.0 / (2.0 * e * f)));
}

// Area of the unit square centred on the origin where n . y <= t, for a unit normal n with
// edge constants `edge` (segment_frame) (the box-filtered edge: a triangle, a trapezoid, then
// the complement of a triangle; with f = 0 only the trapezoid). CPU twin: square_below in
// src/render/soft.rs.
float square_below(float t, vec4 edge) {
    float s = t + 0.5 * (edge.x + edge.y);
    if (s <= 0.0) {
        return 0.0;
    }
    if (s >= edge.x + edge.y) {
        return 1.0;
    }
    if (s < edge.y) {
        return s * s * edge.w;
    }
    if (s <= edge.x) {
        return (s - 0.5 * edge.y) * edge.z;
    }
    float r = edge.x + edge.y - s;
    return 1.0 - r * r * edge.w;
}

// Share of the unit pixel square with corner `pmin` covered by the rectangle of half-width `h`
// around the segment (no end caps, so consecutive segments of a straight strand tile it
// exactly). Across: the exact area of the square inside the strip |v| <= h, two box-filtered
// edges. Along: times the share of the square between the segment's end lines, the
// box-filtered edges along it (1 for the pixels between them, most of them); the two shares
// of a joint between collinear segments add up to 1, so a strand has no seam (per pixel
// within 0.06 of the exact clipped area: src/render/soft.rs tests). No loops, no arrays: the
// same cost for every width.
float pixel_coverage(SegmentFrame f, float h, vec2 pmin) {
    if (f.len < 1e-9) {
        return 0.0;
    }
    vec2 q = pmin + 0.5 - f.a;
    float uc = dot(q, f.d);
    float vc = dot(q, f.n);
    float across = square_below(h - vc, f.edge) - square_below(-h - vc, f.edge);
    float along = square_below(f.len - uc, f.edge) - square_below(-uc, f.edge);
    return across * along;
}

#endif
