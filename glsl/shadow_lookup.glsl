// Light transmittance at a world point from the light's maps (src/render/shadow.rs):
// opaque props by depth comparison, hair by deep opacity layers (mode 1, Yuksel and Keyser
// 2008) or by the approximate deep shadow estimate (mode 2, seed 002: strands in front
// counted from the depth difference). 3x3 percentage-closer filtering over texels.
// Requires bindings.glsl. Used by strands.frag and props.frag.
#ifndef SHADOW_LOOKUP_GLSL
#define SHADOW_LOOKUP_GLSL

layout(set = SET_FRAME, binding = BINDING_SHADOW_HAIR_DEPTH) uniform sampler2D shadow_hair_depth;
layout(set = SET_FRAME, binding = BINDING_SHADOW_PROP_DEPTH) uniform sampler2D shadow_prop_depth;
layout(set = SET_FRAME, binding = BINDING_SHADOW_LAYERS) uniform sampler2D shadow_layers;

// Hair opacity (sum of strand opacities) between the first hair and depth dz behind it,
// interpolated within the layer dz falls in (the cumulative layer sums of the DOM paper).
float deep_opacity(vec4 layers, float dz) {
    float x = dz / frame.shadow_params.x;
    return layers.x * clamp(x, 0.0, 1.0) + layers.y * clamp(x - 1.0, 0.0, 1.0)
        + layers.z * clamp(x - 2.0, 0.0, 1.0) + layers.w * clamp(x - 3.0, 0.0, 1.0);
}

// How the light reaches `p` (shade::scattering::LightArrival): x the fraction arriving
// without crossing hair (1: fully lit), y the fraction not behind a body, z the expected
// strand hits on the way where not behind a body (dual scattering's strand count). `offset`
// moves the lookup point toward the light (world units) against self-shadowing of opaque
// surfaces.
vec3 light_arrival(vec3 p, float offset) {
    uint mode = frame.shadow.x;
    if (mode == SHADOW_OFF) {
        return vec3(1.0, 1.0, 0.0);
    }
    vec4 c = frame.light_view_proj * vec4(p, 1.0);
    vec2 uv = c.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || c.z < 0.0 || c.z > 1.0) {
        return vec3(1.0, 1.0, 0.0);
    }
    int res = int(frame.shadow.y);
    ivec2 centre = ivec2(uv * float(res));
    float range = frame.shadow_params.y;
    float alpha = frame.shadow_params.z;
    float bias = frame.shadow_params.w;
    float z = c.z * range - offset;
    // Per-strand transmittance 1 - alpha written as exp(-k alpha): opacity sums then give the
    // product of strand transmittances, and k * opacity is the expected hits.
    float k = -log(1.0 - alpha) / alpha;
    float sum = 0.0;
    float open = 0.0;
    float hits = 0.0;
    for (int dy = -1; dy <= 1; dy++) {
        for (int dx = -1; dx <= 1; dx++) {
            ivec2 t = clamp(centre + ivec2(dx, dy), ivec2(0), ivec2(res - 1));
            float prop = texelFetch(shadow_prop_depth, t, 0).r * range;
            if (z - bias > prop) {
                continue;  // behind a head or body
            }
            float dz = max(z - texelFetch(shadow_hair_depth, t, 0).r * range, 0.0);
            float opacity;
            if (mode == SHADOW_DEEP_OPACITY) {
                opacity = deep_opacity(texelFetch(shadow_layers, t, 0), dz);
            } else {
                // One strand per layer thickness in front of the point (calibrated against
                // deep opacity maps on the sample heads, tests/shadows.rs).
                opacity = alpha * (dz / frame.shadow_params.x);
            }
            sum += exp(-k * opacity);
            open += 1.0;
            hits += k * opacity;
        }
    }
    return vec3(sum / 9.0, open / 9.0, hits / max(open, 1.0));
}

// Transmittance of the light to `p` (light_arrival's direct fraction).
float light_transmittance(vec3 p, float offset) {
    return light_arrival(p, offset).x;
}

#endif
