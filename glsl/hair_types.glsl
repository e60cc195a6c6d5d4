// Structs shared with Rust (std430). Each mirrors a #[repr(C)] Rust struct field for field;
// tests/glsl_layout.rs checks the offsets. Change both sides together.
#ifndef HAIR_TYPES_GLSL
#define HAIR_TYPES_GLSL

// src/style.rs: HairStyle
struct HairStyle {
    uint seed;
    float strand_width;
    float tip_width_ratio;
    float taper_power;
    float length_variation;
    float root_ramp;
    float clump_strength;
    float clump_power;
    float curl_radius;
    float curl_frequency;
    float curl_phase_jitter;
    float wave_amplitude;
    float wave_frequency;
    float wave_angle;
    float wave_phase_jitter;
    float frizz_amplitude;
    float frizz_frequency;
    float frizz_power;
    uint density_by_area;
    float color[3];
    uint _pad[2];
};

// src/bake.rs: MeshInfo (decode constants of the five textures)
struct MeshInfo {
    vec4 pos_origin;        // xyz: position of texel value 0; w: w scale
    vec4 pos_extent;        // xyz: position extent of texel value 1; w: unused
    vec4 uv_origin_extent;  // xy: uv origin; zw: uv extent
    uvec2 root_size;        // root slice width, height (texels)
    uint layers;            // L
    uint bundle_count;
};

// src/bake.rs: BundleDesc (one per bundle)
struct BundleDesc {
    uvec2 origin;           // root-slice texel of cell corner (0, 0)
    uint flags;             // bit 0: triangle bundle
    float rest_size;        // h of eq. 7: longest root edge at rest
    float density;          // root area / mean root area
    uint _pad[3];
};

#endif
