#version 460
// Props (bodies, ground): simple physically based shading, a Lambert diffuse lobe plus a GGX
// specular lobe (Walter et al. 2007) with Schlick Fresnel (F0 = 0.04, dielectric skin and
// ground) and Smith-Schlick visibility, under the directional light, plus the sky and ground
// (hemisphere_ambient). PROP_* come from shared.glsl (src/shade/mod.rs).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "shadow_lookup.glsl"
#include "hair_shading.glsl"
#include "temporal.glsl"

// Depth is tested before shading (nothing here writes depth or discards), so hidden fragments
// are not shaded: the visibility note would make the test late otherwise.
layout(early_fragment_tests) in;
layout(location = 0) in vec3 in_normal;
layout(location = 1) flat in vec3 in_color;
layout(location = 2) in vec3 in_pos;
layout(location = 3) flat in uint in_instance;
layout(location = 4) flat in float in_roughness;
layout(location = 0) out vec4 out_color;

void main() {
    note_fragment(VISIBILITY_PROP | in_instance, vec2(0.0));
    vec3 n = normalize(in_normal);
    vec3 l = normalize(frame.to_light);
    vec3 v = normalize(frame.eye - in_pos);
    vec3 h = normalize(l + v);
    float nl = max(dot(n, l), 0.0);
    float nv = max(dot(n, v), 1e-4);
    float nh = max(dot(n, h), 0.0);
    float a = in_roughness * in_roughness;
    float d = a * a / (3.14159265 * pow(nh * nh * (a * a - 1.0) + 1.0, 2.0));
    float k = a * 0.5;
    float vis = 0.25 / ((nl * (1.0 - k) + k) * (nv * (1.0 - k) + k));
    float f = 0.04 + 0.96 * pow(1.0 - max(dot(h, v), 0.0), 5.0);
    vec3 brdf = in_color / 3.14159265 + vec3(d * vis * f);
    float lit = nl > 0.0 ? light_arrival_surface(in_pos, n).x : 0.0;
    out_color = vec4(brdf * (PROP_IRRADIANCE * nl * lit) + in_color * hemisphere_ambient(n.y) * (PROP_AMBIENT / AMBIENT), 1.0);
}
