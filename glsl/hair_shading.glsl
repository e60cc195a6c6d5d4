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

// The ambient light at a surface whose normal has world-up component `up`: sky above,
// ground below (shade::hemisphere_ambient).
vec3 hemisphere_ambient(float up) {
    return AMBIENT * mix(GROUND_TINT, SKY_TINT, 0.5 + 0.5 * clamp(up, -1.0, 1.0));
}

float hair_fresnel(float eta, float cos_theta) {
    float f0 = (1.0 - eta) / (1.0 + eta);
    f0 *= f0;
    return f0 + (1.0 - f0) * pow(1.0 - clamp(cos_theta, 0.0, 1.0), 5.0);
}

float hair_gaussian(float beta, float x) {
    return exp(-x * x / (2.0 * beta * beta)) / (2.50662827463 * beta);
}

// theta_h, cos(theta_d), cos(phi), cos(theta_i) (shade::hair_angles).
vec4 hair_angles(vec3 t, vec3 l, vec3 v) {
    float sin_i = clamp(dot(t, l), -1.0, 1.0);
    float sin_o = clamp(dot(t, v), -1.0, 1.0);
    float theta_i = asin(sin_i);
    float theta_o = asin(sin_o);
    vec3 lp = l - t * sin_i;
    vec3 vp = v - t * sin_o;
    float cos_phi = clamp(dot(lp, vp) / sqrt(dot(lp, lp) * dot(vp, vp) + 1e-8), -1.0, 1.0);
    return vec4(0.5 * (theta_i + theta_o), max(cos(0.5 * (theta_o - theta_i)), 1e-3), cos_phi,
                sqrt(max(1.0 - sin_i * sin_i, 0.0)));
}

// S(omega_i, omega_o) per channel at the angles `ang` (hair_angles) with `lv` = dot(l, v);
// radiance = S * E * cos(theta_i).
vec3 marschner_at(vec4 ang, float lv, vec3 color, float roughness, float tilt) {
    float theta_h = ang.x;
    float cos_d = ang.y;
    float cos_phi = ang.z;
    float cos_half_phi = sqrt(0.5 + 0.5 * cos_phi);
    float a = tilt;
    float b = roughness;
    float m_r = 0.5 * hair_gaussian(b, theta_h + a);
    float m_tt = 0.5 * hair_gaussian(0.5 * b, theta_h - 0.5 * a);
    float m_trt = 0.5 * hair_gaussian(2.0 * b, theta_h - 1.5 * a);
    float n_r = 0.25 * cos_half_phi * hair_fresnel(HAIR_ETA, sqrt(max(0.5 + 0.5 * lv, 0.0)));
    // Texel centres sit at cos(phi) = -1 + 2 i / (PHI - 1), cos(theta_d) = j / (D - 1), in
    // the first rows of the shading lookup texture.
    vec2 size = vec2(MARSCHNER_LUT_PHI, MARSCHNER_LUT_D);
    vec2 uv = (vec2(0.5 + 0.5 * cos_phi, cos_d) * (size - 1.0) + 0.5)
        / vec2(SHADING_LUT_WIDTH, SHADING_LUT_HEIGHT);
    vec3 az = textureLod(marschner_lut, uv, 0.0).rgb;
    vec3 base = max(color, vec3(1e-4));
    vec3 n_tt = pow(base, vec3(az.r / (2.0 * cos_d))) * az.g;
    vec3 n_trt = pow(base, vec3(0.8 / cos_d)) * (az.b / MARSCHNER_LUT_TRT_SCALE);
    return (vec3(m_r * n_r) + n_tt * m_tt + n_trt * m_trt) * (MARSCHNER_ENERGY_SCALE / (cos_d * cos_d));
}

// S(omega_i, omega_o) per channel for unit tangent t, to-light l and to-eye v.
vec3 marschner(vec3 t, vec3 l, vec3 v, vec3 color, float roughness, float tilt) {
    return marschner_at(hair_angles(t, l, v), dot(l, v), color, roughness, tilt);
}

// ---- Dual scattering (Zinke et al. 2008; seed 000 sec. 3.2, eqs. 3-4). CPU twin:
// src/shade/scattering.rs, where the derivation is written out.

// Energies of R, TT, TRT into the front (back = 0) or back (back = 1) half of azimuth for
// colour channel c (shade::scattering::lobe_energies, tabulated in src/shade/lut.rs).
vec3 lobe_energies(uint back, float cos_d, float c) {
    float x = sqrt(clamp(c, 0.0, 1.0)) * float(SHADING_LUT_WIDTH - 1u) + 0.5;
    float y = float(MARSCHNER_LUT_D + back * SCATTER_LUT_THETA)
        + clamp(cos_d, 0.0, 1.0) * float(SCATTER_LUT_THETA - 1u) + 0.5;
    return textureLod(marschner_lut, vec2(x, y) / vec2(SHADING_LUT_WIDTH, SHADING_LUT_HEIGHT), 0.0).rgb;
}

