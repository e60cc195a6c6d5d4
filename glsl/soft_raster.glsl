// Software rasterizer: what the binning (soft_bin.comp) and raster (soft_raster.comp) passes
// share: the segment buffers, decoding a SoftSegment, the footprint walk and the exact pixel
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
    return uint(frame.soft_params.z);
}

uint tile_rows() {
    return uint(frame.soft_params.w);
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

// Length of the segment offset by v along its normal inside the unit pixel square with
// corner `pmin` (Liang-Barsky slab clipping).
float chord_in_pixel(SegmentFrame f, float v, vec2 pmin) {
    vec2 c = f.a + v * f.n;
    float lo = 0.0;
    float hi = f.len;
    for (int axis = 0; axis < 2; axis++) {
        float da = f.d[axis];
        float p0 = pmin[axis] - c[axis];
        if (abs(da) < 1e-12) {
            // Parallel to this axis: inside when pmin <= c < pmin + 1 (half-open, so a line
            // on a pixel edge counts once).
            if (p0 > 0.0 || p0 + 1.0 <= 0.0) {
                return 0.0;
            }
        } else {
            float t0 = p0 / da;
            float t1 = (p0 + 1.0) / da;
            lo = max(lo, min(t0, t1));
            hi = min(hi, max(t0, t1));
        }
    }
    return max(hi - lo, 0.0);
}

// Strands drawn at most this wide (pixels) take the line-sampled coverage below. CPU twin:
// THIN_WIDTH.
// SOFT_THIN_WIDTH: shared.glsl (render::soft::THIN_WIDTH).

// The exact area for thick strands: the square in the segment's frame, clipped by the four
// sides of the rectangle (Sutherland-Hodgman), then the shoelace formula. Its arrays land in
// local memory on GPUs (4-5x slower than the line samples), hence only beyond SOFT_THIN_WIDTH.
float pixel_coverage_exact(SegmentFrame f, float h, vec2 pmin) {
    vec2 poly[8];
    vec2 tmp[8];
    for (int i = 0; i < 4; i++) {
        vec2 q = pmin + vec2(float(i == 1 || i == 2), float(i >= 2)) - f.a;
        poly[i] = vec2(dot(q, f.d), dot(q, f.n));
    }
    // The pixel wholly outside one side of the rectangle, or wholly inside it: no clipping
    // (most pixels of a wide strand's footprint; the clip's local arrays are slow).
    vec2 lo = min(min(poly[0], poly[1]), min(poly[2], poly[3]));
    vec2 hi = max(max(poly[0], poly[1]), max(poly[2], poly[3]));
    if (hi.x <= 0.0 || lo.x >= f.len || hi.y <= -h || lo.y >= h) {
        return 0.0;
    }
    if (lo.x >= 0.0 && hi.x <= f.len && lo.y >= -h && hi.y <= h) {
        return 1.0;
    }
    int count = 4;
    // Keep sign * (p[axis] - bound) <= 0 for (axis, bound, sign) = (u, len, +), (u, 0, -),
    // (v, h, +), (v, -h, -).
    for (int side = 0; side < 4; side++) {
        int axis = side / 2;
        float bound = side == 0 ? f.len : (side == 1 ? 0.0 : (side == 2 ? h : -h));
        float sgn = (side % 2 == 0) ? 1.0 : -1.0;
        int m = 0;
        for (int i = 0; i < count; i++) {
            vec2 p = poly[i];
            vec2 q = poly[(i + 1) % count];
            float fp = sgn * (p[axis] - bound);
            float fq = sgn * (q[axis] - bound);
            if (fp <= 0.0) {
                tmp[m++] = p;
            }
            if ((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) {
                tmp[m++] = mix(p, q, fp / (fp - fq));
            }
        }
        count = m;
        for (int i = 0; i < m; i++) {
            poly[i] = tmp[i];
        }
        if (count < 3) {
            return 0.0;
        }
    }
    float area = 0.0;
    for (int i = 0; i < count; i++) {
        vec2 p = poly[i];
        vec2 q = poly[(i + 1) % count];
        area += p.x * q.y - q.x * p.y;
    }
    return clamp(0.5 * abs(area), 0.0, 1.0);
}

// Area of the unit pixel square with corner `pmin` covered by the rectangle of half-width
// `h` around the segment (no end caps, so consecutive segments of a straight strand tile it
// exactly). Thin strands (2h <= SOFT_THIN_WIDTH): the rectangle as n = ceil(8h) lines
// across its width (at most a quarter pixel apart), 2h / n each, every line clipped to the
// pixel (the midpoint rule across, exact along; summed over the pixels it gives exactly the
// rectangle's area, and n = 1 is the box-filtered centre line). Thicker strands: the exact
// area.
float pixel_coverage(SegmentFrame f, float h, vec2 pmin) {
    if (f.len < 1e-9) {
        return 0.0;
    }
    if (2.0 * h > SOFT_THIN_WIDTH) {
        return pixel_coverage_exact(f, h, pmin);
    }
    int lines = max(int(ceil(8.0 * h)), 1);
    float step = 2.0 * h / float(lines);
    float sum = 0.0;
    for (int i = 0; i < lines; i++) {
        sum += chord_in_pixel(f, -h + (float(i) + 0.5) * step, pmin);
    }
    // Not clamped at 1: a pixel's samples may add up a little past it (the neighbours get as
    // much less), and the total stays the strand's area.
    return sum * step;
}

#endif
