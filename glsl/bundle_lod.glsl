// Per-bundle decisions shared by the compute path (cull.comp) and the task shader:
// frustum culling and strand / vertex level of detail (paper 003 sec. 3.6, eq. 7-12).
// CPU twin: src/reference/lod.rs (bundle_lod). Requires bindings.glsl, common.glsl,
// strand_eval.glsl.
#ifndef BUNDLE_LOD_GLSL
#define BUNDLE_LOD_GLSL

struct BundleLod {
    uint strands;     // eq. 8 (0 when culled)
    uint e;           // eq. 9: 2^e segments
    float gamma;      // eq. 12 geomorph factor toward level e - 1 (0: none)
    float thickness;  // sec. 3.6.1 width factor min(1/L, N)
    bool soft;        // drawn by the software rasterizer (src/render/soft.rs)
    float fade;       // width share of the newest strand (newest_strand_fade)
};

// bundle_lods[] / payload encoding of a decision.
uvec4 encode_lod(BundleLod r) {
    uint fade = uint(round(clamp(r.fade, 0.0, 1.0) * 65535.0)) << 16;
    return uvec4(r.strands, r.e | (r.soft ? LOD_SOFT : 0u) | fade, floatBitsToUint(r.gamma), floatBitsToUint(r.thickness));
}

// Software or hardware raster (frame.soft.mode: RASTER_HARDWARE, RASTER_SOFTWARE, RASTER_AUTO, or
// RASTER_LIGHT: the light's software shadow passes, every bundle). Auto: software
// when the bundle's strands are drawn at most frame.soft.auto_split_pixels pixels wide at its nearest
// point `d` (the LoD-thickened width, or the cluster footprint of lod_appearance.glsl).
bool soft_raster(float d, float width, float thickness, float cap) {
    if (frame.soft.mode != RASTER_AUTO) {
        return frame.soft.mode != RASTER_HARDWARE;
    }
    float pixel = frame.cot_half_fov > 0.0 ? 2.0 * max(d, 1e-6) / (frame.pixels_high * frame.cot_half_fov)
                                          : frame.lod.ortho_height / frame.pixels_high;
    float drawn = width * thickness;
    if (frame.shading.lod_appearance != 0u && thickness > 1.0) {
        drawn = max(drawn, min(sqrt(thickness) * min(pixel, width), cap));
    }
    return drawn <= frame.soft.auto_split_pixels * pixel;
}

// Eq. 8's strand count for `wanted` strands (its level times N + delta), clamped to
// 1..=count (0 when nothing is wanted). Stable LoD: the newest strand comes in as wide as the
// fractional part, so a bundle's strands fade in one by one as it nears instead of popping
// (CPU twin: strands_at_level and newest_strand_fade in src/reference/lod.rs).
void set_strands(inout BundleLod r, float wanted, uint count) {
    r.strands = wanted > 0.0 ? clamp(uint(ceil(wanted)), 1u, count) : 0u;
    r.fade = r.strands > 1u && wanted < float(r.strands) ? wanted - float(r.strands - 1u) : 1.0;
}

bool box_visible(vec3 lo, vec3 hi) {
    for (int p = 0; p < 6; p++) {
        vec4 pl = frame.planes[p];
        vec3 c = vec3(pl.x >= 0.0 ? hi.x : lo.x, pl.y >= 0.0 ? hi.y : lo.y, pl.z >= 0.0 ? hi.z : lo.z);
        if (dot(pl.xyz, c) + pl.w < 0.0) {
            return false;
        }
    }
    return true;
}

// Eq. 7's d tan theta at distance d (orthographic, frame.lod.tan_fov == 0: the view height).
float eq7_denominator(float d) {
    return frame.lod.tan_fov > 0.0 ? max(d, 1e-6) * frame.lod.tan_fov : max(frame.lod.ortho_height, 1e-6);
}

// Eq. 7's measure h R / (d tan theta) before alpha and the clamp.
float detail_level_unclamped(float h, float d) {
    return h * frame.pixels_high / eq7_denominator(d);
}

// Eq. 7 (perspective, or orthographic when frame.lod.tan_fov == 0).
float detail_level(float h, float d, float alpha) {
    return clamp(h * frame.pixels_high * alpha / eq7_denominator(d), 0.0, 1.0);
}

// Eq. 7's strand level times the crowd's area term (frame.lod.area_below: 0 off): below that
// extent (h R / (d tan theta), about pixels) a bundle's strands fall with its area, and eq. 8's
// thickness widens the rest; then the pixel cap (frame.lod.strands_per_pixel strands per square pixel of
// the extent, 0 off) for a bundle of `count` strands: at crowd distance a bundle draws as many
// strands as the pixels it covers need, whatever its count at full detail (seed 000's thick
// strands in place of a cluster). CPU twin: reference::lod::{bundle_extent, area_factor,
// pixel_cap_level}.
float strand_level(float h, float d, uint count) {
    float level = detail_level(h, d, frame.lod.alpha_strands);
    float extent = detail_level_unclamped(h, d);
    float below = frame.lod.area_below;
    if (below > 0.0) {
        level *= clamp(extent / below, 0.0, 1.0);
    }
    float per_pixel = frame.lod.strands_per_pixel;
    if (per_pixel > 0.0) {
        level = min(level, per_pixel * extent * extent / float(count));
    }
    return level;
}

// Strands of a bundle at full detail, N_i of eq. 8: the character's count per average
// bundle, weighted by the bundle's root area where the style asks (its character bound).
// CPU twin: reference::generate::strands_in_bundle.
uint bundle_strand_count(GpuBundle desc) {
    uint n = ch_strands;
    uint count = style.density_by_area != 0u ? uint(round(float(n) * desc.density)) : n;
    return clamp(count, 1u, MAX_STRANDS_PER_BUNDLE);
}

