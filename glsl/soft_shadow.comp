#version 460
// Software shadows (src/render/passes/soft_shadow.rs): the light's segments, binned into
// 16x16-texel tiles by soft_bin.comp with the light's frame block, drawn into the shadow maps
// in compute. One workgroup per tile, one thread per texel for setup and output, one thread
// per segment of the tile in between. Every workgroup writes all its texels (empty tiles
// included), so nothing needs clearing first. Compiled twice:
//
// - depth (OPACITY_PASS undefined): the depth of the hair nearest the light per texel, as
//   the hardware depth pass's strips at least one texel wide give it: a texel whose centre is
//   within max(half width, 1/2 texel) of the segment's centre line takes the depth of the
//   nearest centre line point; the minimum over segments by atomicMin on the float bits
//   (non-negative floats order as their bits).
// - deep opacity (OPACITY_PASS, Yuksel and Keyser 2008, as shadow.frag): each texel a segment
//   covers adds one strand's opacity (frame.shadow.strand_opacity) times the exact covered area
//   (soft_raster.glsl's pixel_coverage) times the drawn width's share, with seed 000's cluster
//   opacity for thick LoD strands, into the layer its depth falls in behind the hair depth
//   (steps of frame.shadow.layer_thickness). Sums are fixed point (SHADOW_OPACITY_FIXED) so the
//   result does not depend on the order segments arrive in; the four layers are written as the
//   RGBA16F texel of the layers map.
//
// The outputs are buffers that transfer copies put into the maps shadow_lookup.glsl samples.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
layout(local_size_x = SOFT_TILE, local_size_y = SOFT_TILE) in;
#include "soft_raster.glsl"
#include "lod_appearance.glsl"

#define TILE_TEXELS (SOFT_TILE * SOFT_TILE)

#ifdef OPACITY_PASS
layout(set = SET_FRAME, binding = BINDING_SOFT_SHADOW_DEPTH, std430) readonly buffer SoftShadowDepth { float soft_shadow_depth[]; };
layout(set = SET_FRAME, binding = BINDING_SOFT_SHADOW_LAYERS, std430) writeonly buffer SoftShadowLayers { uvec2 soft_shadow_layers[]; };
shared uint s_layers[TILE_TEXELS * 4u];
shared float s_hair_depth[TILE_TEXELS];
#else
layout(set = SET_FRAME, binding = BINDING_SOFT_SHADOW_DEPTH, std430) writeonly buffer SoftShadowDepth { uint soft_shadow_depth[]; };
shared uint s_depth[TILE_TEXELS];
#endif

// The centre line parameter of the point nearest `q`, and the squared distance to it.
vec2 nearest_on_segment(Segment s, vec2 q) {
    vec2 d = s.b - s.a;
    float u = clamp(dot(q - s.a, d) / max(dot(d, d), 1e-20), 0.0, 1.0);
    vec2 e = s.a + u * d - q;
    return vec2(u, dot(e, e));
}

// Visit the texels of the tile at `origin` (`extent` inside the map) that segment `s` reaches
// at half width `h`.
void draw_segment(Segment s, ivec2 origin, ivec2 extent, float h) {
#ifdef OPACITY_PASS
    SegmentFrame frame_ab = segment_frame(s.a, s.b);
    float share = 0.5 * (unpack_fragment(s.color_a).a + unpack_fragment(s.color_b).a);
#endif
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
            vec2 near = nearest_on_segment(s, vec2(x, y) + 0.5);
            float z = mix(s.za, s.zb, near.x);
            uint lp = uint(y - origin.y) * SOFT_TILE + uint(x - origin.x);
#ifdef OPACITY_PASS
            float cov = pixel_coverage(frame_ab, s.half_width, vec2(x, y));
            if (cov <= 0.0) {
                continue;
            }
            float dz = max(z - s_hair_depth[lp], 0.0) * frame.shadow.depth_range;
            uint layer = uint(min(int(dz / frame.shadow.layer_thickness), 3));
            float o = cluster_opacity(frame.shadow.strand_opacity * cov * share, s.thickness);
            atomicAdd(s_layers[lp * 4u + layer], uint(round(o * SHADOW_OPACITY_FIXED)));
#else
            if (near.y <= h * h) {
                atomicMin(s_depth[lp], floatBitsToUint(z));
            }
#endif
        }
    }
}

void main() {
    uint cols = tiles_per_row();
    uint tile = gl_WorkGroupID.y * cols + gl_WorkGroupID.x;
    uvec4 info = soft_tiles[tile];
    uint lp = gl_LocalInvocationIndex;
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * int(SOFT_TILE);
    ivec2 extent = min(ivec2(SOFT_TILE), size - origin);
    ivec2 texel = origin + ivec2(gl_LocalInvocationID.xy);
    bool inside = all(lessThan(texel, size));
    uint p = uint(texel.y) * uint(size.x) + uint(texel.x);
    // A tile no segment reaches (most of the map): its texels' results are known, so they are
    // written without the shared setup and its barriers (the branch is uniform: one tile per
    // workgroup).
    if (info.w == 0u) {
        if (inside) {
#ifdef OPACITY_PASS
            soft_shadow_layers[p] = uvec2(0u);
#else
            soft_shadow_depth[p] = floatBitsToUint(1.0);
#endif
        }
        return;
    }
#ifdef OPACITY_PASS
    for (uint i = 0u; i < 4u; i++) {
        s_layers[lp * 4u + i] = 0u;
    }
    s_hair_depth[lp] = inside ? soft_shadow_depth[p] : 1.0;
#else
    s_depth[lp] = floatBitsToUint(1.0);
#endif
    barrier();
    for (uint e = lp; e < info.w; e += TILE_TEXELS) {
        Segment s = load_segment(soft_entries[info.y + e]);
#ifdef OPACITY_PASS
        draw_segment(s, origin, extent, s.half_width);
#else
        draw_segment(s, origin, extent, max(s.half_width, 0.5));
#endif
    }
    barrier();
    if (!inside) {
        return;
    }
#ifdef OPACITY_PASS
    vec4 layers = vec4(s_layers[lp * 4u], s_layers[lp * 4u + 1u], s_layers[lp * 4u + 2u], s_layers[lp * 4u + 3u]) / SHADOW_OPACITY_FIXED;
    soft_shadow_layers[p] = uvec2(packHalf2x16(layers.xy), packHalf2x16(layers.zw));
#else
    soft_shadow_depth[p] = s_depth[lp];
#endif
}
