#version 460
// Props: static triangle lists pulled from the prop vertex buffer (the ground, heads), or
// skinned meshes (bodies, clothes): their triangle list indexes the instance's posed vertices,
// written this frame by skin.comp. One instance record (transform, colour) per placed prop;
// the colour multiplies a skinned vertex's own (whose alpha is its roughness). The light's
// prop pass (BODY_MAP_PASS) draws into the bodies' map, fitted to the camera's view
// (render::shadow::LightView::fit_bodies).
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"

layout(set = SET_FRAME, binding = BINDING_PROP_VERTICES, std430) readonly buffer PropVertices { PropVertex prop_vertices[]; };
layout(set = SET_FRAME, binding = BINDING_PROP_INSTANCES, std430) readonly buffer PropInstances { PropInstance prop_instances[]; };
layout(set = SET_FRAME, binding = BINDING_SKINNED_VERTICES, std430) readonly buffer Posed { SkinnedVertex skinned[]; };

layout(location = 0) out vec3 out_normal;
layout(location = 1) flat out vec3 out_color;
layout(location = 2) out vec3 out_pos;
layout(location = 3) flat out uint out_instance;
layout(location = 4) flat out float out_roughness;

void main() {
    PropInstance inst = prop_instances[gl_InstanceIndex];
    vec3 position;
    vec3 normal;
    vec3 color = inst.color.rgb;
    float roughness = PROP_ROUGHNESS;
    if (inst.skin.x == SKIN_NONE) {
        PropVertex v = prop_vertices[gl_VertexIndex];
        position = v.position.xyz;
        normal = v.normal.xyz;
    } else {
        // Skinned meshes are drawn indexed: gl_VertexIndex is the mesh's own index.
        SkinnedVertex v = skinned[inst.skin.x + uint(gl_VertexIndex)];
        position = v.position;
        normal = v.normal;
        vec4 packed = unpackUnorm4x8(v.color);
        color *= packed.rgb;
        roughness = packed.a;
    }
    vec4 world = inst.model * vec4(position, 1.0);
    // Inverse transpose: people are scaled non-uniformly (head proportions).
    out_normal = normalize(transpose(inverse(mat3(inst.model))) * normal);
    out_color = color;
    out_roughness = roughness;
    out_pos = world.xyz;
    out_instance = uint(gl_InstanceIndex);
#ifdef BODY_MAP_PASS
    gl_Position = frame.body_view_proj * world;
#else
    gl_Position = frame.view_proj * world;
#endif
}
