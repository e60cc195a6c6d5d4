#version 460
// Props (bodies, ground): static triangle lists pulled from the prop vertex buffer, one
// instance record (transform, colour) per placed prop.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"

layout(set = SET_FRAME, binding = BINDING_PROP_VERTICES, std430) readonly buffer PropVertices { PropVertex prop_vertices[]; };
layout(set = SET_FRAME, binding = BINDING_PROP_INSTANCES, std430) readonly buffer PropInstances { PropInstance prop_instances[]; };

layout(location = 0) out vec3 out_normal;
layout(location = 1) flat out vec3 out_color;
layout(location = 2) out vec3 out_pos;
layout(location = 3) flat out uint out_instance;

void main() {
    PropVertex v = prop_vertices[gl_VertexIndex];
    PropInstance inst = prop_instances[gl_InstanceIndex];
    vec4 world = inst.model * vec4(v.position.xyz, 1.0);
    // Inverse transpose: people are scaled non-uniformly (head proportions).
    out_normal = normalize(transpose(inverse(mat3(inst.model))) * v.normal.xyz);
    out_color = inst.color.rgb;
    out_pos = world.xyz;
    out_instance = uint(gl_InstanceIndex);
    gl_Position = frame.view_proj * world;
}