// The share of its strands every bundle of a kind keeps when the view's LoD asks for
// `demand` items (units of LOD_DEMAND_UNIT, summed by cull.comp) of a buffer of `budget`:
// 1 when they fit, else (budget - slack) / demand, at least LOD_LEAST_PRESSURE (every visible
// bundle keeps a strand). CPU twin: reference::lod::lod_pressure.
float lod_pressure(uint demand, uint slack, uint budget) {
    float d = float(demand) * float(LOD_DEMAND_UNIT);
    if (d <= float(budget)) {
        return 1.0;
    }
    float p = (float(budget) - float(slack) * float(LOD_DEMAND_UNIT)) / d;
    return clamp(p, LOD_LEAST_PRESSURE, 1.0);
}

// Eq. 8's width factor min(1/L, N) for `strands` strands at level `level` of a bundle of
// `count`, held to the bundle's cross-section: each of k strands at most `size_over_width /
// sqrt(k)` strand widths (h / sqrt(k) across), so k thick strands cover the bundle once and no
// more (a cluster's footprint, seed 000). The cap only binds where the strands left would
// cover the bundle more than sqrt(k) times over, opaque either way. CPU twin:
// reference::lod::thickness_at.
float eq8_thickness(float level, uint count, uint strands, float size_over_width) {
    float t = min(1.0 / max(level, 1e-6), float(count));
    return max(min(t, size_over_width / sqrt(float(max(strands, 1u)))), 1.0);
}

// A bundle's size over its strands' width (both in object units): the cross-section cap's
// measure (its character bound).
float bundle_size_over_width(GpuBundle desc) {
    return desc.rest_size / max(style.strand_width, 1e-12);
}

// Culling and LoD of crowd bundle g (its character bound with bind_character), with eq. 7's
// strand level times `pressure` (1, or lod_pressure's share where the view's buffers would
// run full: the strands fall, eq. 8's thickness keeps the coverage).
BundleLod bundle_lod(uint g, float pressure) {
    // Hidden characters, and hair drawn as its density volume alone (the volume tier's far
    // characters), have no strands in any view: skip the texture reads.
    if (!ch_visible || ch_volume_only) {
        return BundleLod(0u, ch_emax, 0.0, 1.0, false, 1.0);
    }
    GpuBundle desc = bundles[g];
    // World bounds: convex hull of the bundle's Bezier control points, grown by the styling.
    int depth = int(POSITION_DEPTH(mesh.layers));
    vec3 lo = vec3(1e30);
    vec3 hi = vec3(-1e30);
    for (int z = 0; z < depth; z++) {
        for (int c = 0; c < 4; c++) {
            ivec3 t = ivec3(ivec2(desc.origin) + ivec2(c & 1, c >> 1), z);
            vec3 p = (model * vec4(decode_position(texelFetch(TEX_POSITION, t, 0).xyz), 1.0)).xyz;
            lo = min(lo, p);
            hi = max(hi, p);
        }
    }
    float scale = model_scale;
    float margin = scale * (style.curl_radius + style.wave_amplitude + style.frizz_amplitude + style.strand_width);
    lo -= margin;
    hi += margin;
    uint count = bundle_strand_count(desc);
    uint emax = ch_emax;
    BundleLod r = BundleLod(count, emax, 0.0, 1.0, false, 1.0);
    // Curved roots leave the hull by at most the root cell's bulge bound; the LoD distance
    // below stays that of the hull (src/reference/root_surface.rs).
    float bulge = scale * root_bulge_bound(root_cell(desc.origin));
    if (!box_visible(lo - bulge, hi + bulge)) {
        r.strands = 0u;
        return r;
    }
    vec3 eye = frame.eye;
    float d = length(eye - clamp(eye, lo, hi));
    float h = scale * desc.rest_size;
    float delta = hash_f32(hash_u32(desc.local_index ^ 0x2545f491u) ^ style.seed);
    float size_over_width = bundle_size_over_width(desc);
    if (frame.counts.lod_on == 0u) {
        r.soft = soft_raster(d, scale * style.strand_width, 1.0, h);
        if (ch_strand_share < 1.0 || pressure < 1.0) {
            set_strands(r, ch_strand_share * pressure * (float(count) + delta), count);
        }
        if (pressure < 1.0) {
            r.thickness = eq8_thickness(pressure, count, r.strands, size_over_width);
        }
        return r;
    }
    // Strand LoD: eq. 7 and eq. 8 with a per-bundle increment delta_i, clamped to N_i. In the
    // volume tier's band the level drops by the strands' share, the thickness does not: the
    // strands thin out one by one (each fading as set_strands says) while the volume comes in under
    // them, a blend with no screen-door pattern (CPU twin: LodView::strand_share).
    float ls = strand_level(h, d, count) * pressure;
    set_strands(r, ls * ch_strand_share * (float(count) + delta), count);
    r.thickness = eq8_thickness(ls, count, r.strands, size_over_width);
    // Vertex LoD: eq. 9, 10, 12.
    float lv = detail_level(h, d, frame.lod.alpha_verts);
    float x = log2(max(lv * float(1u << emax), 1e-30));
    r.e = uint(clamp(ceil(x), 0.0, float(emax)));
    float lambda = clamp(frame.lod.lambda, 1e-6, 1.0);
    float e_next = max(ceil(x - lambda), 0.0);
    if (float(r.e) > e_next && r.e > 0u) {
        r.gamma = clamp(1.0 - (x - e_next) / lambda, 0.0, 1.0);
    }
    r.soft = soft_raster(d, scale * style.strand_width, r.thickness, h);
    return r;
}

#endif