// Energy-weighted (total, mean shift, variance) of one half's lobes.
vec3 half_moments(vec3 e, vec3 shifts, vec3 widths) {
    float total = e.x + e.y + e.z;
    float w = 1.0 / max(total, 1e-6);
    return vec3(total, dot(e, shifts) * w, dot(e, widths * widths) * w);
}

// Local back-scattering A_1 + A_3 (Zinke) + A_1+ (seed 000 eq. 10, a cluster crossed `cluster`
// times) with its mean shift and variance (shade::scattering::back_scattering).
vec3 back_scattering(vec3 front, vec3 back, float cluster) {
    float af2 = front.x * front.x;
    float q = max(1.0 - af2, 1e-4);
    float a1 = back.x * af2 / q;
    float a3 = back.x * back.x * back.x * af2 / (q * q * q);
    float n = max(cluster, 1.0);
    float gap = GAP_DENSITY * back.x * front.x * (1.0 - pow(af2, n)) / q;
    float gap_forward = min((1.0 + af2) / q, 2.0 * n - 1.0);
    float w = 1.0 / max(a1 + a3 + gap, 1e-8);
    float shift = (a1 * (back.y + 2.0 * front.y) + a3 * (3.0 * back.y + 2.0 * front.y)
        + gap * (back.y + gap_forward * front.y)) * w;
    float var = (a1 * (back.z + 2.0 * front.z) + a3 * (3.0 * back.z + 2.0 * front.z)
        + gap * (back.z + gap_forward * front.z)) * w;
    float widen = 1.0 + BACKWARD_DENSITY * af2;
    return vec3(a1 + a3 + gap, shift, var * widen * widen);
}

// Radiance per unit light irradiance (shade::scattering::dual_scattering): single scattering
// of the direct light, plus with `multiple` Zinke's global and local multiple scattering per
// channel and seed 000's aggregated model for a strand standing for a cluster whose strands a
// ray crosses `cluster` times (1: one strand). arrival: x direct fraction, y fraction not
// behind bodies, z expected strand hits.
vec3 dual_scattering(vec3 t, vec3 l, vec3 v, vec3 color, float roughness, float tilt, vec3 arrival, bool multiple,
                     float cluster) {
    vec4 ang = hair_angles(t, l, v);
    vec3 single = marschner_at(ang, dot(l, v), color, roughness, tilt);
    if (!multiple) {
        return single * (ang.w * arrival.x);
    }
    vec3 shifts = vec3(-tilt, 0.5 * tilt, 1.5 * tilt);
    vec3 widths = vec3(roughness, 0.5 * roughness, 2.0 * roughness);
    float inv_cos2 = 1.0 / (ang.y * ang.y);
    float back_azimuth = (1.0 + ang.z) / 6.28318530718;
    vec3 result;
    for (int ch = 0; ch < 3; ch++) {
        vec3 ef = lobe_energies(0u, ang.y, color[ch]);
        vec3 eb = lobe_energies(1u, ang.y, color[ch]);
        vec3 front = half_moments(ef, shifts, widths);
        vec3 back = back_scattering(front, half_moments(eb, shifts, widths), cluster);
        // Eq. 8: light leaving through the cluster's far side crossed its other strands.
        float inherited = pow(max(front.x, 1e-6), (max(cluster, 1.0) - 1.0) * 0.5 * (1.0 - ang.z));
        float scattered = max(arrival.y * exp(-arrival.z * (1.0 - front.x)) - arrival.x, 0.0);
        float spread = max(arrival.z, 1.0) * front.z;
        float back_direct = back.x * 0.5 * hair_gaussian(sqrt(back.z), ang.x - back.y) * back_azimuth;
        float back_spread = back.x * 0.5 * hair_gaussian(sqrt(back.z + spread), ang.x - back.y) * back_azimuth;
        vec3 energy = ef + eb;
        vec3 g = vec3(hair_gaussian(sqrt(widths.x * widths.x + spread), ang.x - shifts.x),
                      hair_gaussian(sqrt(widths.y * widths.y + spread), ang.x - shifts.y),
                      hair_gaussian(sqrt(widths.z * widths.z + spread), ang.x - shifts.z));
        float global = 0.5 * dot(g, energy) / 6.28318530718;
        float direct = arrival.x * (single[ch] * inherited + BACKWARD_DENSITY * back_direct * inv_cos2);
        float scatter = FORWARD_DENSITY * scattered * (global + BACKWARD_DENSITY * back_spread) * inv_cos2;
        result[ch] = (direct + scatter) * ang.w;
    }
    return result;
}

#endif
