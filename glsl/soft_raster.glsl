// Software rasterizer: what the binning (soft_bin.comp) and raster (soft_raster.comp) passes
// share: the segment buffers, decoding a SoftSegment, the footprint walk and the pixel
// coverage. CPU twin of the coverage: src/render/soft.rs (pixel_coverage). Requires bindings.glsl.
#ifndef SOFT_RASTER_GLSL
#define SOFT_RASTER_GLSL
#include "fragment_pack.glsl"

layout(set = SET_FRAME, binding = BINDING_SOFT_SEGMENTS, std430) readonly buffer SoftSegments { SoftSegment soft_segments[]; };
// Per tile: x segments touching it, y first entry, z scatter cursor, w entries kept.
layout(set = SET_FRAME, binding = BINDING_SOFT_TILES, std430) buffer SoftTiles { uvec4 soft_tiles[]; };
layout(set = SET_FRAME, binding = BINDING_SOFT_ENTRIES, std430) buffer SoftEntries { uint soft_entries[]; };
layout(set = SET_FRAME, binding = BINDING_SOFT_DEPTH, std430) readonly buffer SoftDepth { float soft_depth[]; };

struct Segment {
    vec2 a;          // end a, pixels
    vec2 b;          // end b, pixels
    float za;        // depths (0..1)
    float zb;
    float half_width; // half the drawn width, pixels
    float thickness;  // strands it stands for (lod_appearance.glsl)
    uint color_a;     // pack_fragment: colour, covered share of the drawn width
    uint color_b;
};

Segment load_segment(uint i) {
    SoftSegment s = soft_segments[i];
    Segment r;
    r.a = s.a.xy;
    r.b = s.a.xy + unpackHalf2x16(s.b.x);
    r.za = s.a.z;
    r.zb = s.a.w;
    vec2 wk = unpackHalf2x16(s.b.w);
    r.half_width = 0.5 * wk.x;
    r.thickness = wk.y;
    r.color_a = s.b.y;
    r.color_b = s.b.z;
    return r;
}

uint tiles_per_row() {
    return frame.soft_grid.x;
}

uint tile_rows() {
    return frame.soft_grid.y;
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
// its normal n, length len.
struct SegmentFrame {
    vec2 a;
    vec2 d;
    vec2 n;
    float len;
};

SegmentFrame segment_frame(vec2 a, vec2 b) {
    vec2 d = b - a;
    float len = length(d);
    d = len > 0.0 ? d / len : vec2(1.0, 0.0);
    return SegmentFrame(a, d, vec2(-d.y, d.x), len);
}

// Area of the unit square centred on the origin where n . y <= t, for a unit normal n whose
// larger and smaller absolute components are a and b (the box-filtered edge: a triangle, a
// trapezoid, then the complement of a triangle). CPU twin: square_below in src/render/soft.rs.
float square_below(float t, float a, float b) {
    float s = t + 0.5 * (a + b);
    if (s <= 0.0) {
        return 0.0;
    }
    if (s >= a + b) {
        return 1.0;
    }
    if (s < b) {
        return s * s / (2.0 * a * b);
    }
    if (s <= a) {
        return (s - 0.5 * b) / a;
    }
    float e = a + b - s;
    return 1.0 - e * e / (2.0 * a * b);
}

// Share of the unit pixel square with corner `pmin` covered by the rectangle of half-width `h`
// around the segment (no end caps, so consecutive segments of a straight strand tile it
// exactly). Across: the exact area of the square inside the strip |v| <= h, two box-filtered
// edges. Along: times the share of the square between the segment's end lines, the
// box-filtered edges along it (1 for the pixels between them, most of them); the two shares of a joint between collinear
// segments add up to 1, so a strand has no seam (per pixel within 0.06 of the exact clipped
// area: src/render/soft.rs tests). No loops, no arrays: the same cost for every width.
float pixel_coverage(SegmentFrame f, float h, vec2 pmin) {
    if (f.len < 1e-9) {
        return 0.0;
    }
    vec2 q = pmin + 0.5 - f.a;
    float uc = dot(q, f.d);
    float vc = dot(q, f.n);
    float ea = max(abs(f.d.x), abs(f.d.y));
    float eb = min(abs(f.d.x), abs(f.d.y));
    float across = square_below(h - vc, ea, eb) - square_below(-h - vc, ea, eb);
    float along = square_below(f.len - uc, ea, eb) - square_below(-uc, ea, eb);
    return across * along;
}

#endif
