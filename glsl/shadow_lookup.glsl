// Light transmittance at a world point from the light's maps (src/render/shadow.rs):
// opaque props (bodies) by filtered depth comparison in their own camera-fitted map, hair by
// deep opacity layers (mode 1, Yuksel and Keyser 2008) or by the approximate deep shadow
// estimate (mode 2, seed 002: strands in front counted from the depth difference), 3x3 texels
// averaged.
// Requires bindings.glsl. Used by strands.frag and props.frag.
#ifndef SHADOW_LOOKUP_GLSL
#define SHADOW_LOOKUP_GLSL

layout(set = SET_FRAME, binding = BINDING_SHADOW_HAIR_DEPTH) uniform sampler2D shadow_hair_depth;
layout(set = SET_FRAME, binding = BINDING_SHADOW_PROP_DEPTH) uniform sampler2D shadow_prop_depth;
layout(set = SET_FRAME, binding = BINDING_SHADOW_LAYERS) uniform sampler2D shadow_layers;

// Hair opacity (sum of strand opacities) between the first hair and depth dz behind it,
// interpolated within the layer dz falls in (the cumulative layer sums of the DOM paper).
float deep_opacity(vec4 layers, float dz) {
    float x = dz / frame.shadow.layer_thickness;
    return layers.x * clamp(x, 0.0, 1.0) + layers.y * clamp(x - 1.0, 0.0, 1.0)
        + layers.z * clamp(x - 2.0, 0.0, 1.0) + layers.w * clamp(x - 3.0, 0.0, 1.0);
}

// Weight of tap `i` (-1..=2) of a 3x3-texel box sliding with fraction `f` of the point's
// texel: (1 - f, 1, 1, f), summing to 3 (CPU twin: render::shadow::box_pcf_weights).
float box_weight(int i, float f) {
    return i == -1 ? 1.0 - f : (i == 2 ? f : 1.0);
}

// The fraction of the light not blocked by bodies at world point `p`, from the bodies' map
// (render::shadow::LightView::fit_bodies). Percentage-closer filtering over a 3x3-texel box
// that slides with the point: 4x4 depth comparisons weighted (1 - f, 1, 1, f) per axis by the
// point's position within its texel, so an edge is a smooth ramp three texels wide and not a
// staircase of texels (the CPU twin is render::shadow::box_pcf_weights). Texels off the map
// count as lit. Unfiltered (strands: a strand is thinner than a texel, and its many fragments
// or vertices average the edge anyway), one comparison at the nearest texel.
float body_visibility(vec3 p, bool filtered) {
    float res = frame.body_shadow.resolution;
    if (res <= 0.0) {
        return 1.0;
    }
    vec4 c = frame.body_view_proj * vec4(p, 1.0);
    if (c.z < 0.0 || c.z > 1.0) {
        return 1.0;
    }
    vec2 st = (c.xy * 0.5 + 0.5) * res - 0.5;
    vec2 base = floor(st);
    vec2 f = st - base;
    float z = c.z * frame.body_shadow.depth_range - frame.body_shadow.bias;
    int side = int(res);
    if (!filtered) {
        ivec2 t = ivec2(floor(st + 0.5));
        bool off = any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, ivec2(side)));
        return off || z <= texelFetch(shadow_prop_depth, t, 0).r * frame.body_shadow.depth_range ? 1.0 : 0.0;
    }
    float lit = 0.0;
    for (int j = -1; j <= 2; j++) {
        float wy = box_weight(j, f.y);
        for (int i = -1; i <= 2; i++) {
            float wx = box_weight(i, f.x);
            ivec2 t = ivec2(base) + ivec2(i, j);
            bool open = any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, ivec2(side)))
                || z <= texelFetch(shadow_prop_depth, t, 0).r * frame.body_shadow.depth_range;
            lit += open ? wx * wy : 0.0;
        }
    }
    return lit / 9.0;
}

// How the light reaches `p` (shade::scattering::LightArrival): x the fraction arriving
// without crossing hair or a body (1: fully lit), y the fraction not behind a body, z the
// expected strand hits on the way (dual scattering's strand count). `offset` moves the hair
// maps' lookup toward the light (world units); `body` is body_visibility at the point.
// `slide`: the hair maps' 3x3 texels slide with the point as in body_visibility (opaque
// surfaces, where a hair shadow's edge would show the texels); else the 3x3 texels around
// the nearest (strands: 9 taps, not 16).
vec3 light_arrival_with(vec3 p, float offset, float body, bool slide) {
    uint mode = frame.shadow.mode;
    if (mode == SHADOW_OFF) {
        return vec3(1.0, 1.0, 0.0);
    }
    vec4 c = frame.light_view_proj * vec4(p, 1.0);
    vec2 uv = c.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || c.z < 0.0 || c.z > 1.0) {
        return vec3(body, body, 0.0);
    }
    // Wholly behind bodies: no light arrives, directly or scattered through hair (x and y are
    // 0, and dual scattering's every term carries one of them), so the hair taps are skipped.
    if (body <= 0.0) {
        return vec3(0.0);
    }
    int res = int(frame.shadow.resolution);
    vec2 st = uv * float(res) - (slide ? 0.5 : 0.0);
    ivec2 base = ivec2(floor(st));
    vec2 f = slide ? st - floor(st) : vec2(0.5);
    int last = slide ? 2 : 1;
    float range = frame.shadow.depth_range;
    float alpha = frame.shadow.strand_opacity;
    float z = c.z * range - offset;
    // Per-strand transmittance 1 - alpha written as exp(-k alpha): opacity sums then give the
    // product of strand transmittances, and k * opacity is the expected hits.
    float k = -log(1.0 - alpha) / alpha;
    float sum = 0.0;
    float hits = 0.0;
    for (int dy = -1; dy <= last; dy++) {
        for (int dx = -1; dx <= last; dx++) {
            float w = slide ? box_weight(dx, f.x) * box_weight(dy, f.y) : 1.0;
            ivec2 t = clamp(base + ivec2(dx, dy), ivec2(0), ivec2(res - 1));
            float dz = max(z - texelFetch(shadow_hair_depth, t, 0).r * range, 0.0);
            // No hair in front of the point: opacity 0 in both modes, so the layers and the
            // exponential are skipped (most texels of a frame; the result is the same).
            if (dz <= 0.0) {
                sum += w;
                continue;
            }
            float opacity;
            if (mode == SHADOW_DEEP_OPACITY) {
                opacity = deep_opacity(texelFetch(shadow_layers, t, 0), dz);
            } else {
                // One strand per layer thickness in front of the point (calibrated against
                // deep opacity maps on the sample heads, tests/shadows.rs).
                opacity = alpha * (dz / frame.shadow.layer_thickness);
            }
            sum += w * exp(-k * opacity);
            hits += w * k * opacity;
        }
    }
    return vec3(body * sum / 9.0, body, hits / 9.0);
}

// light_arrival_with at a strand point (no surface to lift off).
vec3 light_arrival(vec3 p, float offset) {
    return light_arrival_with(p, offset, body_visibility(p, false), false);
}

// How the light reaches a point `p` of an opaque surface with unit normal `n`: the bodies'
// map is read a texel and a half off the surface along the normal (normal offset, against
// acne on slopes without the light leaking under contacts), the hair maps two biases toward
// the light.
vec3 light_arrival_surface(vec3 p, vec3 n) {
    float body = body_visibility(p + n * (1.5 * frame.body_shadow.texel), true);
    return light_arrival_with(p, 2.0 * frame.shadow.bias, body, true);
}


#endif
