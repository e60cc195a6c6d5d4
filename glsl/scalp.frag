#version 460
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "temporal.glsl"

// Depth is tested before shading (nothing here writes depth or discards): the visibility
// note would make the test late otherwise.
layout(early_fragment_tests) in;
layout(location = 0) in vec3 in_normal;
layout(location = 1) flat in vec3 in_color;
layout(location = 2) flat in uint in_character;
layout(location = 0) out vec4 out_color;

void main() {
    note_fragment(VISIBILITY_SOLID | in_character, vec2(0.0));
    vec3 n = normalize(in_normal);
    // Two-sided: the scalp winding is arbitrary.
    float d = abs(dot(n, normalize(frame.to_light)));
    out_color = vec4(in_color * (0.3 + 0.7 * d), 1.0);
}
