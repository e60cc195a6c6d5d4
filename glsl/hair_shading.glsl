// Hair shading models: the GPU twin of src/shade/mod.rs (same formulas and constants).
// Kajiya-Kay (Kajiya and Kay 1989) and Marschner R / TT / TRT (Marschner et al. 2003, seed 000
// eq. 1) with the azimuthal fits of Karis 2016. All directions point away from the fibre.
#ifndef HAIR_SHADING_GLSL
#define HAIR_SHADING_GLSL
#include "shared.glsl"

// The colour-independent TT / TRT azimuthal factors, tabulated at start-up (src/shade/lut.rs;
// seed 001's precomputation idea). Includers other than the hair passes (the test probe) name
// its set and binding first.
#ifndef SHADING_LUT_SET
#define SHADING_LUT_SET SET_FRAME
#define SHADING_LUT_BINDING BINDING_SHADING_LUT
#endif
layout(set = SHADING_LUT_SET, binding = SHADING_LUT_BINDING) uniform sampler2D marschner_lut;

// HAIR_ETA, KAJIYA_KAY_EXPONENT and MARSCHNER_ENERGY_SCALE come from shared.glsl (their
// Rust twins in src/shade/mod.rs).

// (diffuse, specular) of Kajiya-Kay.
vec2 kajiya_kay(vec3 t, vec3 l, vec3 v) {
    float tl = clamp(dot(t, l), -1.0, 1.0);
    float tv = clamp(dot(t, v), -1.0, 1.0);
    float sin_tl = sqrt(max(1.0 - tl * tl, 0.0));
    float sin_tv = sqrt(max(1.0 - tv * tv, 0.0));
    return vec2(sin_tl, pow(max(sin_tl * sin_tv - tl * tv, 0.0), KAJIYA_KAY_EXPONENT));
}

float hair_fresnel(float eta, float cos_theta) {
    float f0 = (1.0 - eta) / (1.0 + eta);
    f0 *= f0;
    return f0 + (1.0 - f0) * pow(1.0 - clamp(cos_theta, 0.0, 1.0), 5.0);
}

float hair_gaussian(float beta, float x) {
    return exp(-x * x / (2.0 * beta * beta)) / (2.50662827463 * beta);
}

// S(omega_i, omega_o) per channel; radiance = S * E * cos(theta_i).
vec3 marschner(vec3 t, vec3 l, vec3 v, vec3 color, float roughness, float tilt) {
    float sin_i = clamp(dot(t, l), -1.0, 1.0);
    float sin_o = clamp(dot(t, v), -1.0, 1.0);
    float theta_i = asin(sin_i);
    float theta_o = asin(sin_o);
    float theta_h = 0.5 * (theta_i + theta_o);
    float cos_d = max(cos(0.5 * (theta_o - theta_i)), 1e-3);
    vec3 lp = l - t * sin_i;
    vec3 vp = v - t * sin_o;
    float cos_phi = clamp(dot(lp, vp) / sqrt(dot(lp, lp) * dot(vp, vp) + 1e-8), -1.0, 1.0);
    float cos_half_phi = sqrt(0.5 + 0.5 * cos_phi);
    float a = tilt;
    float b = roughness;
    float m_r = 0.5 * hair_gaussian(b, theta_h + a);
    float m_tt = 0.5 * hair_gaussian(0.5 * b, theta_h - 0.5 * a);
    float m_trt = 0.5 * hair_gaussian(2.0 * b, theta_h - 1.5 * a);
    float n_r = 0.25 * cos_half_phi * hair_fresnel(HAIR_ETA, sqrt(max(0.5 + 0.5 * dot(l, v), 0.0)));
    // Texel centres sit at cos(phi) = -1 + 2 i / (PHI - 1), cos(theta_d) = j / (D - 1).
    vec2 size = vec2(MARSCHNER_LUT_PHI, MARSCHNER_LUT_D);
    vec2 uv = (vec2(0.5 + 0.5 * cos_phi, cos_d) * (size - 1.0) + 0.5) / size;
    vec3 az = textureLod(marschner_lut, uv, 0.0).rgb;
    vec3 base = max(color, vec3(1e-4));
    vec3 n_tt = pow(base, vec3(az.r / (2.0 * cos_d))) * az.g;
    vec3 n_trt = pow(base, vec3(0.8 / cos_d)) * (az.b / MARSCHNER_LUT_TRT_SCALE);
    return (vec3(m_r * n_r) + n_tt * m_tt + n_trt * m_trt) * (MARSCHNER_ENERGY_SCALE / (cos_d * cos_d));
}

#endif
