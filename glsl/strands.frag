#version 460
// Strand shading, chosen per frame (frame.shading.x, src/shade/mod.rs ShadingModel):
// 0 placeholder (Kajiya-Kay diffuse with a half-vector highlight and darker roots),
// 1 Kajiya-Kay diffuse + specular, 2 Marschner R / TT / TRT (hair_shading.glsl).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "hair_shading.glsl"
#include "shadow_lookup.glsl"

layout(location = 0) in vec3 in_tangent;
layout(location = 1) in float in_s;
layout(location = 2) in vec3 in_pos;
layout(location = 3) flat in vec3 in_color;
layout(location = 4) flat in uint in_character;
layout(location = 0) out vec4 out_color;

// Irradiance of the directional light, and an ambient term that stands in for multiple
// scattering (dual scattering is not implemented) in the physically based models.
#define LIGHT_IRRADIANCE 4.5
#define AMBIENT 0.25

void main() {
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
    out_color = vec4(c, 1.0);
}
