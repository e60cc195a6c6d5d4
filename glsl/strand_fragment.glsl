// Inputs of every strand fragment shader (from strands.vert and strands.mesh) and the strand
// radiance they share: the opaque pass (strands.frag), k-buffer OIT (oit.frag) and depth
// peeling (peel_color.frag) shade with the same code, chosen per frame by frame.shading.x
// (src/shade/mod.rs ShadingModel): 0 placeholder (Kajiya-Kay diffuse with a half-vector
// highlight and darker roots), 1 Kajiya-Kay diffuse + specular, 2 Marschner R / TT / TRT.
#ifndef STRAND_FRAGMENT_GLSL
#define STRAND_FRAGMENT_GLSL
#include "hair_shading.glsl"
#include "shadow_lookup.glsl"
#include "lod_appearance.glsl"

layout(location = 0) in vec3 in_tangent;
layout(location = 1) in float in_s;
layout(location = 2) in vec3 in_pos;
layout(location = 3) flat in vec3 in_color;
layout(location = 4) flat in uint in_character;
// Fraction of the drawn (at least one pixel wide) strip the strand covers (strip.glsl).
layout(location = 5) in float in_coverage;
// Strands this strip stands for under strand LoD (sec. 3.6.1 width factor; 1 at full detail).
layout(location = 6) flat in float in_thickness;

// Irradiance of the directional light, and an ambient term that stands in for multiple
// scattering (dual scattering is not implemented) in the physically based models.
#define LIGHT_IRRADIANCE 4.5
#define AMBIENT 0.25

// Radiance toward the eye of this fragment's strand.
vec3 shade_strand() {
    vec3 t = normalize(in_tangent);
    vec3 l = normalize(frame.light_dir.xyz);
    vec3 e = normalize(frame.camera_pos.xyz - in_pos);
    vec3 base = in_color;
    // Direct light reaching this fragment through the hair and bodies in front of it.
    float lit = light_transmittance(in_pos, 0.0);
    float root_shadow = mix(0.55, 1.0, smoothstep(0.0, 0.3, in_s));
    vec3 c;
    if (frame.shading.x == 1u) {
        vec2 kk = kajiya_kay(t, l, e);
        c = (base * (AMBIENT + kk.x * lit) + vec3(0.3) * (kk.y * lit)) * root_shadow;
    } else if (frame.shading.x == 2u) {
        HairStyle s = characters[in_character].style;
        vec3 sc = marschner(t, l, e, base, s.roughness, radians(s.cuticle_tilt_degrees));
        float cos_i = sqrt(max(1.0 - dot(t, l) * dot(t, l), 0.0));
        c = (sc * (LIGHT_IRRADIANCE * cos_i * lit) + base * AMBIENT) * root_shadow;
    } else {
        float tl = dot(t, l);
        float diffuse = sqrt(max(1.0 - tl * tl, 0.0));
        vec3 h = normalize(l + e);
        float th = dot(t, h);
        float spec = pow(sqrt(max(1.0 - th * th, 0.0)), 80.0);
        c = base * (0.25 + 0.75 * diffuse * lit) * root_shadow + vec3(0.25) * (spec * lit) * root_shadow;
    }
    return c;
}

// Opacity of this fragment over its pixel: one strand's opacity times the fraction of the
// pixel it covers (coverage to alpha, seed 002), aggregated under LoD (lod_appearance.glsl).
float strand_alpha() {
    return cluster_opacity(STRAND_OPACITY * clamp(in_coverage, 0.0, 1.0), in_thickness);
}

#endif
