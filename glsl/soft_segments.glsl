// Software rasterizer, step 1 (src/render/soft.rs): the strand builders (generate.comp,
// strands.mesh; pool_segments.comp for the stored strands of the static and LHS paths) hand a
// software bundle's strands, built (or loaded) in shared memory as strand_build.glsl lays
// them out, to emit_soft_segments: every vertex is shaded (strand_radiance.glsl, the
// same models as the fragment shaders, evaluated at the vertices and interpolated along the
// segment) and projected; every segment with both ends in the depth range and its footprint
// on screen is appended to soft_segments[]. The workgroup reserves its segments with one
// atomic add; those past the budget (frame.soft.segment_budget) are counted, not written. In the light's
// view (frame.soft.mode == RASTER_LIGHT) nothing is shaded: the shadow passes need depth and
// coverage only.
#ifndef SOFT_SEGMENTS_GLSL
#define SOFT_SEGMENTS_GLSL
#include "strip.glsl"
#include "strand_radiance.glsl"
#include "fragment_pack.glsl"

layout(set = SET_FRAME, binding = BINDING_SOFT_SEGMENTS, std430) writeonly buffer SoftSegments { SoftSegment soft_segments[]; };

// Per vertex: x, y in pixels, depth, drawn width in pixels (negative: outside the depth range).
shared vec4 sv_screen[MAX_ENTRIES];
// Per vertex: pack_fragment(radiance, covered share of the drawn width).
shared uint sv_color[MAX_ENTRIES];
shared uint s_soft_count;
shared uint s_soft_base;
#ifdef SOFT_POOL
// Per vertex: the stored strand width (pool_segments.comp loads it with the positions).
shared float sw[MAX_ENTRIES];
#elif defined(VISIBILITY)
// Per vertex: its deformation residual (temporal.glsl), in frames with motion vectors.
shared vec2 sv_residual[MAX_ENTRIES];
#endif

// Per strand handed to emit_soft_segments (strand j of the shared arrays): x its width scale
// (the model's scale times eq. 8's thickness, and for a bundle's newest strand its width share,
// lod_strand_fade), y eq. 8's thickness, z the cap on its drawn width (its bundle's size). The
// mesh path's software pass packs strands of several bundles into one workgroup, so these
// are per strand; set by the thread of strand j before the call.
shared vec3 s_soft_strand[S];

void set_soft_strand(uint j, float width_scale, float thickness, float cap) {
    s_soft_strand[j] = vec3(width_scale, thickness, cap);
}

// Width of entry idx (strand `strand` of those handed over) at parameter s: the stored one,
// or the builder's strand width.
float soft_vertex_width(uint idx, uint strand, float s) {
#ifdef SOFT_POOL
    return sw[idx];
#else
    return s_soft_strand[strand].x * strand_width_at(s);
#endif
}

// Longest segment kept, in pixels (the half-float end offset stays well inside its range).
#define SOFT_MAX_SEGMENT_PIXELS 16384.0

// Width the software rasterizer draws a strand of `width` with: its own width, or with the
// thick-strand term the footprint of the `thickness` strands it stands for (lod_appearance.glsl,
// sqrt(k) times the smaller of a pixel and one strand's width, capped by the bundle). Unlike
// hardware strips it is not widened to a pixel: coverage is computed exactly.
float soft_drawn_width(float width, float pixel, float thickness, float cap) {
    if (frame.shading.lod_appearance == 0u || thickness <= 1.0) {
        return width;
    }
    return max(width, min(sqrt(thickness) * min(pixel, width / thickness), cap));
}

bool soft_segment_kept(uint idx) {
    vec4 a = sv_screen[idx];
    vec4 b = sv_screen[idx + 1u];
    if (a.w < 0.0 || b.w < 0.0) {
        return false;
    }
    vec2 d = b.xy - a.xy;
    float h = 0.5 * max(a.w, b.w);
    vec2 lo = min(a.xy, b.xy) - h;
    vec2 hi = max(a.xy, b.xy) + h;
    bool on_screen = all(lessThan(lo, frame.viewport.xy)) && all(greaterThan(hi, vec2(0.0)));
    return on_screen && dot(d, d) > 1e-12 && max(abs(d.x), abs(d.y)) < SOFT_MAX_SEGMENT_PIXELS;
}

