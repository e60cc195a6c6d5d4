// The radiance of a strand point toward the eye, shared by every strand fragment shader
// (strand_fragment.glsl) and the software rasterizer's vertex shading (soft_segments.glsl).
// The model is chosen per frame by frame.shading.model (src/shade/mod.rs ShadingModel):
// 0 placeholder (Kajiya-Kay diffuse with a half-vector highlight and darker roots),
// 1 Kajiya-Kay diffuse + specular, 2 Marschner R / TT / TRT. Requires bindings.glsl.
#ifndef STRAND_RADIANCE_GLSL
#define STRAND_RADIANCE_GLSL
#include "hair_shading.glsl"
#include "shadow_lookup.glsl"
#include "volume_shading.glsl"
#include "lod_appearance.glsl"

// LIGHT_IRRADIANCE (the directional light) and AMBIENT, SKY_TINT, GROUND_TINT (the sky and
// ground) come from shared.glsl (Rust twins in src/shade/mod.rs). With frame.shading.multiple_scattering on,
// Marschner adds dual scattering (hair_shading.glsl) from the light; the ambient term is the
// sky and ground in every model.

// The sky and ground light reaching strand point `pos` of character `character`: a strand has
// no normal, so the direction out of the character's hair (from the centre of its hair mesh's
// box) stands for one: hair on the crown sees the sky, the ends under a bob the ground.
vec3 hair_ambient(uint character, vec3 pos) {
    CharacterRecord r = characters[character];
    vec3 centre = (r.model * vec4(r.mesh.pos_origin.xyz + 0.5 * r.mesh.pos_extent.xyz, 1.0)).xyz;
    vec3 out_dir = pos - centre;
    float len = length(out_dir);
    return hemisphere_ambient(len > 0.0 ? out_dir.y / len : 0.0);
}

// Radiance toward the eye at world point `pos` of a strand with unit-ish tangent `tangent`,
// parameter `s` along it, base colour `base`, of character `character`, standing for
// `thickness` strands (strand LoD; 1 at full detail), given how the light arrives there
// (`arrival`: light_arrival's direct fraction, open fraction, strand hits) and the ambient
// light's visibility `ambient`.
vec3 strand_radiance_lit(vec3 tangent, float s_param, vec3 pos, vec3 base, uint character, float thickness, vec3 arrival,
                         float ambient) {
    float lit = arrival.x;
    vec3 t = normalize(tangent);
    vec3 l = normalize(frame.to_light);
    vec3 e = normalize(frame.eye - pos);
    float root_shadow = mix(0.55, 1.0, smoothstep(0.0, 0.3, s_param));
    vec3 c;
    if (frame.shading.model == SHADING_KAJIYA_KAY) {
        vec2 kk = kajiya_kay(t, l, e);
        c = (base * (hair_ambient(character, pos) * ambient + kk.x * lit) + vec3(0.3) * (kk.y * lit)) * root_shadow;
    } else if (frame.shading.model == SHADING_MARSCHNER) {
        HairStyle s = characters[character].style;
        vec3 sc = dual_scattering(t, l, e, base, s.roughness, radians(s.cuticle_tilt_degrees), arrival,
                                  frame.shading.multiple_scattering != 0u, cluster_crossings(thickness));
        c = (sc * LIGHT_IRRADIANCE + base * (hair_ambient(character, pos) * ambient)) * root_shadow;
    } else {
        float tl = dot(t, l);
        float diffuse = sqrt(max(1.0 - tl * tl, 0.0));
        vec3 h = normalize(l + e);
        float th = dot(t, h);
        float spec = pow(sqrt(max(1.0 - th * th, 0.0)), 80.0);
        c = base * (0.25 * ambient + 0.75 * diffuse * lit) * root_shadow + vec3(0.25) * (spec * lit) * root_shadow;
    }
    return c;
}

// strand_radiance_lit with the light through the light's maps (hair and bodies in front of
// the point) and the ambient light through the character's density volume (volumetric
// ambient occlusion, where on).
vec3 strand_radiance(vec3 tangent, float s_param, vec3 pos, vec3 base, uint character, float thickness) {
    return strand_radiance_lit(tangent, s_param, pos, base, character, thickness, light_arrival(pos, 0.0),
                               volume_ambient(character, pos));
}

#endif
