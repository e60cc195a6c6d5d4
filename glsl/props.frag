#version 460
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"

layout(location = 0) in vec3 in_normal;
layout(location = 1) flat in vec3 in_color;
layout(location = 0) out vec4 out_color;

void main() {
    float d = max(dot(normalize(in_normal), normalize(frame.light_dir.xyz)), 0.0);
    out_color = vec4(in_color * (0.35 + 0.65 * d), 1.0);
}