// Shade, project and append the segments of `count` strands of `segments` segments in
// sp / st, each with its set_soft_strand (all S threads call it: it contains barriers).
void emit_soft_segments(uint count, uint segments, vec3 color, uint character, uint t) {
    uint stride = segments + 1u;
    uint entries = count * stride;
    if (t == 0u) {
        s_soft_count = 0u;
    }
    barrier();
    for (uint idx = t; idx < entries; idx += S) {
        uint k = idx % stride;
        float s = float(k) / float(segments);
        vec3 p = sp[idx];
        vec4 c = frame.view_proj * vec4(p, 1.0);
        float pixel = pixel_size(p);
        vec3 strand = s_soft_strand[idx / stride];
        float thickness = strand.y;
        float width = soft_vertex_width(idx, idx / stride, s);
        float drawn = soft_drawn_width(width, pixel, thickness, strand.z);
        bool in_range = c.w > 1e-6 && c.z >= 0.0 && c.z <= c.w;
        vec3 ndc = c.xyz / max(c.w, 1e-6);
        vec2 screen = (ndc.xy * 0.5 + 0.5) * frame.viewport.xy;
        sv_screen[idx] = vec4(screen, ndc.z, in_range ? drawn / pixel : -1.0);
        vec3 radiance = frame.soft.mode == RASTER_LIGHT ? vec3(0.0) : strand_radiance(st[idx], s, p, color, character, thickness);
        sv_color[idx] = pack_fragment(radiance, width / max(drawn, 1e-20));
#if defined(VISIBILITY) && !defined(SOFT_POOL)
        sv_residual[idx] = entry_residual(idx, character);
#endif
    }
    barrier();
    // Count the kept segments (bit i of `kept`: this thread's i-th entry), reserve them with
    // one atomic add, then write them.
    uint mine = 0u;
    uint kept = 0u;
    for (uint idx = t, i = 0u; idx < entries; idx += S, i++) {
        if (idx % stride < segments && soft_segment_kept(idx)) {
            mine++;
            kept |= 1u << i;
        }
    }
    uint local = atomicAdd(s_soft_count, mine);
    barrier();
    if (t == 0u) {
        s_soft_base = s_soft_count > 0u ? atomicAdd(args.stats.segments_demanded, s_soft_count) : 0u;
    }
    barrier();
    uint budget = frame.soft.segment_budget;
    uint out_index = s_soft_base + local;
    for (uint idx = t, i = 0u; idx < entries; idx += S, i++) {
        if ((kept & (1u << i)) != 0u) {
            if (out_index < budget) {
                vec4 a = sv_screen[idx];
                vec4 b = sv_screen[idx + 1u];
                // The far end's depth as a half-float step from the near end's (relative
                // precision 2^-11 of the step), beside the character's visibility id.
                uint dz = packHalf2x16(vec2(b.z - a.z, 0.0)) & 0xFFFFu;
                soft_segments[out_index].a = a.xy;
                soft_segments[out_index].za = a.z;
                soft_segments[out_index].dz_id = dz | ((character & VISIBILITY_INDEX) << 16);
                float thickness = s_soft_strand[idx / stride].y;
                soft_segments[out_index].b = uvec4(packHalf2x16(b.xy - a.xy), sv_color[idx], sv_color[idx + 1u],
                                                   packHalf2x16(vec2(0.5 * (a.w + b.w), thickness)));
#ifdef VISIBILITY
                if (frame.temporal.motion != 0u) {
                    // The segment's deformation residual: its ends' mean (the stored strands
                    // of the static and LHS paths have none).
#ifdef SOFT_POOL
                    vec2 residual = vec2(0.0);
#else
                    vec2 residual = 0.5 * (sv_residual[idx] + sv_residual[idx + 1u]);
#endif
                    segment_motion[out_index] = packHalf2x16(residual);
                }
#endif
            }
            out_index++;
        }
    }
}

#endif
