#version 460
// Simple hair shading until the physically based pass lands: Kajiya-Kay diffuse
// sqrt(1 - (T.L)^2) (Kajiya and Kay 1989) plus ambient, darker toward the root.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"

layout(location = 0) in vec3 in_tangent;
layout(location = 1) in float in_s;
layout(location = 2) in vec3 in_pos;
layout(location = 3) flat in vec3 in_color;
layout(location = 0) out vec4 out_color;

void main() {
    vec3 t = normalize(in_tangent);
    vec3 l = normalize(frame.light_dir.xyz);
    float tl = dot(t, l);
    float diffuse = sqrt(max(1.0 - tl * tl, 0.0));
    vec3 e = normalize(frame.camera_pos.xyz - in_pos);
    vec3 h = normalize(l + e);
    float th = dot(t, h);
    float spec = pow(sqrt(max(1.0 - th * th, 0.0)), 80.0);
    vec3 base = in_color;
    float root_shadow = mix(0.55, 1.0, smoothstep(0.0, 0.3, in_s));
    vec3 c = base * (0.25 + 0.75 * diffuse) * root_shadow + vec3(0.25) * spec * root_shadow;
    out_color = vec4(c, 1.0);
}
