#version 460
// Test probe (tests/shading_twin.rs): evaluates the GPU shading models at given directions so
// they can be compared with their CPU twins in src/shade/mod.rs and src/shade/scattering.rs.
// Per sample, inputs are five vec4 (tangent, to light, to eye, colour + roughness, tilt +
// light arrival + cluster crossings (0: multiple scattering off)) and outputs three vec4 (Marschner rgb;
// Kajiya-Kay diffuse, specular; dual scattering rgb). Binding 2: the shading lookup texture.
#extension GL_GOOGLE_include_directive : require
#define SHADING_LUT_SET 0
#define SHADING_LUT_BINDING 2
#include "hair_shading.glsl"
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) readonly buffer Inputs { vec4 inputs[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uvec4 params; } push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.params.x) {
        return;
    }
    vec3 t = inputs[5u * i].xyz;
    vec3 l = inputs[5u * i + 1u].xyz;
    vec3 v = inputs[5u * i + 2u].xyz;
    vec4 cr = inputs[5u * i + 3u];
    vec4 extra = inputs[5u * i + 4u];
    float tilt = extra.x;
    // Arrival: direct = exp(-hits) * open (no map's filtering), open, hits.
    vec3 arrival = vec3(extra.y * exp(-extra.z), extra.y, extra.z);
    outputs[3u * i] = vec4(marschner(t, l, v, cr.rgb, cr.a, tilt), 0.0);
    outputs[3u * i + 1u] = vec4(kajiya_kay(t, l, v), 0.0, 0.0);
    outputs[3u * i + 2u] = vec4(dual_scattering(t, l, v, cr.rgb, cr.a, tilt, arrival, extra.w != 0.0, max(extra.w, 1.0)), 0.0);
}
