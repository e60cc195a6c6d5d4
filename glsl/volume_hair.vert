#version 460
// The volume tier's far hair (seed 002, vkhr sec. 4): one box per character, instance =
// character slot, the 36 vertices of its density volume's grid box in world space; characters
// without a built volume or with no volume share this frame get no triangles.
#extension GL_GOOGLE_include_directive : require
#include "bindings.glsl"
#include "volume_shading.glsl"

layout(location = 0) out vec3 out_world;
layout(location = 1) flat out uint out_character;

// The 6 faces' corners (bit 0: x, bit 1: y, bit 2: z), two triangles each.
const uint FACES[36] = uint[36](
    0u, 2u, 1u, 1u, 2u, 3u,  4u, 5u, 6u, 5u, 7u, 6u,
    0u, 1u, 4u, 1u, 5u, 4u,  2u, 6u, 3u, 3u, 6u, 7u,
    0u, 4u, 2u, 2u, 4u, 6u,  1u, 3u, 5u, 3u, 7u, 5u);

void main() {
    uint c = uint(gl_InstanceIndex);
    out_character = c;
    bool drawn = (characters[c].flags & CHARACTER_VISIBLE) != 0u && volume_weight(c) > 0.0;
    if (!drawn) {
        // Beyond the far plane: clipped.
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        out_world = vec3(0.0);
        return;
    }
    uint corner = FACES[gl_VertexIndex];
    vec3 g = vec3(uvec3(corner & 1u, (corner >> 1u) & 1u, corner >> 2u)) * vec3(volume_dims(c));
    vec4 world = inverse(characters[c].world_to_volume) * vec4(g, 1.0);
    out_world = world.xyz / world.w;
    gl_Position = frame.view_proj * vec4(out_world, 1.0);
}
