#version 460
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"

layout(location = 0) in vec3 in_normal;
layout(location = 0) out vec4 out_color;

void main() {
    vec3 n = normalize(in_normal);
    // Two-sided: the scalp winding is arbitrary.
    float d = abs(dot(n, normalize(frame.light_dir.xyz)));
    vec3 skin = vec3(style.color[0], style.color[1], style.color[2]) * 0.6;
    out_color = vec4(skin * (0.3 + 0.7 * d), 1.0);
}
